//! The clock offset that best aligns the gyroscope with the robot's log (`evtac import --sync
//! imu`), for a rig without trigger wiring.
//!
//! The log commands a rate profile `c(t)`: each row's speed from its onset to its end, zero
//! during its stop and between motions (the accelerations the log does not describe are
//! symmetric about each edge, so they do not bias the fit). The gyroscope measures the rate's
//! magnitude `g(t) = |omega(t)|`. The offset `o` minimises `integral (g(t) - c(t - o))^2 dt`,
//! which, as long as every motion lies inside the recording, is the same as maximising the
//! correlation `C(o) = sum over rows of speed * integral of g over the row's motion moved by
//! o`: `integral g^2` and `integral c^2` do not depend on `o`. With the running integral of `g`
//! (linear between samples), `C` costs two lookups per motion, so the search is a coarse scan
//! over every offset that keeps the log inside the IMU's span, at a step shorter than any
//! motion (so the coarse best lies on the true peak), then scans ten times finer around the
//! best, down to [`FINEST_STEP_US`].
//!
//! A gyroscope bias moves that peak: in a ramp's first milliseconds `|ramp + bias|` is not
//! `|bias|` plus the ramp (it can even dip below `|bias|`), so `C` gets two maxima a few ms
//! either side of the true offset (2.6 ms off on a simulated session). A second search, within
//! 20 ms of the first, fits `|omega - bias|` instead, with each motion's bias taken from
//! the still segment before its onset that the labels take it from. The fit's residual, the RMS
//! of `g - c` over the log's span (bias included), says how well the log describes what the
//! gyroscope saw.

use crate::robot_log::RobotLog;
use evtac_events::manifest::TrialMeta;
use evtac_labels::LabelConfig;
use evtac_labels::integration::CumulativeTrapezoid;
use std::path::{Path, PathBuf};

/// The coarse scan's step, us: a tenth of the shortest motion the protocols command (20 deg
/// at 10 deg/s is 2 s; a stop cuts a motion into parts of at least 400 ms).
const COARSE_STEP_US: i64 = 40_000;

/// The most offsets the coarse scan tries; a longer slack between the log and the recording
/// makes the step longer.
const MAX_COARSE_STEPS: i64 = 200_000;

/// How far from the first fit the second, without the gyroscope's bias, looks, us: the first
/// is off by no more than the time a ramp takes to reach the bias (a few ms).
const REFINE_US: i64 = 20_000;

/// The last refinement's step, us.
pub const FINEST_STEP_US: i64 = 5;

/// Errors of an IMU synchronisation.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImuSyncError {
    /// The session could not be read.
    #[error(transparent)]
    Recording(#[from] evtac_events::Error),
    /// The session has too few IMU samples to align anything.
    #[error(
        "{}: {samples} IMU sample(s): --sync imu aligns the gyroscope with the log (record the \
         IMU, or use --sync trigger or --clock-offset-us)",
        .session.display()
    )]
    NoImu {
        /// The session.
        session: PathBuf,
        /// Its IMU samples.
        samples: usize,
    },
    /// The log's motions span longer than the recording's IMU.
    #[error(
        "{}: its motions span {log_s:.3} s, longer than the {imu_s:.3} s of IMU in {}: the log \
         cannot lie inside the recording",
        .log.display(),
        .session.display()
    )]
    TooLong {
        /// The log.
        log: PathBuf,
        /// The session.
        session: PathBuf,
        /// The log's span, s.
        log_s: f64,
        /// The IMU's span, s.
        imu_s: f64,
    },
}

/// The offset found and how well it fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuFit {
    /// Recording time minus robot time, microseconds.
    pub offset_us: i64,
    /// RMS of the gyroscope's rate magnitude minus the commanded rate over the log's span at
    /// that offset, deg/s.
    pub residual_deg_s: f64,
}

/// The running integral of a series sampled at `(t_us, value)` (the labels' trapezoid, exact
/// for the series linear between samples, so the fit is smooth in the offset and not drawn to
/// the sample times), or `None` for an empty window, which contributes nothing. The callers'
/// times are sorted and deduplicated, so an empty window is the only error
/// [`CumulativeTrapezoid::new`] can give them.
struct Integral(Option<CumulativeTrapezoid>);

impl Integral {
    fn new(samples: &[(i64, f64)]) -> Self {
        let (t, y): (Vec<i64>, Vec<f64>) = samples.iter().copied().unzip();
        Self(CumulativeTrapezoid::new(&t, &y).ok())
    }

    /// The integral from `from` to `to` (flat outside the samples).
    fn between(&self, from: i64, to: i64) -> f64 {
        self.0.as_ref().map_or(0.0, |i| i.between(from, to))
    }
}

/// A piece of the commanded rate: `(from, to, speed)`, us on the robot's clock and deg/s.
type Piece = (i64, i64, f64);

/// The commanded rate's pieces.
fn commanded(log: &RobotLog) -> Vec<Piece> {
    log.rows
        .iter()
        .flat_map(|(_, t)| commanded_row(t))
        .collect()
}

/// One row's commanded rate: its speed from onset to end but during its stop.
fn commanded_row(t: &TrialMeta) -> Vec<Piece> {
    let v = t.speed_deg_s;
    match (t.stop_start_us, t.stop_end_us) {
        (Some(a), Some(b)) => vec![(t.motion_start_us, a, v), (b, t.motion_end_us, v)],
        _ => vec![(t.motion_start_us, t.motion_end_us, v)],
    }
}

/// `|w - bias|`, deg/s.
fn magnitude(w: [f64; 3], bias: [f64; 3]) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|i| w[i] - bias[i]);
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// The offset in `[lo, hi]` where `f` is largest: a scan at `step`, then scans ten times finer
/// around the best, down to [`FINEST_STEP_US`].
fn search(f: &dyn Fn(i64) -> f64, lo: i64, hi: i64, step: i64) -> i64 {
    let best_of = |from: i64, to: i64, step: i64| -> i64 {
        let mut best = (f64::NEG_INFINITY, from);
        let mut o = from;
        while o <= to {
            let c = f(o);
            if c > best.0 {
                best = (c, o);
            }
            o += step;
        }
        best.1
    };
    let mut step = step.max(FINEST_STEP_US);
    let mut best = best_of(lo, hi, step);
    while step > FINEST_STEP_US {
        let finer = (step / 10).max(FINEST_STEP_US);
        best = best_of((best - 2 * step).max(lo), (best + 2 * step).min(hi), finer);
        step = finer;
    }
    best
}

/// Every IMU sample of the recording at `path`, in time order, one per timestamp (a sample
/// repeated across packets counted once).
pub fn read_imu(path: &Path) -> Result<Vec<evtac_events::ImuSample>, evtac_events::Error> {
    let mut reader = evtac_events::open(path)?;
    let mut samples = Vec::new();
    while let Some(chunk) = reader.next_chunk()? {
        samples.extend_from_slice(chunk.imu);
    }
    samples.sort_by_key(|s| s.t);
    samples.dedup_by_key(|s| s.t);
    Ok(samples)
}

/// Finds the offset of `log` (on the robot's clock) that best aligns its commanded rate with the
/// gyroscope of `session`.
pub fn imu_offset(session: &Path, log: &RobotLog) -> Result<ImuFit, ImuSyncError> {
    let samples_3d = read_imu(session)?;
    let samples: Vec<(i64, f64)> = samples_3d
        .iter()
        .map(|s| (s.t, magnitude(s.gyroscope.map(f64::from), [0.0; 3])))
        .collect();
    let (Some(first), Some(last)) = (samples.first(), samples.last()) else {
        return Err(no_imu(session, 0));
    };
    let pieces = commanded(log);
    let (Some(log_from), Some(log_to)) = (
        pieces.iter().map(|p| p.0).min(),
        pieces.iter().map(|p| p.1).max(),
    ) else {
        return Err(no_imu(session, samples.len()));
    };
    if samples.len() < 2 {
        return Err(no_imu(session, samples.len()));
    }
    let (lo, hi) = (first.0 - log_from, last.0 - log_to);
    if lo > hi {
        return Err(ImuSyncError::TooLong {
            log: log.path.clone(),
            session: session.to_path_buf(),
            log_s: (log_to - log_from) as f64 * 1e-6,
            imu_s: (last.0 - first.0) as f64 * 1e-6,
        });
    }
    let rate = Integral::new(&samples);
    let correlation = |o: i64| -> f64 {
        pieces
            .iter()
            .map(|&(a, b, v)| v * rate.between(a + o, b + o))
            .sum()
    };
    let step = COARSE_STEP_US.max((hi - lo) / MAX_COARSE_STEPS);
    let rough = search(&correlation, lo, hi, step);
    // Again without each motion's gyroscope bias, taken where the labels take it.
    let still = LabelConfig::default();
    let rows: Vec<(Integral, Vec<Piece>)> = log
        .rows
        .iter()
        .map(|(_, t)| {
            let onset = t.motion_start_us + rough;
            let bias_from = onset - still.still_lead_in_us();
            let bias_to = onset - still.bias_margin_us;
            let around = &samples_3d[samples_3d.partition_point(|s| s.t < bias_from)
                ..samples_3d.partition_point(|s| s.t <= t.motion_end_us + rough + REFINE_US)];
            let rest: Vec<_> = around.iter().filter(|s| s.t <= bias_to).collect();
            let bias: [f64; 3] = std::array::from_fn(|i| {
                rest.iter().map(|s| f64::from(s.gyroscope[i])).sum::<f64>()
                    / rest.len().max(1) as f64
            });
            let magnitudes: Vec<(i64, f64)> = around
                .iter()
                .map(|s| (s.t, magnitude(s.gyroscope.map(f64::from), bias)))
                .collect();
            (Integral::new(&magnitudes), commanded_row(t))
        })
        .collect();
    let unbiased = |o: i64| -> f64 {
        rows.iter()
            .flat_map(|(rate, pieces)| {
                pieces
                    .iter()
                    .map(move |&(a, b, v)| v * rate.between(a + o, b + o))
            })
            .sum()
    };
    let best = search(
        &unbiased,
        (rough - REFINE_US).max(lo),
        (rough + REFINE_US).min(hi),
        REFINE_US / 20,
    );
    let span = (log_to - log_from) as f64 * 1e-6;
    let c2: f64 = pieces
        .iter()
        .map(|&(a, b, v)| v * v * (b - a) as f64 * 1e-6)
        .sum();
    let squares: Vec<(i64, f64)> = samples.iter().map(|&(t, g)| (t, g * g)).collect();
    let g2 = Integral::new(&squares).between(log_from + best, log_to + best);
    let sse = (g2 - 2.0 * correlation(best) + c2).max(0.0);
    Ok(ImuFit {
        offset_us: best,
        residual_deg_s: (sse / span.max(1e-6)).sqrt(),
    })
}

fn no_imu(session: &Path, samples: usize) -> ImuSyncError {
    ImuSyncError::NoImu {
        session: session.to_path_buf(),
        samples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_events::{EventWriter, ImuSample, Resolution};

    /// A session whose gyroscope turns at each motion's trapezoidal rate (200 deg/s^2 ramps)
    /// `offset` after the log says, plus a bias; the fit finds the offset.
    #[test]
    fn finds_the_offset_of_trapezoids_under_a_bias() {
        let dir = tempfile::tempdir().unwrap();
        let log_path = dir.path().join("log.csv");
        let text = "trial,direction_deg,speed_deg_s,depth_mm,total_deg,motion_start_us,\
                    motion_end_us\na,0,10,1.5,20,1000000,3050000\nb,0,4,1.5,20,5000000,10020000\n";
        std::fs::write(&log_path, text).unwrap();
        let log = RobotLog::read(&log_path, 0).unwrap();
        let offset = 1_234_567;
        let rate = |t: i64| -> f64 {
            let t = t - offset;
            let trapezoid = |a: i64, b: i64, v: f64| {
                let ramp = v / 200.0;
                let (x, y) = ((t - a) as f64 * 1e-6, (b - t) as f64 * 1e-6);
                if x < 0.0 || y < 0.0 {
                    0.0
                } else {
                    v * (x / ramp).min(y / ramp).min(1.0)
                }
            };
            trapezoid(1_000_000, 3_050_000, 10.0) + trapezoid(5_000_000, 10_020_000, 4.0)
        };
        let imu: Vec<ImuSample> = (0..16_000)
            .map(|k| {
                let t = k * 1250;
                ImuSample {
                    t,
                    gyroscope: [0.3, rate(t) as f32, -0.2],
                    ..ImuSample::default()
                }
            })
            .collect();
        let session = dir.path().join("s.aedat4");
        let mut w = EventWriter::create(&session, Some(Resolution::new(640, 480)), None).unwrap();
        w.write_imu(&imu).unwrap();
        w.finish().unwrap();
        let fit = imu_offset(&session, &log).unwrap();
        // Within a fifth of the 1250 us sample period: the samples' phase at the edges (the
        // same at every edge here) is what is left.
        assert!((fit.offset_us - offset).abs() <= 250, "{fit:?}");
        assert!(fit.residual_deg_s < 1.0, "{fit:?}");

        // A log longer than the recording cannot fit.
        let long = RobotLog::parse(
            &text.replace("10020000", "30000000"),
            Path::new("log.csv"),
            0,
        )
        .unwrap();
        let err = imu_offset(&session, &long).unwrap_err().to_string();
        // Nor can a session without IMU.
        let silent = dir.path().join("silent.aedat4");
        EventWriter::create(&silent, Some(Resolution::new(640, 480)), None)
            .unwrap()
            .finish()
            .unwrap();
        let none = imu_offset(&silent, &log).unwrap_err().to_string();
        assert!(none.contains("silent.aedat4: 0 IMU sample(s)"), "{none}");
        assert!(
            err.starts_with("log.csv: its motions span 29.000 s, longer than the 19.999"),
            "{err}"
        );
    }
}
