//! Readers and writers for the files event-camera users have: AEDAT 4.0 ([`aedat`]), the older
//! AEDAT 3.1 and 2.0 ([`aedat_legacy`]), Prophesee EVT 2.0 / 2.1 / 3.0 ([`evt`]), CSV ([`csv`])
//! and NPY ([`npy`], with numpy's NPZ archives in [`npy::npz`]); and readers for HDF5 ([`hdf5`]),
//! the NeuroTac lab's pickles ([`neurotac`]) and ROS bags ([`ros`]: ROS 1 `.bag` and ROS 2 MCAP,
//! with `dvs_msgs/EventArray` or `event_camera_msgs/EventPacket` events and `sensor_msgs/Imu`, a
//! topic chosen like an AEDAT4 stream).
//!
//! The types they read into (`Event`, `ImuSample`, `Trigger`, `Resolution`) and the checks they
//! apply are `evtac-events`'; this crate is the formats only.
//!
//! [`open`] recognises a file's format and streams it in chunks that borrow reused buffers;
//! [`read_recording`] reads it whole; [`read_recording_range`] (or
//! [`EventReader::select_range`]) reads only a time range `[from, to)`, through an AEDAT4 file's
//! data table when it has one ([`RangeIndex`] says how the range was found); [`EventWriter`]
//! writes AEDAT4 (events, IMU samples and triggers), CSV or NPY, whole or not at all; [`Summary`]
//! is what a recording holds (counts, time spans, IMU rate), read in one streaming pass. Readers
//! never panic on bad input: a truncated or corrupt file, a bad header, an event outside the
//! declared resolution or a timestamp going backwards is an [`Error`] naming the file, the byte
//! offset or event index, and the broken limit.
//!
//! ```no_run
//! let recording = evtac_formats::read_recording("trial.aedat4")?;
//! println!("{} events on a {:?} sensor", recording.events.len(), recording.resolution);
//! # Ok::<(), evtac_formats::Error>(())
//! ```

pub mod aedat;
pub mod aedat_legacy;
pub mod columns;
pub mod csv;
mod error;
pub mod evt;
mod family;
mod format;
pub mod hdf5;
pub mod neurotac;
pub mod npy;
mod range;
mod reader;
mod registry;
pub mod ros;
mod selection;
mod summary;
mod text_header;
mod writer;

// The ground types, under the paths this crate's modules have always used (`crate::Event`,
// `crate::check::EventCheck`): one owner, `evtac-events`, and no second public path to them.
use evtac_events::{Event, ImuSample, Resolution, Trigger, check};

pub use error::Error;
pub use family::{FormatReader, FormatWriter, Ranged};
pub use format::Format;
pub use range::{RangeIndex, ScanReason};
pub use reader::{
    Chunk, EventReader, Events, Recording, open, open_with, read_recording, read_recording_range,
};
pub use ros::{TopicInfo, topics};
pub use selection::{StreamChoice, StreamSelection};
pub use summary::Summary;
pub use writer::EventWriter;
