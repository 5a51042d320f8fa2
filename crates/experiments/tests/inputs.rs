//! A dataset without `calibration.json` or `no_contact.aedat4` is refused, naming the file and
//! the flag that opts out; opting out gives the identity rotation or no mask.

use crate::simulate;
use evtac_events::layout::{CALIBRATION_FILE, NO_CONTACT_FILE};
use evtac_experiments::dataset::Dataset;
use evtac_experiments::inputs::{Inputs, MaskSource};
use evtac_experiments::plan;
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
    let events = ds.no_contact_events().unwrap();
    assert!(events.as_ref().is_some_and(|e| !e.is_empty()));
    assert!(
        ds.mask_for(&static_config, events.as_deref())
            .unwrap()
            .is_some()
    );

    // Opting out is honoured even when the files are there.
    let out = Inputs::from_flags(true, true);
    let ds = Dataset::open(dir.path(), out).unwrap();
    assert_eq!(ds.calibration, Calibration::default());
    assert!(ds.no_contact_events().unwrap().is_none());

    std::fs::remove_file(dir.path().join(CALIBRATION_FILE)).unwrap();
    let err = Dataset::open(dir.path(), Inputs::FROM_FILES)
        .unwrap_err()
        .to_string();
    assert!(err.contains(CALIBRATION_FILE), "{err}");
    assert!(err.contains("--identity-calibration"), "{err}");
    let identity = Inputs {
        calibration: CalibrationSource::Identity,
        mask: MaskSource::NoContact,
    };
    let ds = Dataset::open(dir.path(), identity).unwrap();
    assert_eq!(ds.calibration, Calibration::default());
    assert!(ds.no_contact_events().unwrap().is_some());

    std::fs::remove_file(dir.path().join(NO_CONTACT_FILE)).unwrap();
    let err = Dataset::open(dir.path(), identity).unwrap_err().to_string();
    assert!(err.contains(NO_CONTACT_FILE), "{err}");
    assert!(err.contains("--no-mask"), "{err}");
    let ds = Dataset::open(dir.path(), out).unwrap();
    assert!(ds.no_contact_events().unwrap().is_none());
    assert!(ds.mask_for(&static_config, None).unwrap().is_none());
}
