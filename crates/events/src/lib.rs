//! Event and IMU types for evtac, and readers and writers for the files event-camera users have.
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

pub mod aedat;
pub mod check;
pub mod csv;
pub mod evt;
pub mod manifest;
pub mod npy;
mod types;

pub use types::{Event, ImuSample, Resolution, Roi, Trigger};
