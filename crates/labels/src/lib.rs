//! Contact-angle labels from the event camera's IMU, and the one place where evtac's angle
//! conventions are written down ([`geometry`]).
//!
//! The paper derives its ground truth from the IMU inside the event camera: the gyroscope's
//! rate about the rolling axis is bias-compensated, scale-calibrated against the commanded
//! motion, zero-phase low-pass filtered and integrated into the tilt `theta(t)`, which with the
//! tilt direction `phi` gives the contact angles (pitch, roll). [`trial`] walks through the
//! steps; each has its own module. [`label_trial`] and [`label_dataset`] work on dataset
//! folders (`trials.csv`, `calibration.json`, recordings) and write `labels/<trial>.csv`. A
//! dataset of recordings without an IMU is labelled from the robot's commanded motion instead
//! ([`commanded`]), when its [`LabelSource`] says so.
//!
//! ```
//! use evtac_events::ImuSample;
//! use evtac_labels::geometry::{self, Calibration};
//! use evtac_labels::{LabelConfig, TrialMotion, label_imu};
//!
//! // Still for 0.5 s, then 2 s of tilting at 10 deg/s towards phi = 90 deg, then still.
//! let calibration = Calibration::default();
//! let motion = TrialMotion {
//!     direction_deg: 90.0,
//!     speed_deg_s: 10.0,
//!     total_deg: 20.0,
//!     motion_start_us: 500_000,
//!     motion_end_us: 2_500_000,
//!     stop: None,
//! };
//! let imu: Vec<ImuSample> = (0..3_200)
//!     .map(|i| {
//!         let t = i * 1_000;
//!         let moving = (500_000..=2_500_000).contains(&t);
//!         let rate = if moving { 10.0 } else { 0.0 };
//!         let omega = calibration.sensor_to_imu(geometry::sensor_angular_velocity(rate, 90.0));
//!         ImuSample { t, gyroscope: omega.map(|w| w as f32), ..ImuSample::default() }
//!     })
//!     .collect();
//! let labels = label_imu(&imu, &motion, &calibration, &LabelConfig::default())?;
//! let (pitch, roll) = labels.at(1_500_000);
//! assert!(pitch.abs() < 1e-9 && (roll - 10.0).abs() < 1e-3);
//! # Ok::<(), evtac_labels::TrialError>(())
//! ```

pub mod bias;
pub mod commanded;
pub mod dataset;
pub mod error;
pub mod filter;
pub mod geometry;
pub mod integration;
pub mod rate;
pub mod scale;
pub mod series;
pub mod source;
pub mod trial;
pub mod validation;

pub use dataset::{
    CalibrationSource, DatasetLabels, TrialReport, dataset_calibration, label_dataset, label_trial,
    read_calibration, read_calibration_file,
};
pub use error::{Error, TrialError};
pub use scale::ScaleMethod;
pub use series::LabelSeries;
pub use source::LabelSource;
pub use trial::{LabelConfig, Stop, TrialLabels, TrialMotion, label_imu};
pub use validation::{StopCheck, Summary, TruthError};
