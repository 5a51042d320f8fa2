//! A dataset without `calibration.json` or `no_contact.aedat4` is refused, naming the file and
//! the flag that opts out; opting out gives the identity rotation or no mask, and labels of one
//! calibration are never reused with another.

use crate::simulate;
use evtac_events::layout::{CALIBRATION_FILE, NO_CONTACT_FILE};
use evtac_experiments::cache::FeatureCache;
use evtac_experiments::dataset::Dataset;
use evtac_experiments::plan;
use evtac_experiments::sampling::Sampling;
use evtac_import::inputs::{Inputs, MaskSource};
use evtac_labels::CalibrationSource;
use evtac_labels::geometry::Calibration;
use evtac_sim::Protocol;

#[test]
fn missing_files_are_refused_unless_opted_out() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path(), Protocol::Exp1, 1);
    let static_config = plan::static_config(1000.0, 2.0);

    // Both files present: both used.
    let ds = Dataset::open(dir.path(), Inputs::FROM_FILES).unwrap();
    assert_ne!(
        ds.calibration,
        Calibration::default(),
        "the simulator rotates its IMU"
    );
    let no_contact = ds.no_contact().unwrap();
    assert!(no_contact.as_ref().is_some_and(|nc| !nc.cropped.is_empty()));
    assert!(
        ds.mask_for(&static_config, no_contact.as_ref())
            .unwrap()
            .is_some()
    );

    // Opting out is honoured even when the files are there.
    let out = Inputs::from_flags(true, true);
    let ds = Dataset::open(dir.path(), out.clone()).unwrap();
    assert_eq!(ds.calibration, Calibration::default());
    assert!(ds.no_contact().unwrap().is_none());

    std::fs::remove_file(dir.path().join(CALIBRATION_FILE)).unwrap();
    let err = Dataset::open(dir.path(), Inputs::FROM_FILES)
        .unwrap_err()
        .to_string();
    assert!(err.contains(CALIBRATION_FILE), "{err}");
    assert!(err.contains("--identity-calibration"), "{err}");
    let identity = Inputs {
        calibration: CalibrationSource::Identity,
        mask: MaskSource::NoContact,
        filters: Vec::new(),
    };
    let ds = Dataset::open(dir.path(), identity.clone()).unwrap();
    assert_eq!(ds.calibration, Calibration::default());
    assert!(ds.no_contact().unwrap().is_some());

    std::fs::remove_file(dir.path().join(NO_CONTACT_FILE)).unwrap();
    let err = Dataset::open(dir.path(), identity).unwrap_err().to_string();
    assert!(err.contains(NO_CONTACT_FILE), "{err}");
    assert!(err.contains("--no-mask"), "{err}");
    let ds = Dataset::open(dir.path(), out).unwrap();
    assert!(ds.no_contact().unwrap().is_none());
    assert!(ds.mask_for(&static_config, None).unwrap().is_none());
}

/// Regression: labels (and the labels at samples in the feature cache) computed with one
/// calibration were silently reused after the dataset was opened with another.
#[test]
fn labels_of_one_calibration_are_not_reused_with_another() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path(), Protocol::Exp1, 1);
    let labels_and_samples = |inputs: Inputs| {
        let ds = Dataset::open(dir.path(), inputs)?;
        let meta = ds.manifest.trials[0].clone();
        let labels = ds.labels(&meta)?;
        let cache = FeatureCache::new(&ds).unwrap();
        let samples = cache.samples(&meta, Sampling::MOTION).unwrap().labels;
        Ok::<_, evtac_experiments::dataset::Error>((labels.pitch_deg, samples))
    };
    let original = labels_and_samples(Inputs::FROM_FILES).unwrap();
    // The identity (the simulator turns its IMU 90 degrees) cannot label the trial: an error,
    // not the file calibration's labels.
    assert!(labels_and_samples(Inputs::from_flags(true, false)).is_err());
    // The calibration file turned by 3 degrees about z: labels and samples computed afresh.
    let path = dir.path().join(CALIBRATION_FILE);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut turned: Calibration = serde_json::from_str(&text).unwrap();
    let (s, c) = 3f64.to_radians().sin_cos();
    let m = turned.imu_to_sensor;
    turned.imu_to_sensor = std::array::from_fn(|j| {
        std::array::from_fn(|k| match j {
            0 => c * m[0][k] - s * m[1][k],
            1 => s * m[0][k] + c * m[1][k],
            _ => m[2][k],
        })
    });
    std::fs::write(&path, serde_json::to_string(&turned).unwrap()).unwrap();
    let other = labels_and_samples(Inputs::FROM_FILES).unwrap();
    assert_ne!(original.0, other.0, "labels reused across calibrations");
    assert_ne!(original.1, other.1, "samples reused across calibrations");
    // The original file again: its labels, unchanged.
    std::fs::write(&path, text).unwrap();
    assert_eq!(labels_and_samples(Inputs::FROM_FILES).unwrap(), original);
}
