//! The crate-level error of the whole-file API ([`open`](crate::open),
//! [`read_recording`](crate::read_recording), [`EventWriter`](crate::EventWriter)): each
//! format's error, with the path of the file it concerns.
//!
//! Messages embed the inner error's message (so `{}` alone tells the whole story); the inner
//! error is a public field rather than a `source()`, so that `{:#}` chains do not repeat it.

use std::path::PathBuf;

use crate::aedat::{AedatError, SelectionError};
use crate::aedat_legacy::LegacyError;
use crate::check::CheckError;
use crate::csv::CsvError;
use crate::evt::EvtError;
use crate::npy::NpyError;
use crate::{Format, Resolution};

/// What can go wrong opening, reading or writing an event file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The file could not be opened, created or inspected.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        error: std::io::Error,
    },
    /// The streams asked for are not in the file, or the file holds several and none was
    /// chosen.
    #[error("{}: {error}", path.display())]
    Streams {
        /// The file.
        path: PathBuf,
        /// Which kind, and the file's streams.
        error: SelectionError,
    },
    /// Neither the first bytes nor the extension identify a format evtac reads.
    #[error("{}: unknown event file format ({reason})", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// What was looked at.
        reason: String,
    },
    /// evtac cannot write this format.
    #[error("{}: cannot write {format} files (write .aedat4, .csv or .npy)", path.display())]
    NotWritable {
        /// The file.
        path: PathBuf,
        /// The format its extension names.
        format: Format,
    },
    /// Writing AEDAT4 needs the sensor size, and none was given.
    #[error("{}: writing AEDAT4 needs the sensor resolution, and the input has none", path.display())]
    MissingResolution {
        /// The file.
        path: PathBuf,
    },
    /// A declared resolution contradicts the one the file states.
    #[error("{}: the file states a {found} sensor, not {declared}", path.display())]
    ResolutionMismatch {
        /// The file.
        path: PathBuf,
        /// The resolution the caller declared.
        declared: Resolution,
        /// The resolution in the file.
        found: Resolution,
    },
    /// A range read was asked for an empty time range.
    #[error("{}: the time range [{from}, {to}) us is empty: from must be smaller than to", path.display())]
    EmptyRange {
        /// The file.
        path: PathBuf,
        /// Start of the range (included), microseconds.
        from: i64,
        /// End of the range (excluded), microseconds.
        to: i64,
    },
    /// An AEDAT4 file is broken.
    #[error("{}: {error}", path.display())]
    Aedat {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: AedatError,
    },
    /// An AEDAT 2.0 or 3.1 file is broken.
    #[error("{}: {error}", path.display())]
    AedatLegacy {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: LegacyError,
    },
    /// An EVT file is broken.
    #[error("{}: {error}", path.display())]
    Evt {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: EvtError,
    },
    /// A CSV file is broken.
    #[error("{}: {error}", path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: CsvError,
    },
    /// An NPY file is broken.
    #[error("{}: {error}", path.display())]
    Npy {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: NpyError,
    },
    /// An HDF5 event file is broken or holds no event datasets.
    #[error("{}: {error}", path.display())]
    Hdf5 {
        /// The file.
        path: PathBuf,
        /// What is wrong (boxed: the error enum stays small).
        error: Box<crate::hdf5::Hdf5Error>,
    },
    /// An NPZ archive is broken or holds no events.
    #[error("{}: {error}", path.display())]
    Npz {
        /// The file.
        path: PathBuf,
        /// What is wrong (boxed: the error enum stays small).
        error: Box<crate::npy::npz::NpzError>,
    },
    /// A NeuroTac pickle (or its pair) is not the lab's structure, or is broken.
    #[error("{error}")]
    Neurotac {
        /// The file opened.
        path: PathBuf,
        /// What is wrong (naming the file of the pair it is in).
        error: Box<crate::neurotac::NeurotacError>,
    },
    /// A ROS bag (ROS 1 `.bag` or ROS 2 MCAP) is broken, or a message does not decode.
    #[error("{}: {error}", path.display())]
    Ros {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the topic and message (boxed: the error enum stays small).
        error: Box<crate::ros::RosError>,
    },
    /// An event read from the file is invalid (outside the sensor, or earlier than its
    /// predecessor).
    #[error("{}: {error}", path.display())]
    Event {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: CheckError,
    },
}
