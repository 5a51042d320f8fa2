//! Labelling dataset folders: files in, `labels/<trial>.csv` out, errors that name the trial.

use std::path::Path;

use evtac_events::manifest::{Manifest, TrialMeta};
use evtac_events::{Event, ImuSample, Resolution};
use evtac_formats::EventWriter;
use evtac_labels::dataset::{label_and_write, labels_path};
use evtac_labels::geometry::Calibration;
use evtac_labels::{
    CalibrationSource, LabelConfig, LabelSeries, dataset_calibration, label_dataset, label_trial,
    read_calibration,
};

use crate::synthetic::{Gyro, Profile, rotated_calibration};

fn write_recording(path: &Path, imu: &[ImuSample]) {
    let mut w = EventWriter::create(path, Some(Resolution::new(640, 480)), Some("test")).unwrap();
    let events = [Event {
        t: 10,
        x: 3,
        y: 4,
        polarity: true,
    }];
    w.write_events(&events).unwrap();
    if !imu.is_empty() {
        w.write_imu(imu).unwrap();
    }
    w.finish().unwrap();
}

fn meta(name: &str, profile: &Profile) -> TrialMeta {
    let m = profile.motion;
    TrialMeta {
        trial: name.into(),
        file: format!("{name}.aedat4").into(),
        truth: Some(format!("truth/{name}.csv").into()),
        direction_deg: m.direction_deg,
        speed_deg_s: m.speed_deg_s,
        depth_mm: 2.0,
        total_deg: m.total_deg,
        motion_start_us: m.motion_start_us,
        motion_end_us: m.motion_end_us,
        stop_start_us: m.stop.map(|s| s.start_us),
        stop_end_us: m.stop.map(|s| s.end_us),
        stop_deg: m.stop.map(|s| s.deg),
        group: None,
    }
}

/// A dataset of four trials (two with a stop) recorded through rotated extrinsics.
fn dataset(dir: &Path) -> (Manifest, Calibration) {
    let calibration = rotated_calibration();
    let mut trials = Vec::new();
    for k in 0..4u64 {
        let name = format!("t{k:04}");
        let stop = (k % 2 == 1).then_some((6.0 + k as f64, 500_000));
        let profile = Profile::new(
            90.0 * k as f64 + 9.0,
            4.0 + 2.0 * k as f64,
            200.0,
            20.0,
            stop,
            600_000,
        );
        let imu = Gyro::realistic().record(&profile, &calibration, 40 + k);
        write_recording(&dir.join(format!("{name}.aedat4")), &imu);
        profile
            .truth(1_000)
            .write_csv(dir.join(format!("truth/{name}.csv")))
            .unwrap();
        trials.push(meta(&name, &profile));
    }
    let manifest = Manifest { trials };
    manifest.write(dir).unwrap();
    std::fs::write(
        dir.join("calibration.json"),
        serde_json::to_string(&calibration).unwrap(),
    )
    .unwrap();
    (manifest, calibration)
}

#[test]
fn labels_every_trial_and_writes_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let (manifest, calibration) = dataset(dir.path());
    assert_eq!(read_calibration(dir.path()).unwrap(), calibration);
    let mut seen = Vec::new();
    let result = label_dataset(dir.path(), &LabelConfig::default(), |r| {
        seen.push(r.trial.clone())
    })
    .unwrap();
    assert_eq!(seen, ["t0000", "t0001", "t0002", "t0003"]);
    assert_eq!(result.stop_error_deg.unwrap().n, 2);
    let rms = result.truth_rms_deg.unwrap();
    assert_eq!(rms.n, 4);
    assert!(rms.max <= 0.05, "{rms}");
    for meta in &manifest.trials {
        let written = LabelSeries::read_csv(labels_path(dir.path(), &meta.trial)).unwrap();
        let labels = label_trial(dir.path(), meta, &calibration, &LabelConfig::default()).unwrap();
        assert_eq!(written, labels.labels);
    }
    let report = &result.trials[1];
    assert_eq!(report.labels_file, Path::new("labels/t0001.csv"));
    assert!(report.stop.unwrap().error_deg.abs() < 0.02);
}

#[test]
fn a_recording_without_imu_names_the_trial() {
    let dir = tempfile::tempdir().unwrap();
    let (manifest, calibration) = dataset(dir.path());
    write_recording(&dir.path().join("t0002.aedat4"), &[]);
    let err = label_dataset(dir.path(), &LabelConfig::default(), |_| {}).unwrap_err();
    assert_eq!(
        err.to_string(),
        "trial `t0002`: the recording has no IMU stream (0 IMU samples)"
    );
    std::fs::remove_file(dir.path().join("t0001.aedat4")).unwrap();
    let err = label_and_write(
        dir.path(),
        &manifest.trials[1],
        &calibration,
        &LabelConfig::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("trial `t0001`: cannot read the recording"),
        "{err}"
    );
    assert!(err.contains("t0001.aedat4"), "{err}");
}

#[test]
fn calibration_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let err = read_calibration(dir.path()).unwrap_err().to_string();
    assert!(err.contains("calibration.json"), "{err}");
    assert!(err.contains("--identity-calibration"), "{err}");
    assert_eq!(
        dataset_calibration(dir.path(), CalibrationSource::Identity).unwrap(),
        Calibration::default()
    );
    let mut skewed = Calibration::default();
    skewed.imu_to_sensor[0][0] = 1.1;
    std::fs::write(
        dir.path().join("calibration.json"),
        serde_json::to_string(&skewed).unwrap(),
    )
    .unwrap();
    let err = read_calibration(dir.path()).unwrap_err().to_string();
    assert!(err.contains("not a rotation"), "{err}");
}
