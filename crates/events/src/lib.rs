//! Event and IMU types for evtac, and readers and writers for the files event-camera users have:
//! AEDAT 4.0 ([`aedat`]), the older AEDAT 3.1 and 2.0 ([`aedat_legacy`]), Prophesee EVT 2.0 / 2.1 /
//! 3.0 ([`evt`]), CSV ([`csv`]) and NPY ([`npy`]); and readers for the NeuroTac lab's pickles
//! ([`neurotac`]) and for ROS bags ([`ros`]: ROS 1 `.bag` and ROS 2 MCAP, with
//! `dvs_msgs/EventArray` or `event_camera_msgs/EventPacket` events and `sensor_msgs/Imu`, a
//! topic chosen like an AEDAT4 stream).
//!
//! Time is `i64` microseconds everywhere; coordinates are on the full sensor with `x` to the right
//! and `y` downwards; a [`Roi`] crops them (the paper uses the centered 240x240 region).
//!
//! [`open`] recognises a file's format and streams it in chunks that borrow reused buffers;
//! [`read_recording`] reads it whole; [`read_recording_range`] (or
//! [`EventReader::select_range`]) reads only a time range `[from, to)`, through an AEDAT4 file's
//! data table when it has one ([`RangeIndex`] says how the range was found); [`EventWriter`]
//! writes AEDAT4 (events, IMU samples and triggers), CSV or NPY, whole or not at all
//! ([`output`]); [`Summary`] is what a
//! recording holds (counts, time spans, IMU rate), read in one streaming pass. Readers never
//! panic on bad input: a truncated or corrupt file, a bad header, an event outside the declared
//! resolution or a timestamp going backwards is an [`Error`] naming the file, the byte offset or
//! event index, and the broken limit.
//!
//! ```
//! use evtac_events::{Event, Resolution, Roi};
//!
//! let roi = Roi::centered(Resolution::new(640, 480), Resolution::new(240, 240)).unwrap();
//! let e = Event { t: 10, x: 320, y: 240, polarity: true };
//! assert_eq!(roi.map(e).map(|e| (e.x, e.y)), Some((120, 120)));
//! ```
//!
//! ```no_run
//! let recording = evtac_events::read_recording("trial.aedat4")?;
//! println!("{} events on a {:?} sensor", recording.events.len(), recording.resolution);
//! # Ok::<(), evtac_events::Error>(())
//! ```

pub mod aedat;
pub mod aedat_legacy;
pub mod check;
pub mod columns;
pub mod csv;
mod error;
pub mod evt;
pub mod hdf5;
mod io_error;
pub mod layout;
pub mod manifest;
pub mod neurotac;
pub mod npy;
pub mod npz;
pub mod output;
pub mod pickle;
mod range;
mod recording;
pub mod ros;
mod summary;
mod text_header;
mod types;

pub use error::Error;
pub use io_error::{Cause, IoError};
pub use range::{RangeIndex, ScanReason};
pub use recording::{
    Chunk, EventReader, EventWriter, Events, Format, Recording, open, open_with, read_recording,
    read_recording_range,
};
pub use ros::{TopicInfo, topics};
pub use summary::Summary;
pub use types::{Event, ImuSample, Resolution, Roi, Trigger};
