//! Contact-angle labels from the event camera's IMU, and the one place where evtac's angle
//! conventions are written down ([`geometry`]).
//!
//! ```
//! use evtac_labels::geometry::contact_angles;
//!
//! let (pitch, roll) = contact_angles(10.0, 90.0);
//! assert!(pitch.abs() < 1e-9 && (roll - 10.0).abs() < 1e-9);
//! ```

pub mod geometry;
