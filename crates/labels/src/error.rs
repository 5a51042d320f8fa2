//! The errors of labelling one trial ([`TrialError`]) and a whole dataset ([`Error`]).
//!
//! Step errors ([`StreamError`], [`BiasError`], ...) say what is wrong; [`Error::Trial`] adds
//! which trial it is, so a message reads e.g. "trial `t0007`: the recording has no IMU stream".

use std::path::PathBuf;

use evtac_events::manifest::ManifestError;

use crate::bias::BiasError;
use crate::filter::FilterError;
use crate::integration::IntegrationError;
use crate::rate::StreamError;
use crate::scale::ScaleError;
use crate::series::SeriesError;
use crate::validation::ValidationError;

/// The command-line flag (without its dashes) that labels with the identity rotation instead of
/// a dataset's `calibration.json`; errors about a missing calibration name it.
pub const IDENTITY_CALIBRATION_FLAG: &str = "identity-calibration";

/// Why one trial could not be labelled.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TrialError {
    /// The trial's motion description is inconsistent.
    #[error("invalid motion in the manifest: {reason}")]
    Motion {
        /// What is inconsistent, naming the manifest columns.
        reason: String,
    },
    /// The recording could not be read.
    #[error("cannot read the recording {path}: {message}")]
    Read {
        /// The recording.
        path: PathBuf,
        /// The reader's message.
        message: String,
    },
    /// The motion does not lie inside the IMU stream.
    #[error(
        "the motion from {motion_start_us} to {motion_end_us} us does not lie inside the IMU \
         stream, which runs from {first_us} to {last_us} us"
    )]
    MotionOutsideRecording {
        /// Manifest motion onset.
        motion_start_us: i64,
        /// Manifest motion end.
        motion_end_us: i64,
        /// First IMU sample.
        first_us: i64,
        /// Last IMU sample.
        last_us: i64,
    },
    /// The IMU stream is missing or broken.
    #[error(transparent)]
    Stream(#[from] StreamError),
    /// No bias estimate (no stationary segment).
    #[error(transparent)]
    Bias(#[from] BiasError),
    /// The scale could not be calibrated.
    #[error(transparent)]
    Scale(#[from] ScaleError),
    /// The low-pass could not be designed or applied.
    #[error(transparent)]
    Filter(#[from] FilterError),
    /// The rate could not be integrated.
    #[error(transparent)]
    Integration(#[from] IntegrationError),
    /// The stop check could not be made.
    #[error(transparent)]
    Validation(#[from] ValidationError),
    /// The labels could not be written, or the ground truth read.
    #[error(transparent)]
    Series(#[from] SeriesError),
}

/// Why a dataset could not be labelled.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// One trial failed.
    #[error("trial `{trial}`: {kind}")]
    Trial {
        /// The trial's name.
        trial: String,
        /// What went wrong.
        kind: TrialError,
    },
    /// The manifest `trials.csv` could not be read.
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    /// The dataset has no `calibration.json`.
    #[error(
        "{path} is missing: add the IMU-to-sensor rotation there, or pass --{flag} to label \
         with the identity rotation",
        flag = IDENTITY_CALIBRATION_FLAG
    )]
    MissingCalibration {
        /// The file that is missing.
        path: PathBuf,
    },
    /// `label_source.json` could not be read or parsed.
    #[error("cannot read the label source {path}: {message}")]
    LabelSource {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// `calibration.json` could not be read or parsed.
    #[error("cannot read the calibration {path}: {message}")]
    Calibration {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl Error {
    /// Wraps a trial's error with its name.
    pub fn trial(trial: impl Into<String>, kind: impl Into<TrialError>) -> Self {
        Self::Trial {
            trial: trial.into(),
            kind: kind.into(),
        }
    }
}
