//! [`Error`]: what can stop a reproduction, one variant per stage that can fail, and
//! [`PerturbError`], why the sensitivity study could not scale a simulator parameter. Their own
//! file so that the stages (the noise study simulates and trains), the pipeline that runs them
//! and the studies share them without importing each other.

use std::path::PathBuf;

/// Errors of a reproduction.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A dataset could not be opened.
    #[error(transparent)]
    Dataset(#[from] crate::dataset::Error),
    /// Features, training or evaluation failed.
    #[error(transparent)]
    Training(#[from] crate::training::Error),
    /// The latency study failed.
    #[error(transparent)]
    Latency(#[from] crate::latency::Error),
    /// The end-to-end replay at recorded pace failed.
    #[error(transparent)]
    PacedLatency(#[from] crate::paced_latency::Error),
    /// The feature cache failed.
    #[error(transparent)]
    Cache(#[from] crate::cache::Error),
    /// A dataset could not be simulated.
    #[error("simulating {protocol} into {dir}: {source}")]
    Simulation {
        /// The protocol.
        protocol: evtac_sim::Protocol,
        /// The dataset folder.
        dir: PathBuf,
        /// The cause (boxed: it is large, and rare).
        source: Box<evtac_sim::DatasetError>,
    },
    /// The `done` marker of a simulated dataset could not be written.
    #[error(transparent)]
    Jobs(#[from] crate::jobs::Error),
    /// A simulator parameter of the sensitivity study could not be scaled.
    #[error(transparent)]
    Perturb(#[from] PerturbError),
    /// Something a stage needs from an earlier one is not in its results.
    #[error("missing {what}")]
    Missing {
        /// What is missing.
        what: &'static str,
    },
    /// The log of stage times (`stage-times.csv`) could not be read or appended to.
    #[error(transparent)]
    StageLog(#[from] crate::stage_log::Error),
}

/// Why a parameter could not be scaled.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PerturbError {
    /// No parameter has this name.
    #[error(
        "no simulator parameter {name:?} in the sensitivity study; the parameters are {}",
        crate::parameters::names()
    )]
    Unknown {
        /// The name given.
        name: String,
    },
    /// A field is not one of the numbers of `simulator.json` a parameter scales.
    #[error("simulator parameter {field} is not a number in simulator.json")]
    NotANumber {
        /// The field, `section.field`.
        field: String,
    },
    /// The scaled parameters are not valid simulator parameters (a count out of range).
    #[error("simulator parameters with {field} scaled: {message}")]
    Invalid {
        /// The fields.
        field: String,
        /// What is wrong.
        message: String,
    },
}
