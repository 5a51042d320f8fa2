//! A recording session as a real rig writes it (`evtac simulate --session`): one AEDAT4 file
//! with every trial of a protocol back to back, still idle time between them, a trigger at each
//! motion's onset, and the robot's log of its motions on the robot's own clock.
//!
//! ```text
//! SESSION/session.aedat4     idle, trial, idle, trial, ..., idle; a trigger at each onset
//! SESSION/robot_log.csv      one row per motion (evtac import's log), on the robot's clock
//! SESSION/no_contact.aedat4  the sensor at rest out of contact (as in a dataset)
//! SESSION/calibration.json   the IMU-to-sensor rotation (as in a dataset)
//! SESSION/truth/<trial>.csv  the pose reached (sensor frame), on the session's clock
//! SESSION/session.json       the settings, the true clock offset and the true trial times
//! ```
//!
//! The session's clock starts at [`SessionConfig::start_us`] (DV stamps with Unix time). The
//! robot's clock is the session's minus a clock offset drawn from the seed (recording time =
//! robot time + offset, `evtac import`'s convention), and every time the robot logs is off by
//! its own jitter, uniform within [`SessionConfig::jitter_us`], as a controller's timestamps
//! are. The idle time is still: the sensor is lifted off the plane and does not turn, so the
//! gyroscope only sees the logged motions. The trials are those of the dataset with the same
//! configuration (same camera, same trial seeds), so a session and a per-trial dataset can be
//! compared trial by trial.

use std::path::Path;

use evtac_events::Trigger;
use evtac_events::layout::{
    ROBOT_LOG_FILE, SESSION_FILE, SESSION_RECORD_FILE, TRUTH_DIR, trial_file,
};
use evtac_events::manifest::{Manifest, TrialMeta};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

use crate::dataset::{
    DatasetConfig, DatasetError, Setup, aedat_error, create_writer, set_up, write_json,
    write_shifted, write_truth,
};
use crate::params::SimParams;
use crate::protocol::{Protocol, Scale, trial_seed};

/// Trials simulated at once before being written in order: enough to keep every worker busy,
/// few enough to keep a paper-scale session's memory bounded.
const BATCH: usize = 8;

/// What to simulate as one session.
#[derive(Debug, Clone, PartialEq)]
pub struct SessionConfig {
    /// The trials (protocol, scale, seed, parameters, compression, limit).
    pub dataset: DatasetConfig,
    /// The still time before, between and after the trials, seconds: each drawn uniformly
    /// from this range.
    pub gap_s: [f64; 2],
    /// The session's clock at its start, microseconds.
    pub start_us: i64,
    /// The largest clock offset drawn (either sign), microseconds.
    pub max_clock_offset_us: i64,
    /// The largest error of a logged time (either sign), microseconds.
    pub jitter_us: i64,
}

impl SessionConfig {
    /// A session of `protocol` at `scale`: gaps of 1 to 3 s, the clock at 2026-01-01 00:00 UTC,
    /// an offset of up to a minute and a jitter of up to 300 us.
    pub fn new(protocol: Protocol, scale: Scale, seed: u64) -> Self {
        Self {
            dataset: DatasetConfig::new(protocol, scale, seed),
            gap_s: [1.0, 3.0],
            start_us: 1_767_225_600_000_000,
            max_clock_offset_us: 60_000_000,
            jitter_us: 300,
        }
    }
}

/// What `session.json` holds, and what [`simulate_session`] returns.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SessionRecord {
    /// The program that wrote the session.
    pub generator: String,
    /// The protocol.
    pub protocol: Protocol,
    /// The scale.
    pub scale: Scale,
    /// The seed.
    pub seed: u64,
    /// The session's clock at its start, microseconds.
    pub start_us: i64,
    /// The session's clock minus the robot's, microseconds: `--clock-offset-us` for the log.
    pub clock_offset_us: i64,
    /// The largest error of a logged time, microseconds.
    pub jitter_us: i64,
    /// The range the still gaps were drawn from, seconds.
    pub gap_s: [f64; 2],
    /// The trials as they happened, on the session's clock (the log's rows without the clock
    /// offset and the jitter), with their truth files.
    pub trials: Vec<TrialMeta>,
    /// The simulator's parameters.
    pub params: SimParams,
}

/// The seeds of a session's own draws (clock offset, gaps, jitter) and of its idle stretches,
/// apart from those of the dataset (camera, no-contact recording, protocols).
const SESSION_STREAM: usize = usize::MAX - 16;

/// A session's random draws, all made up front so that they do not depend on the batching.
struct Draws {
    /// Recording time minus robot time, us.
    clock_offset_us: i64,
    /// The still time before each trial and after the last, us.
    gaps_us: Vec<i64>,
    /// Each row's logged errors: onset, end, stop start, stop end, us.
    jitters: Vec<[i64; 4]>,
}

impl Draws {
    fn new(config: &SessionConfig, seed: u64, trials: usize, period_us: i64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let max_offset = config.max_clock_offset_us.abs();
        let clock_offset_us = rng.random_range(-max_offset..=max_offset);
        let [lo, hi] = config.gap_s;
        let gaps_us = (0..=trials)
            .map(|_| {
                let s = lo + (hi - lo).max(0.0) * rng.random::<f64>();
                ((s * 1e6 / period_us as f64).round() as i64).max(1) * period_us
            })
            .collect();
        let jitter = config.jitter_us.abs();
        let jitters = (0..trials)
            .map(|_| std::array::from_fn(|_| rng.random_range(-jitter..=jitter)))
            .collect();
        Self {
            clock_offset_us,
            gaps_us,
            jitters,
        }
    }
}

/// Simulates the session `config` into `out_dir` (created if missing; files of the same names
/// are replaced). `on_trial` is called after each trial is written, with its true row.
pub fn simulate_session(
    config: &SessionConfig,
    out_dir: &Path,
    on_trial: impl Fn(&TrialMeta),
) -> Result<SessionRecord, DatasetError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| DatasetError::Io { path, source }
    };
    let dataset = &config.dataset;
    let Setup {
        sim,
        resolution,
        trials,
    } = set_up(dataset, out_dir, &crate::capture::AsSimulated)?;

    // Gaps are whole IMU periods, so that the IMU keeps its rate across the whole session.
    let period_us = (1e6 / dataset.params.imu.rate_hz.max(1.0)).round().max(1.0) as i64;
    let session_seed = trial_seed(dataset.seed, SESSION_STREAM);
    let draws = Draws::new(config, session_seed, trials.len(), period_us);
    let Draws {
        clock_offset_us,
        gaps_us,
        jitters,
    } = &draws;
    let clock_offset_us = *clock_offset_us;
    let idle = |k: usize| {
        sim.simulate_idle(
            "idle",
            trial_seed(session_seed, k),
            gaps_us[k] as f64 * 1e-6,
        )
    };

    let session_path = out_dir.join(SESSION_FILE);
    let mut writer = create_writer(&session_path, resolution, dataset.compression)?;
    let total = dataset.params.timeline.total_deg;
    let mut t0 = config.start_us;
    let mut truths = Vec::with_capacity(trials.len());
    let mut logged = Vec::with_capacity(trials.len());
    for (b, batch) in trials.chunks(BATCH).enumerate() {
        let done: Vec<_> = batch
            .par_iter()
            .enumerate()
            .map(|(i, spec)| (idle(b * BATCH + i), sim.simulate(spec)))
            .collect();
        for (i, (gap, recording)) in done.iter().enumerate() {
            let k = b * BATCH + i;
            write_shifted(&mut writer, gap, t0, gaps_us[k]).map_err(aedat_error(&session_path))?;
            t0 += gaps_us[k];
            let onset = Trigger {
                t: t0 + recording.motion_start_us,
                kind: Trigger::RISING_EDGE,
            };
            writer
                .write_triggers(&[onset])
                .map_err(aedat_error(&session_path))?;
            write_shifted(&mut writer, recording, t0, i64::MAX)
                .map_err(aedat_error(&session_path))?;
            let name = &recording.spec.name;
            let truth = format!("{TRUTH_DIR}/{name}.csv");
            write_truth(&out_dir.join(&truth), &recording.truth, t0)?;
            let mut meta = recording.meta(&trial_file(name), Some(&truth), total);
            meta.shift(t0);
            let mut robot = meta.clone();
            robot.shift(-clock_offset_us);
            let [start, end, stop_start, stop_end] = jitters[k];
            robot.motion_start_us += start;
            robot.motion_end_us += end;
            robot.stop_start_us = robot.stop_start_us.map(|t| t + stop_start);
            robot.stop_end_us = robot.stop_end_us.map(|t| t + stop_end);
            on_trial(&meta);
            truths.push(meta);
            logged.push(robot);
            // The next stretch starts one IMU period after this one's last sample.
            t0 += (recording.duration_us / period_us + 1) * period_us;
        }
    }
    let tail = idle(trials.len());
    write_shifted(&mut writer, &tail, t0, gaps_us[trials.len()])
        .map_err(aedat_error(&session_path))?;
    writer.finish().map_err(aedat_error(&session_path))?;

    let log = Manifest { trials: logged }.to_log_csv()?;
    let log_path = out_dir.join(ROBOT_LOG_FILE);
    std::fs::write(&log_path, log).map_err(io(&log_path))?;
    let record = SessionRecord {
        generator: format!("evtac-sim {}", env!("CARGO_PKG_VERSION")),
        protocol: dataset.protocol,
        scale: dataset.scale,
        seed: dataset.seed,
        start_us: config.start_us,
        clock_offset_us,
        jitter_us: config.jitter_us.abs(),
        gap_s: config.gap_s,
        trials: truths,
        params: dataset.params.clone(),
    };
    write_json(&out_dir.join(SESSION_RECORD_FILE), &record)?;
    Ok(record)
}
