//! Recordings into datasets, and what they say about the sensor.
//!
//! - [`import`]: a recording session cut into a dataset by the robot's log ([`robot_log`]), put
//!   on the recording's clock by [`sync`] (a clock offset, the triggers, or the IMU:
//!   [`imu_sync`]), or by the motions found in its gyroscope ([`motions`]); several sessions,
//!   or a folder of per-trial files ([`trial_folder`]), into one dataset.
//! - [`check`]: a dataset validated before training, every problem listed (`evtac check`), as
//!   it would be opened with [`inputs`]: whether its calibration and mask come from its files
//!   or were opted out of.
//! - [`filtering`]: a recording's events through event filters, `hot-pixels=auto` learned from
//!   the recording itself.
//! - [`sensor_stats`]: what a recording says about its sensor (noise at rest, hot pixels, the
//!   IMU's noise and bias), as simulator parameters (`evtac stats`).
//!
//! Everything here reads recordings and writes dataset folders; training and the experiments
//! (`evtac-experiments`) read the datasets it makes.
//!
//! ```no_run
//! use evtac_import::import::{ImportConfig, NoContact, import_session};
//! use evtac_import::robot_log::RobotLog;
//! use std::path::Path;
//!
//! // A session whose log is on the recording's clock already (offset 0).
//! let log = RobotLog::read(Path::new("robot_log.csv"), 0)?;
//! let config = ImportConfig {
//!     pre_us: 200_000,
//!     post_us: 200_000,
//!     no_contact: Some(NoContact::File("no_contact.aedat4".into())),
//!     calibration: Some("calibration.json".into()),
//!     labels: evtac_labels::LabelSource::Imu,
//!     filters: Vec::new(),
//! };
//! let out = Path::new("data/exp1");
//! let summary = import_session(Path::new("session.aedat4"), &log, out, &config, &|| {})?;
//! println!("{summary:?}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod check;
pub mod filtering;
pub mod import;
pub mod imu_sync;
pub mod inputs;
pub mod motions;
pub mod robot_log;
pub mod sensor_stats;
pub mod sync;
pub mod trial_folder;
