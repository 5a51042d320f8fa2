//! The dataset folder: the one place its file and folder names are spelled.
//!
//! A dataset is a folder that `evtac simulate` (or an import of real recordings) writes and that
//! `labels`, `tune`, `train`, `evaluate` and `reproduce` read:
//!
//! ```text
//! DATASET/
//!   trials.csv          the manifest: one row per trial (crate::manifest)
//!   <trial files>       one recording per trial, named in trials.csv's `file` column
//!   calibration.json    the IMU-to-sensor rotation (evtac-labels)
//!   no_contact.aedat4   a recording without contact, for the static representation's mask
//!   label_source.json   labels from the commanded motion instead of the IMU (evtac-labels)
//!   labels/<trial>.csv  (pitch, roll) over time, computed from the IMU (evtac-labels)
//!   truth/<trial>.csv   the simulator's true angles (simulated datasets only)
//!   simulator.json      how the simulator made it (simulated datasets only)
//!   splits.json         the train/validation/test trials (evtac-experiments)
//!   cache/              features per representation config (evtac-experiments)
//! ```
//!
//! A session folder is what a rig writes in one sitting, before `evtac import` cuts it into a
//! dataset; `evtac simulate --session` writes one:
//!
//! ```text
//! SESSION/
//!   session.aedat4      every trial back to back: events, IMU, a trigger at each motion onset
//!   robot_log.csv       the robot's log of its motions, on the robot's clock
//!   no_contact.aedat4, calibration.json, truth/<trial>.csv (on the session's clock)
//!   session.json        what the simulator did, with the true clock offset
//! ```

/// The manifest, one row per trial.
pub const MANIFEST_FILE: &str = "trials.csv";
/// The IMU-to-sensor rotation.
pub const CALIBRATION_FILE: &str = "calibration.json";
/// The recording without contact that the no-contact mask is built from.
pub const NO_CONTACT_FILE: &str = "no_contact.aedat4";
/// Where the dataset's labels come from (the IMU, or the robot's commanded motion), when not
/// the IMU.
pub const LABEL_SOURCE_FILE: &str = "label_source.json";
/// The folder of label files, `<trial>.csv` each.
pub const LABELS_DIR: &str = "labels";
/// The folder of the simulator's true angles, `<trial>.csv` each.
pub const TRUTH_DIR: &str = "truth";
/// How the simulator made the dataset: protocol, scale, seed and every parameter (`params`).
pub const SIMULATOR_FILE: &str = "simulator.json";
/// The train/validation/test split.
pub const SPLITS_FILE: &str = "splits.json";
/// The feature cache folder.
pub const CACHE_DIR: &str = "cache";
/// A session's recording.
pub const SESSION_FILE: &str = "session.aedat4";
/// A session's robot log.
pub const ROBOT_LOG_FILE: &str = "robot_log.csv";
/// What the simulator did to make a session (its parameters and the true clock offset).
pub const SESSION_RECORD_FILE: &str = "session.json";

/// The recording of the trial named `trial`, as the simulator and `evtac import` name it.
pub fn trial_file(trial: &str) -> String {
    format!("{trial}.aedat4")
}
