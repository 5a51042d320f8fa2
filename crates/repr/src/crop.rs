//! The region the paper's representations are built on: the centered 240x240 crop of the
//! sensor (the pin array of a NeuroTac dome imaged by a 640x480 DVXplorer).
//!
//! The crop's size is what makes 900 features: 8x8 pooling of 240x240 pixels gives 30x30. Every
//! part of evtac that crops a sensor (dataset features, the online estimator, `evtac represent`,
//! the model bundle's check) takes it from here.

use evtac_events::{Resolution, Roi};

/// Width and height of the crop the representations and the MLP's 900 features are built on.
pub const CROP: Resolution = Resolution::new(240, 240);

/// The sensor is smaller than the crop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the sensor ({sensor}) is smaller than the {CROP} region of interest")]
pub struct SensorTooSmall {
    /// The sensor's resolution.
    pub sensor: Resolution,
}

/// The [`CROP`] centered on `sensor` (offsets rounded down).
///
/// ```
/// use evtac_events::Resolution;
/// let roi = evtac_repr::centered_crop(Resolution::new(640, 480)).unwrap();
/// assert_eq!((roi.x0, roi.y0), (200, 120));
/// assert!(evtac_repr::centered_crop(Resolution::new(200, 200)).is_err());
/// ```
pub fn centered_crop(sensor: Resolution) -> Result<Roi, SensorTooSmall> {
    Roi::centered(sensor, CROP).ok_or(SensorTooSmall { sensor })
}
