//! The ground every evtac crate stands on: the event, IMU and trigger types; the checks every
//! reader applies to what it decodes ([`check`]); outputs written whole or not at all and never
//! over an input ([`output`]); and the dataset folder's layout ([`layout`]) and trial manifest
//! ([`manifest`]).
//!
//! File formats are not here: they are `evtac-formats`, so that crates which read no event file
//! (representations, training, labels) do not compile the containers, codecs and HDF5 readers
//! the formats need.
//!
//! Time is `i64` microseconds everywhere; coordinates are on the full sensor with `x` to the right
//! and `y` downwards; a [`Roi`] crops them (the paper uses the centered 240x240 region).
//!
//! ```
//! use evtac_events::{Event, Resolution, Roi};
//!
//! let roi = Roi::centered(Resolution::new(640, 480), Resolution::new(240, 240)).unwrap();
//! let e = Event { t: 10, x: 320, y: 240, polarity: true };
//! assert_eq!(roi.map(e).map(|e| (e.x, e.y)), Some((120, 120)));
//! ```

pub mod check;
mod io_error;
pub mod layout;
pub mod manifest;
pub mod output;
mod types;

pub use io_error::{Cause, IoError};
pub use types::{Event, ImuSample, Resolution, Roi, Trigger};
