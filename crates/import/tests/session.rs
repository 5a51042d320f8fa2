//! A simulated session (`evtac simulate --session`) imported back into a dataset, its log put
//! on the recording's clock by each sync mode, or its motions found in the gyroscope without
//! the log: its labels match the simulator's truth as closely as the per-trial simulated
//! dataset's do.

use evtac_events::Trigger;
use evtac_events::manifest::{Manifest, TrialMeta};
use evtac_import::check::check;
use evtac_import::import::{ImportConfig, NoContact, import_session};
use evtac_import::imu_sync::{imu_offset_whole, read_imu};
use evtac_import::inputs::Inputs;
use evtac_import::motions::{FindConfig, as_log, find_motions, find_motions_in};
use evtac_import::robot_log::RobotLog;
use evtac_import::sync::{Sync, SyncError, synchronise};
use evtac_labels::dataset::{label_trial, read_calibration, read_calibration_file};
use evtac_labels::{LabelConfig, LabelSeries, TruthError};
use evtac_sim::{
    Protocol, Scale, SessionConfig, SessionRecord, simulate_dataset, simulate_session,
};
use std::path::Path;

/// The labels' worst per-trial RMS error against the truth the issue allows, degrees.
const RMS_LIMIT_DEG: f64 = 0.05;

/// A tiny Experiment 2 session of four trials (stops exercise every logged time).
fn session_config() -> SessionConfig {
    let mut config = SessionConfig::new(Protocol::Exp2, Scale::Tiny, 3);
    config.dataset.limit = Some(4);
    // The sensor seated without a turn: the labels keep the commanded rolling axis, so a turn
    // would show against the truth (sensor frame) as the rig's error, not the import's, and
    // would move the direction the gyroscope finds off the commanded one.
    config.dataset.params.rig.reseat_rotation_sd_deg = 0.0;
    config
}

/// Simulates the session into `dir/session`.
pub fn simulate(dir: &Path) -> SessionRecord {
    simulate_session(&session_config(), &dir.join("session"), |_| {}).unwrap()
}

/// Imports `dir/session` cut by `log` into `dir/<name>`, checked.
pub fn import(dir: &Path, log: &RobotLog, name: &str) -> std::path::PathBuf {
    let session = dir.join("session");
    let out = dir.join(name);
    let config = ImportConfig {
        pre_us: 1_000_000,
        post_us: 300_000,
        no_contact: Some(NoContact::File(session.join("no_contact.aedat4"))),
        calibration: Some(session.join("calibration.json")),
        labels: evtac_labels::LabelSource::Imu,
        filters: Vec::new(),
    };
    import_session(&session.join("session.aedat4"), log, &out, &config, &|| {}).unwrap();
    assert_eq!(check(&out, &Inputs::FROM_FILES, &|_| {}).problems, []);
    out
}

/// Each trial's labels' RMS error against the truth in `truth_dir` (the trial's `truth` file
/// names it relative to there), in manifest order.
pub fn label_errors(dataset: &Path, truth_dir: &Path, truths: &Manifest) -> Vec<f64> {
    let manifest = Manifest::read(dataset).unwrap();
    let calibration = read_calibration(dataset).unwrap();
    manifest
        .trials
        .iter()
        .zip(&truths.trials)
        .map(|(meta, truth)| {
            assert_eq!(meta.trial, truth.trial);
            let labels = label_trial(dataset, meta, &calibration, &LabelConfig::default())
                .unwrap()
                .labels;
            let truth =
                LabelSeries::read_csv(truth_dir.join(truth.truth.as_ref().unwrap())).unwrap();
            TruthError::compare(&labels, &truth).unwrap().rms_deg
        })
        .collect()
}

/// The per-trial simulated dataset's errors: the bar an import must meet.
pub fn per_trial_errors(dir: &Path) -> Vec<f64> {
    let ds = dir.join("per-trial");
    let manifest = simulate_dataset(&session_config().dataset, &ds, |_| {}).unwrap();
    label_errors(&ds, &ds, &manifest)
}

/// The imported labels are as close to the truth as the per-trial dataset's: each within the
/// issue's limit, and no worse than the per-trial dataset's by more than a tenth of it.
pub fn assert_as_close(imported: &[f64], per_trial: &[f64]) {
    assert_eq!(imported.len(), per_trial.len());
    for (i, (a, b)) in imported.iter().zip(per_trial).enumerate() {
        assert!(
            *a <= RMS_LIMIT_DEG && *b <= RMS_LIMIT_DEG,
            "trial {i}: {a} / {b}"
        );
        assert!(*a <= b + 0.1 * RMS_LIMIT_DEG, "trial {i}: {a} vs {b}");
    }
}

#[test]
fn a_session_imported_with_its_clock_offset_labels_as_well_as_per_trial_files() {
    let dir = tempfile::tempdir().unwrap();
    let record = simulate(dir.path());
    let log = RobotLog::read(
        &dir.path().join("session/robot_log.csv"),
        record.clock_offset_us,
    )
    .unwrap();
    // The logged onsets are the true ones but for the jitter.
    for ((_, row), truth) in log.rows.iter().zip(&record.trials) {
        let error = row.motion_start_us - truth.motion_start_us;
        assert!(error.abs() <= record.jitter_us, "{error}");
    }
    let out = import(dir.path(), &log, "imported");
    let truths = Manifest {
        trials: record.trials.clone(),
    };
    let imported = label_errors(&out, &dir.path().join("session"), &truths);
    let per_trial = per_trial_errors(dir.path());
    eprintln!("labels vs truth, RMS deg: imported {imported:?}, per-trial {per_trial:?}");
    assert_as_close(&imported, &per_trial);
}

#[test]
fn a_session_synchronised_by_its_triggers_labels_as_well_as_per_trial_files() {
    let dir = tempfile::tempdir().unwrap();
    let record = simulate(dir.path());
    let session = dir.path().join("session");
    let log = RobotLog::read(&session.join("robot_log.csv"), 0).unwrap();
    let synced = synchronise(
        &session.join("session.aedat4"),
        log.clone(),
        Sync::Trigger(Trigger::RISING_EDGE),
    )
    .unwrap();
    // Each row's onset is its trigger, so exactly the true onset; the other times are off by
    // at most the jitter of two logged times.
    for ((_, row), truth) in synced.log.rows.iter().zip(&record.trials) {
        assert_eq!(row.motion_start_us, truth.motion_start_us);
        let error = row.motion_end_us - truth.motion_end_us;
        assert!(error.abs() <= 2 * record.jitter_us, "{error}");
    }
    let [lo, _, hi] = synced.offset_range().unwrap();
    assert!(
        (lo - record.clock_offset_us).abs() <= record.jitter_us
            && (hi - record.clock_offset_us).abs() <= record.jitter_us,
        "{lo} .. {hi} vs {}",
        record.clock_offset_us
    );
    let out = import(dir.path(), &synced.log, "imported");
    let truths = Manifest {
        trials: record.trials.clone(),
    };
    let imported = label_errors(&out, &session, &truths);
    let per_trial = per_trial_errors(dir.path());
    eprintln!("labels vs truth, RMS deg: imported {imported:?}, per-trial {per_trial:?}");
    assert_as_close(&imported, &per_trial);

    // A motion logged a second late is paired with a trigger a second early: its line is named.
    let mut late = log.clone();
    late.rows[2].1.motion_start_us += 1_000_000;
    late.rows[2].1.motion_end_us += 1_000_000;
    let err = synchronise(
        &session.join("session.aedat4"),
        late,
        Sync::Trigger(Trigger::RISING_EDGE),
    )
    .unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, SyncError::TriggerJump { .. }), "{text}");
    assert!(
        text.contains("robot_log.csv:4: column `motion_start_us`")
            && text.contains("off the motion before it (line 3)"),
        "{text}"
    );

    // A log with a row fewer than the triggers names both files.
    let mut short = log;
    short.rows.pop();
    let err = synchronise(
        &session.join("session.aedat4"),
        short,
        Sync::Trigger(Trigger::RISING_EDGE),
    )
    .unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, SyncError::TriggerCount { .. }), "{text}");
    assert!(
        text.contains("session.aedat4: 4 trigger(s) of type 1")
            && text.contains("robot_log.csv has 3 row(s)"),
        "{text}"
    );
}

#[test]
fn a_session_synchronised_by_its_imu_recovers_the_offset_within_a_millisecond() {
    let dir = tempfile::tempdir().unwrap();
    let record = simulate(dir.path());
    let session = dir.path().join("session");
    let log = RobotLog::read(&session.join("robot_log.csv"), 0).unwrap();
    let synced = synchronise(&session.join("session.aedat4"), log, Sync::Imu).unwrap();
    let [lo, offset, hi] = synced.offset_range().unwrap();
    assert_eq!(lo, hi, "one offset for every row");
    let residual = synced.residual_deg_s.unwrap();
    eprintln!(
        "offset from the IMU {offset} us, true {} us, residual {residual:.3} deg/s",
        record.clock_offset_us
    );
    assert!((offset - record.clock_offset_us).abs() <= 1000);
    // The gyroscope's bias and the log's missing accelerations, nothing more.
    assert!(residual < 1.5, "{residual}");
    // Found in passes over the IMU, holding none of it: the whole IMU's fit, bit for bit.
    let log = RobotLog::read(&session.join("robot_log.csv"), 0).unwrap();
    let whole = imu_offset_whole(&session.join("session.aedat4"), &log).unwrap();
    assert_eq!(
        (offset, residual.to_bits()),
        (whole.offset_us, whole.residual_deg_s.to_bits())
    );
    let out = import(dir.path(), &synced.log, "imported");
    let truths = Manifest {
        trials: record.trials.clone(),
    };
    let imported = label_errors(&out, &session, &truths);
    assert_as_close(&imported, &per_trial_errors(dir.path()));
}

#[test]
fn a_session_imported_without_its_log_finds_every_motion_and_labels_as_well_as_per_trial_files() {
    let dir = tempfile::tempdir().unwrap();
    let record = simulate(dir.path());
    let session = dir.path().join("session");
    let imu = read_imu(&session.join("session.aedat4")).unwrap();
    let calibration = read_calibration_file(&session.join("calibration.json")).unwrap();
    let found = find_motions(&imu, &calibration, &FindConfig::new(1.5));
    assert_eq!(
        found.len(),
        record.trials.len(),
        "every motion, nothing else"
    );
    // What `evtac import` runs: read as the search goes, forgotten behind it, the same motions.
    let streamed = find_motions_in(
        &session.join("session.aedat4"),
        &calibration,
        &FindConfig::new(1.5),
    )
    .unwrap();
    assert_eq!(streamed.found, found);
    assert!(
        streamed.peak_samples < imu.len() / 2,
        "held {} of {} samples",
        streamed.peak_samples,
        imu.len()
    );
    let mut onset_errors_ms = Vec::new();
    for (m, truth) in found.iter().zip(&record.trials) {
        let t = &m.meta;
        let error_us = t.motion_start_us - truth.motion_start_us;
        onset_errors_ms.push(error_us as f64 * 1e-3);
        assert!(
            error_us.abs() <= 20_000,
            "{}: onset off by {error_us} us",
            truth.trial
        );
        // Rounded to whole degrees and deg/s, the gyroscope's values are the commanded ones.
        assert_eq!(
            (t.direction_deg, t.speed_deg_s, t.total_deg),
            (truth.direction_deg, truth.speed_deg_s, truth.total_deg),
            "{}: {m:?}",
            truth.trial
        );
        // Experiment 2's stop is a pause inside the motion, not a motion of its own.
        assert_eq!(m.pauses, 1, "{}", truth.trial);
    }
    let log = as_log(&session.join("session.aedat4"), &found);
    let out = import(dir.path(), &log, "imported");
    // The motions are named in the order found, which is the truth's.
    let truths = Manifest {
        trials: record
            .trials
            .iter()
            .zip(&found)
            .map(|(truth, m)| TrialMeta {
                trial: m.meta.trial.clone(),
                ..truth.clone()
            })
            .collect(),
    };
    let imported = label_errors(&out, &session, &truths);
    let per_trial = per_trial_errors(dir.path());
    eprintln!(
        "log-free: onset errors {onset_errors_ms:?} ms; labels vs truth, RMS deg: imported \
         {imported:?}, per-trial {per_trial:?}"
    );
    assert_as_close(&imported, &per_trial);
}
