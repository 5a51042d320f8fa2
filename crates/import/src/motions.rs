//! Motions found in a session's gyroscope, for an import without the robot's log (`evtac import
//! SESSION --out DIR` without `--log`): each becomes a row of the log the import would have
//! read, and is listed for review (`motions.csv`) with what was measured and what was rounded.
//!
//! The gyroscope is read in the sensor frame (the calibration's rotation) after a 25 ms moving
//! average. At rest the rate is the gyroscope's bias, taken as the mean over the half second
//! that ends 50 ms before each sample; a motion starts when the rate leaves that bias by more
//! than [`FindConfig::threshold_deg_s`], and the bias is then held until the rate has been back
//! within it for [`FindConfig::max_stop_us`] (a shorter pause is Experiment 2's stop, inside the
//! motion). Its onset and end are where the rate, walked outwards, comes within
//! [`EDGE_DEG_S`] of the bias: the first and last milliseconds of the ramps.
//!
//! A candidate is kept only if it lasts [`FindConfig::min_motion_us`], turns about an axis in
//! the sensor's x-y plane (a tilt does; [`MAX_OFF_AXIS`]), and the accelerometer agrees that the
//! sensor tilted: a change of the gyroscope's bias (the simulator draws one per trial) moves the
//! rate but not gravity.
//!
//! Direction `phi` (from the mean rate: the sensor turns at `theta_dot (sin phi, -cos phi, 0)`),
//! speed (the median rate while moving) and total tilt (the rate integrated about the tilt's
//! axis) are rounded to the protocol's steps, whole degrees and deg/s by default: the robot is
//! commanded round values, and the gyroscope's scale error (about 1 %) would otherwise pass into
//! the labels, which scale the integrated rate onto the total.

use evtac_events::ImuSample;
use evtac_events::layout::trial_file;
use evtac_events::manifest::TrialMeta;
use evtac_labels::geometry::{Calibration, axial_rate};
use serde::Serialize;
use std::path::{Path, PathBuf};

use crate::robot_log::RobotLog;

/// The rate's distance from the bias that ends the walk outwards from a motion's crossing, deg/s:
/// nine times the smoothed noise of a DVXplorer's gyroscope (0.05 deg/s per sample over 20).
pub const EDGE_DEG_S: f64 = 0.1;

/// Largest share of a motion's mean rate about the sensor's z axis: a tilt turns about an axis
/// in the x-y plane, a bias step points anywhere.
pub const MAX_OFF_AXIS: f64 = 0.3;

/// The moving average of the rate, us.
const SMOOTH_US: i64 = 25_000;

/// The bias is the mean over this long, us...
const BIAS_WINDOW_US: i64 = 500_000;

/// ...ending this long before the sample, so a motion's first ramp is not in its own bias.
const BIAS_GUARD_US: i64 = 50_000;

/// Longest walk from a motion's threshold crossing to its edge, us: the ramp from the
/// threshold down to [`EDGE_DEG_S`] (5 ms at the simulator's 200 deg/s^2), with room for a
/// gentler robot; it never reaches into the next still stretch's own bias.
const MAX_EDGE_US: i64 = 100_000;

/// Gravity turns when the accelerometer's means over two consecutive [`GRAVITY_WINDOW_US`]
/// windows differ by this much, degrees: 0.2 at the slowest commanded speed (2 deg/s), four
/// times what a DVXplorer's accelerometer noise (0.002 g) makes.
const GRAVITY_TURN_DEG: f64 = 0.1;

/// The accelerometer's tilt over a motion must be at least this share of the gyroscope's.
const MIN_GRAVITY_SHARE: f64 = 0.5;

/// The accelerometer is averaged over this long at each end of a motion, us.
const GRAVITY_WINDOW_US: i64 = 100_000;

/// How motions are found and rounded.
#[derive(Debug, Clone, PartialEq)]
pub struct FindConfig {
    /// A motion starts when the rate leaves the bias by more than this, deg/s: half the slowest
    /// speed the protocols command (2 deg/s), well above a bias change.
    pub threshold_deg_s: f64,
    /// Shortest motion, us.
    pub min_motion_us: i64,
    /// Longest pause inside a motion (a stop), us; a longer one ends it.
    pub max_stop_us: i64,
    /// Directions are rounded to multiples of this, degrees (0: not rounded).
    pub direction_step_deg: f64,
    /// Speeds are rounded to multiples of this, deg/s (0: not rounded).
    pub speed_step_deg_s: f64,
    /// Totals are rounded to multiples of this, degrees (0: not rounded).
    pub total_step_deg: f64,
    /// The indentation depth written for every motion (the gyroscope cannot see it), mm.
    pub depth_mm: f64,
}

impl FindConfig {
    /// The defaults, with `depth_mm` for every motion.
    pub fn new(depth_mm: f64) -> Self {
        Self {
            threshold_deg_s: 1.0,
            min_motion_us: 300_000,
            max_stop_us: 1_000_000,
            direction_step_deg: 1.0,
            speed_step_deg_s: 1.0,
            total_step_deg: 1.0,
            depth_mm,
        }
    }
}

/// A motion found in the gyroscope.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FoundMotion {
    /// The row the import cuts by (rounded values, depth from the config).
    #[serde(skip)]
    pub meta: TrialMeta,
    /// Direction from the gyroscope before rounding, degrees in [0, 360).
    pub direction_gyro_deg: f64,
    /// Median rate while moving, before rounding, deg/s.
    pub speed_gyro_deg_s: f64,
    /// Integrated tilt before rounding, degrees.
    pub total_gyro_deg: f64,
    /// Tilt between the accelerometer's mean before and after, degrees.
    pub total_gravity_deg: f64,
    /// Share of the mean rate about the sensor's z axis.
    pub off_axis: f64,
    /// Pauses inside the motion (stops) longer than 100 ms.
    pub pauses: usize,
}

/// More than the farthest any step of the search looks back from the sample it is at (the bias
/// window and its guard, 550 ms): samples older than this are forgotten.
const LOOKBACK_US: i64 = 1_000_000;

/// Forgotten samples are dropped from the window's front once there are this many, so that
/// dropping costs a constant per sample.
const DROP_AT: usize = 1 << 12;

/// Appends the next samples (in time order, one per timestamp) to the vector; `false` at the
/// end of the recording.
type Source<'a> = dyn FnMut(&mut Vec<ImuSample>) -> bool + 'a;

/// Everything the search needs per sample, in the sensor frame, over a window of the recording
/// that is read as the search reaches it and, when `forget`, forgotten [`LOOKBACK_US`] behind
/// it: memory holds the longest motion and a few seconds, not the recording. Samples are named
/// by their index in the whole recording; the running sums run from its start, so every value
/// is the one the whole recording in memory gives, bit for bit.
struct Samples<'a> {
    source: &'a mut Source<'a>,
    calibration: &'a Calibration,
    forget: bool,
    /// The recording's index of `imu[0]`.
    base: usize,
    /// The samples held.
    imu: Vec<ImuSample>,
    /// Running sums of the sensor-frame rate: `sum[i]` over the samples before `base + i`.
    sum: Vec<[f64; 3]>,
    /// Running sums of the sensor-frame accelerometer, likewise.
    accel: Vec<[f64; 3]>,
    /// The recording's first timestamp.
    first_t: Option<i64>,
    ended: bool,
    /// The most samples held at once.
    peak: usize,
}

impl<'a> Samples<'a> {
    fn new(source: &'a mut Source<'a>, calibration: &'a Calibration, forget: bool) -> Self {
        Self {
            source,
            calibration,
            forget,
            base: 0,
            imu: Vec::new(),
            sum: vec![[0.0; 3]],
            accel: vec![[0.0; 3]],
            first_t: None,
            ended: false,
            peak: 0,
        }
    }

    /// Reads the next samples; `false` at the end of the recording.
    fn load(&mut self) -> bool {
        if self.ended {
            return false;
        }
        let held = self.imu.len();
        if !(self.source)(&mut self.imu) {
            self.ended = true;
        }
        for s in &self.imu[held..] {
            for (sums, v) in [
                (&mut self.sum, s.gyroscope),
                (&mut self.accel, s.accelerometer),
            ] {
                let v = self.calibration.imu_to_sensor(v.map(f64::from));
                let mut acc = *sums.last().unwrap_or(&[0.0; 3]);
                for i in 0..3 {
                    acc[i] += v[i];
                }
                sums.push(acc);
            }
        }
        self.first_t = self.first_t.or(self.imu.first().map(|s| s.t));
        self.peak = self.peak.max(self.imu.len());
        self.imu.len() > held || !self.ended
    }

    /// Whether the recording has a sample `k`.
    fn has(&mut self, k: usize) -> bool {
        while k >= self.base + self.imu.len() {
            if !self.load() {
                return false;
            }
        }
        true
    }

    /// Sample `k` (held: at most [`LOOKBACK_US`] behind the search, and read).
    fn at(&self, k: usize) -> &ImuSample {
        &self.imu[k - self.base]
    }

    /// Sample `k`'s time.
    fn t(&self, k: usize) -> i64 {
        self.at(k).t
    }

    /// Forgets the samples more than [`LOOKBACK_US`] before sample `k`, but the last of them
    /// (a walk back from a motion reads the time of the sample before it).
    fn forget_before(&mut self, k: usize) {
        if !self.forget {
            return;
        }
        let t = self.t(k) - LOOKBACK_US;
        let behind = self.imu.partition_point(|s| s.t < t).saturating_sub(1);
        if behind >= DROP_AT {
            self.imu.drain(..behind);
            self.sum.drain(..behind);
            self.accel.drain(..behind);
            self.base += behind;
        }
    }

    /// Sample `k`'s sensor-frame rate less `bias`.
    fn rate(&self, k: usize, bias: [f64; 3]) -> [f64; 3] {
        let i = k - self.base;
        std::array::from_fn(|c| self.sum[i + 1][c] - self.sum[i][c] - bias[c])
    }

    /// The first sample at or after `t` (read up to the first sample after it).
    fn index(&mut self, t: i64) -> usize {
        while self.imu.last().is_none_or(|s| s.t < t) && self.load() {}
        self.base + self.imu.partition_point(|s| s.t < t)
    }

    /// Mean of `sums` over samples `[a, b)`, `None` when empty.
    fn mean_of(&self, sums: &[[f64; 3]], a: usize, b: usize) -> Option<[f64; 3]> {
        let (i, j) = (a - self.base, b - self.base);
        (b > a).then(|| std::array::from_fn(|c| (sums[j][c] - sums[i][c]) / (b - a) as f64))
    }

    /// Mean rate over samples `[a, b)`, `None` when empty.
    fn mean(&self, a: usize, b: usize) -> Option<[f64; 3]> {
        self.mean_of(&self.sum, a, b)
    }

    /// Mean rate over the times `[from, to)`.
    fn mean_over(&mut self, from: i64, to: i64) -> Option<[f64; 3]> {
        let (a, b) = (self.index(from), self.index(to));
        self.mean(a, b)
    }

    /// The smoothed rate at sample `k`.
    fn smoothed(&mut self, k: usize) -> [f64; 3] {
        let t = self.t(k);
        self.mean_over(t - SMOOTH_US / 2, t + SMOOTH_US / 2 + 1)
            .unwrap_or([0.0; 3])
    }

    /// The bias before sample `k`, if the recording reaches back far enough.
    fn bias_before(&mut self, k: usize) -> Option<[f64; 3]> {
        let t = self.t(k);
        if t - BIAS_GUARD_US - BIAS_WINDOW_US < self.first_t? {
            return None;
        }
        self.mean_over(t - BIAS_GUARD_US - BIAS_WINDOW_US, t - BIAS_GUARD_US)
    }

    /// The smoothed rate's distance from `bias` at sample `k`.
    fn deviation(&mut self, k: usize, bias: [f64; 3]) -> f64 {
        let w = self.smoothed(k);
        norm(std::array::from_fn(|i| w[i] - bias[i]))
    }

    /// The accelerometer's mean over `[from, to)`.
    fn gravity(&mut self, from: i64, to: i64) -> Option<[f64; 3]> {
        let (a, b) = (self.index(from), self.index(to));
        self.mean_of(&self.accel, a, b)
    }

    /// Whether gravity turned between the two [`GRAVITY_WINDOW_US`] windows before sample `k`,
    /// the way a turn at `omega` (sensor frame) turns it: a vector fixed in the world turns at
    /// `-omega x v` in the sensor's frame. (The simulator puts the sensor back upright between
    /// trials without a motion: gravity jumps then, against the motion before.)
    fn gravity_turns(&mut self, k: usize, omega: [f64; 3]) -> bool {
        let t = self.t(k) + 1;
        let w = GRAVITY_WINDOW_US;
        match (self.gravity(t - 2 * w, t - w), self.gravity(t - w, t)) {
            (Some(a), Some(b)) => {
                let turn = cross(a, omega);
                let moved: [f64; 3] = std::array::from_fn(|i| b[i] - a[i]);
                angle_deg(a, b) >= GRAVITY_TURN_DEG && dot(moved, turn) > 0.0
            }
            _ => false,
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(v: [f64; 3]) -> f64 {
    dot(v, v).sqrt()
}

/// `a x b`.
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Angle between two vectors, degrees.
fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    (dot(a, b) / (norm(a) * norm(b)).max(f64::MIN_POSITIVE))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// `v` rounded to a multiple of `step` (unchanged for a step of 0).
fn round_to(v: f64, step: f64) -> f64 {
    if step > 0.0 {
        (v / step).round() * step
    } else {
        v
    }
}

/// The motions in `imu` (in time order, one sample per timestamp), found and measured as the
/// module docs say.
pub fn find_motions(
    imu: &[ImuSample],
    calibration: &Calibration,
    config: &FindConfig,
) -> Vec<FoundMotion> {
    let mut whole = Some(imu);
    let mut source = |out: &mut Vec<ImuSample>| {
        out.extend_from_slice(whole.take().unwrap_or_default());
        false
    };
    let mut samples = Samples::new(&mut source, calibration, false);
    search(&mut samples, config)
}

/// What [`find_motions_in`] read.
#[derive(Debug, Clone, PartialEq)]
pub struct Streamed {
    /// The motions.
    pub found: Vec<FoundMotion>,
    /// The most IMU samples held at once (the longest motion and a few seconds, or the whole
    /// recording when its samples were out of time order and were read whole).
    pub peak_samples: usize,
}

/// The motions in the gyroscope of the recording at `path`, read as the search goes and
/// forgotten behind it: the same motions as [`find_motions`] of all its samples (sorted, one per
/// timestamp, as [`crate::imu_sync::read_imu`] reads them), in memory bounded by the longest
/// motion. A recording whose samples go back in time (several IMU streams) is read whole.
pub fn find_motions_in(
    path: &Path,
    calibration: &Calibration,
    config: &FindConfig,
) -> Result<Streamed, evtac_formats::Error> {
    let mut reader = evtac_formats::open(path)?;
    let mut error = None;
    let mut unordered = false;
    let mut last_t = i64::MIN;
    let mut source = |out: &mut Vec<ImuSample>| loop {
        match reader.next_chunk() {
            Ok(Some(chunk)) if chunk.imu.is_empty() => {}
            Ok(Some(chunk)) => {
                for s in chunk.imu {
                    unordered |= s.t < last_t;
                    // Repeated across packets: counted once, as `read_imu` does.
                    if s.t != last_t {
                        out.push(*s);
                    }
                    last_t = last_t.max(s.t);
                }
                return !unordered;
            }
            Ok(None) => return false,
            Err(e) => {
                error = Some(e);
                return false;
            }
        }
    };
    let mut samples = Samples::new(&mut source, calibration, true);
    let found = search(&mut samples, config);
    let peak_samples = samples.peak;
    drop(samples);
    if let Some(e) = error {
        return Err(e);
    }
    if unordered {
        let imu = crate::imu_sync::read_imu(path)?;
        return Ok(Streamed {
            found: find_motions(&imu, calibration, config),
            peak_samples: imu.len(),
        });
    }
    Ok(Streamed {
        found,
        peak_samples,
    })
}

/// The search over `samples`.
fn search(samples: &mut Samples, config: &FindConfig) -> Vec<FoundMotion> {
    let mut found = Vec::new();
    let mut k = 0;
    // Where to look next after a motion ending (or a candidate rejected whole) at time `t`: a
    // bias window later, so that the next bias does not hold the motion.
    let past = |samples: &mut Samples, t: i64, k: usize| {
        samples.index(t + BIAS_WINDOW_US + BIAS_GUARD_US).max(k + 1)
    };
    while samples.has(k) {
        samples.forget_before(k);
        let Some(bias) = samples.bias_before(k) else {
            k += 1;
            continue;
        };
        if samples.deviation(k, bias) <= config.threshold_deg_s {
            k += 1;
            continue;
        }
        // Not a tilt (a step of the bias, not yet out of the bias window): the next sample is
        // looked at afresh, with the bias window moved on by one sample.
        let Some(omega) = tilts_at_first(samples, k, bias, config) else {
            k += 1;
            continue;
        };
        // Moving while the rate is off the held bias and gravity turns, until neither for a
        // stop's length (a bias step alone, or a jump of gravity alone, does not keep it going).
        let (mut last_active, mut j) = (k, k);
        while samples.has(j) && samples.t(j) - samples.t(last_active) <= config.max_stop_us {
            if samples.deviation(j, bias) > config.threshold_deg_s
                && samples.gravity_turns(j, omega)
            {
                last_active = j;
            }
            j += 1;
        }
        let (t_first, t_last) = (samples.t(k), samples.t(last_active));
        let mut start = k;
        while start > 0
            && t_first - samples.t(start - 1) <= MAX_EDGE_US
            && samples.deviation(start - 1, bias) > EDGE_DEG_S
        {
            start -= 1;
        }
        let mut end = last_active;
        while samples.has(end + 1)
            && samples.t(end + 1) - t_last <= MAX_EDGE_US
            && samples.deviation(end + 1, bias) > EDGE_DEG_S
        {
            end += 1;
        }
        match measure(samples, start, end, bias, config) {
            Some(m) => {
                found.push(m);
                let t = samples.t(end);
                k = past(samples, t, end);
            }
            None => {
                let t = samples.t(k);
                k = past(samples, t, k);
            }
        }
    }
    number_from(&mut found, 0);
    found
}

/// Names the motions `m<first>`, `m<first + 1>`, ... (four digits at least): one session's of
/// several numbered on from the sessions before.
pub fn number_from(found: &mut [FoundMotion], first: usize) {
    for (i, m) in found.iter_mut().enumerate() {
        m.meta.trial = format!("m{:04}", first + i);
        m.meta.file = trial_file(&m.meta.trial).into();
    }
}

/// The mean rate less `bias` over the first [`FindConfig::min_motion_us`] after the rate left
/// `bias` at sample `k`, if they look like a tilt: the rate about an axis in the x-y plane, and
/// gravity turning with it.
fn tilts_at_first(
    samples: &mut Samples,
    k: usize,
    bias: [f64; 3],
    config: &FindConfig,
) -> Option<[f64; 3]> {
    let t0 = samples.t(k);
    let t1 = t0 + config.min_motion_us;
    let mean = samples.mean_over(t0, t1)?;
    let w: [f64; 3] = std::array::from_fn(|i| mean[i] - bias[i]);
    if w[2].abs() > MAX_OFF_AXIS * norm(w) {
        return None;
    }
    // Gravity is averaged over a window, so the gyroscope's angle is taken to that window's
    // middle.
    let gyro_deg = norm([w[0], w[1], 0.0]) * (t1 - t0 - GRAVITY_WINDOW_US / 2) as f64 * 1e-6;
    let before = samples.gravity(t0 - GRAVITY_WINDOW_US, t0);
    let now = samples.gravity(t1 - GRAVITY_WINDOW_US, t1);
    let (a, b) = (before?, now?);
    let moved: [f64; 3] = std::array::from_fn(|i| b[i] - a[i]);
    (angle_deg(a, b) >= MIN_GRAVITY_SHARE * gyro_deg && dot(moved, cross(a, w)) > 0.0).then_some(w)
}

/// The motion from sample `start` to `end` with `bias`, or `None` when it is no tilt.
fn measure(
    samples: &mut Samples,
    start: usize,
    end: usize,
    bias: [f64; 3],
    config: &FindConfig,
) -> Option<FoundMotion> {
    let (t0, t1) = (samples.t(start), samples.t(end));
    if t1 - t0 < config.min_motion_us {
        return None;
    }
    let mean = samples.mean(start, end + 1)?;
    let w: [f64; 3] = std::array::from_fn(|i| mean[i] - bias[i]);
    let off_axis = w[2].abs() / norm(w).max(f64::MIN_POSITIVE);
    if off_axis > MAX_OFF_AXIS {
        return None;
    }
    let phi = w[0].atan2(-w[1]).to_degrees().rem_euclid(360.0);
    let rates: Vec<(i64, f64)> = (start..=end)
        .map(|k| (samples.t(k), axial_rate(samples.rate(k, bias), phi)))
        .collect();
    let total: f64 = rates
        .windows(2)
        .map(|p| 0.5 * (p[0].1 + p[1].1) * (p[1].0 - p[0].0) as f64 * 1e-6)
        .sum();
    let mut moving: Vec<f64> = rates
        .iter()
        .map(|r| r.1)
        .filter(|&r| r > config.threshold_deg_s)
        .collect();
    moving.sort_by(f64::total_cmp);
    let speed = *moving.get(moving.len() / 2)?;
    let before = samples.gravity(t0 - GRAVITY_WINDOW_US, t0)?;
    let after = samples.gravity(t1 + 1, t1 + 1 + GRAVITY_WINDOW_US)?;
    let gravity = angle_deg(before, after);
    if gravity < MIN_GRAVITY_SHARE * total.abs() {
        return None;
    }
    let meta = TrialMeta {
        trial: String::new(),
        file: Default::default(),
        truth: None,
        direction_deg: round_to(phi, config.direction_step_deg).rem_euclid(360.0),
        speed_deg_s: round_to(speed, config.speed_step_deg_s),
        depth_mm: config.depth_mm,
        total_deg: round_to(total, config.total_step_deg),
        motion_start_us: t0,
        motion_end_us: t1,
        stop_start_us: None,
        stop_end_us: None,
        stop_deg: None,
        group: None,
    };
    Some(FoundMotion {
        meta,
        direction_gyro_deg: phi,
        speed_gyro_deg_s: speed,
        total_gyro_deg: total,
        total_gravity_deg: gravity,
        off_axis,
        pauses: count_pauses(samples, start, end, bias, config.threshold_deg_s),
    })
}

/// Pauses of at least 100 ms inside the motion from sample `start` to `end`: runs with the
/// smoothed rate within `threshold` of `bias` (Experiment 2's stop is one).
fn count_pauses(
    samples: &mut Samples,
    start: usize,
    end: usize,
    bias: [f64; 3],
    threshold: f64,
) -> usize {
    let mut count = 0;
    let mut since = None;
    for k in start..=end {
        let t = samples.t(k);
        match (samples.deviation(k, bias) <= threshold, since) {
            (true, None) => since = Some(t),
            (false, Some(t0)) => {
                count += usize::from(t - t0 >= 100_000);
                since = None;
            }
            _ => {}
        }
    }
    count
}

/// The log an import cuts `session` by: one row per found motion, its line the motion's
/// number (1-based) so that the import's errors name the motion.
pub fn as_log(session: &Path, found: &[FoundMotion]) -> RobotLog {
    RobotLog {
        path: PathBuf::from(format!(
            "{} (motions found in its gyroscope)",
            session.display()
        )),
        rows: found
            .iter()
            .enumerate()
            .map(|(i, m)| (i + 1, m.meta.clone()))
            .collect(),
    }
}

/// Names the motions found in one file of a folder of trials after it: the file's stem for its
/// only motion, `<stem>-m0000`, `<stem>-m0001`, ... for more.
pub fn name_after(found: &mut [FoundMotion], stem: &str) {
    let only = found.len() == 1;
    for (i, m) in found.iter_mut().enumerate() {
        m.meta.trial = if only {
            stem.to_string()
        } else {
            format!("{stem}-m{i:04}")
        };
        m.meta.file = trial_file(&m.meta.trial).into();
    }
}

/// The review file `motions.csv`: each motion's row as written and the recording it was found
/// in, beside what the gyroscope and accelerometer measured before rounding, and a note where a
/// value wants a look.
pub fn review_csv(found: &[(PathBuf, FoundMotion)]) -> String {
    let mut out = String::from(
        "trial,session,motion_start_us,motion_end_us,direction_deg,direction_gyro_deg,\
         speed_deg_s,speed_gyro_deg_s,total_deg,total_gyro_deg,total_gravity_deg,off_axis,\
         pauses,review\n",
    );
    for (session, m) in found {
        let t = &m.meta;
        out += &format!(
            "{},{},{},{},{},{:.3},{},{:.3},{},{:.3},{:.3},{:.3},{},{}\n",
            t.trial,
            session.display(),
            t.motion_start_us,
            t.motion_end_us,
            t.direction_deg,
            m.direction_gyro_deg,
            t.speed_deg_s,
            m.speed_gyro_deg_s,
            t.total_deg,
            m.total_gyro_deg,
            m.total_gravity_deg,
            m.off_axis,
            m.pauses,
            review_note(m)
        );
    }
    out
}

/// What about a motion wants a look: a pause (a stop, not written as one), a value far from
/// its rounding, gravity disagreeing with the gyroscope. Every row says where it came from.
pub fn review_note(m: &FoundMotion) -> String {
    let t = &m.meta;
    let mut notes = vec!["gyro; depth from --depth-mm".to_string()];
    if m.pauses > 0 {
        notes.push(format!(
            "{} pause(s) inside: a stop? (not written as one)",
            m.pauses
        ));
    }
    let far = |raw: f64, written: f64, what: &str, limit: f64| {
        ((raw - written).abs() > limit).then(|| format!("{what} {raw:.2} rounded to {written}"))
    };
    // Angles wrap: 359.7 rounds to 0.
    let direction_off =
        ((m.direction_gyro_deg - t.direction_deg + 180.0).rem_euclid(360.0) - 180.0).abs();
    if direction_off > 0.3 {
        notes.push(format!(
            "direction {:.2} rounded to {}",
            m.direction_gyro_deg, t.direction_deg
        ));
    }
    notes.extend(far(m.speed_gyro_deg_s, t.speed_deg_s, "speed", 0.3));
    notes.extend(far(m.total_gyro_deg, t.total_deg, "total", 0.3));
    if (m.total_gravity_deg - m.total_gyro_deg.abs()).abs() > 0.1 * m.total_gyro_deg.abs() {
        notes.push(format!("gravity turned {:.2} deg", m.total_gravity_deg));
    }
    notes.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_labels::geometry::{contact_direction, sensor_angular_velocity};

    /// 800 Hz samples of a sensor that rests with one bias, rests with another 1.5 deg/s away
    /// (a bias step, gravity still), then tilts 12 degrees towards 30 degrees at 4 deg/s
    /// (ramps of 200 deg/s^2) and rests again: noise-free, identity calibration.
    fn bias_step_then_tilt() -> (Vec<ImuSample>, i64) {
        let (onset_s, speed, accel, total) = (6.0, 4.0, 200.0, 12.0);
        let ramp = speed / accel;
        // Ramps of `ramp` at both ends: the time at full speed plus one ramp covers the total.
        let cruise = total / speed;
        let rate = |t: f64| {
            let u = t - onset_s;
            if u < 0.0 || u > cruise + ramp {
                0.0
            } else {
                (accel * u).min(speed).min(accel * (cruise + ramp - u))
            }
        };
        let mut theta = 0.0;
        let samples = (0..10 * 800)
            .map(|k| {
                let t = k as f64 / 800.0;
                theta += rate(t) / 800.0;
                let bias = if t < 3.0 {
                    [0.2, -0.1, 0.3]
                } else {
                    [1.4, 0.8, 0.3]
                };
                let w = sensor_angular_velocity(rate(t), 30.0);
                let d = contact_direction(theta, 30.0);
                ImuSample {
                    t: (t * 1e6).round() as i64,
                    gyroscope: std::array::from_fn(|i| (w[i] + bias[i]) as f32),
                    accelerometer: d.map(|v| -v as f32),
                    temperature: 30.0,
                }
            })
            .collect();
        (samples, (onset_s * 1e6) as i64)
    }

    #[test]
    fn a_tilt_is_found_and_a_bias_step_is_not() {
        let (imu, onset) = bias_step_then_tilt();
        let found = find_motions(&imu, &Calibration::default(), &FindConfig::new(2.0));
        assert_eq!(found.len(), 1, "{found:?}");
        let m = &found[0];
        assert!((m.meta.motion_start_us - onset).abs() <= 20_000, "{m:?}");
        assert_eq!(
            (m.meta.direction_deg, m.meta.speed_deg_s, m.meta.total_deg),
            (30.0, 4.0, 12.0)
        );
        assert!((m.direction_gyro_deg - 30.0).abs() < 0.01, "{m:?}");
        assert!((m.total_gyro_deg - 12.0).abs() < 0.05, "{m:?}");
        assert!((m.total_gravity_deg - 12.0).abs() < 0.05, "{m:?}");
        assert_eq!((m.meta.trial.as_str(), m.pauses), ("m0000", 0));
    }

    /// Samples read in pieces and forgotten behind the search find what all of them in memory
    /// find, value for value, holding a bounded window: six bias steps and tilts in a row (a
    /// minute, three windows' worth of samples to forget).
    #[test]
    fn a_bounded_window_finds_what_the_whole_recording_finds() {
        let (one, _) = bias_step_then_tilt();
        let span = one.last().unwrap().t + 1250;
        let imu: Vec<ImuSample> = (0..6)
            .flat_map(|r| {
                one.iter().map(move |s| ImuSample {
                    t: s.t + r * span,
                    ..*s
                })
            })
            .collect();
        let (calibration, config) = (Calibration::default(), FindConfig::new(2.0));
        let whole = find_motions(&imu, &calibration, &config);
        assert_eq!(whole.len(), 6, "{whole:?}");
        for piece in [1, 77, 4000] {
            let mut pieces = imu.chunks(piece);
            let mut source = |out: &mut Vec<ImuSample>| match pieces.next() {
                Some(p) => {
                    out.extend_from_slice(p);
                    true
                }
                None => false,
            };
            let mut samples = Samples::new(&mut source, &calibration, true);
            assert_eq!(search(&mut samples, &config), whole, "pieces of {piece}");
            assert!(
                samples.base > 0 && samples.peak < imu.len() / 2,
                "held {} of {}",
                samples.peak,
                imu.len()
            );
        }
    }

    #[test]
    fn rounding_can_be_turned_off() {
        let (imu, _) = bias_step_then_tilt();
        let config = FindConfig {
            direction_step_deg: 0.0,
            speed_step_deg_s: 0.0,
            total_step_deg: 0.0,
            ..FindConfig::new(2.0)
        };
        let m = &find_motions(&imu, &Calibration::default(), &config)[0];
        assert_eq!(m.meta.total_deg, m.total_gyro_deg);
        assert_eq!(m.meta.direction_deg, m.direction_gyro_deg);
    }
}
