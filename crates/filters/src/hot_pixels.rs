//! `hot-pixels=FILE|auto`: removes the events of the pixels a mask marks, the inverse of
//! [`Mask`] (dv-processing has no class for it; it is `dv.EventMaskFilter` with the mask
//! inverted). Its own type only so that its removed count is reported under its own name.

use evtac_events::{Event, Resolution};

use crate::{Mask, Rule};

/// Removes the events of the hot pixels.
#[derive(Debug, Clone)]
pub struct HotPixels(Mask);

impl HotPixels {
    /// Removes the events of the pixels where `marks` (row by row, `sensor.width` a row) is
    /// non-zero; `marks` holds one value a pixel.
    pub fn new(sensor: Resolution, marks: &[u8]) -> Self {
        Self(Mask::removing(sensor, marks))
    }

    /// Removes the events of `pixels` (column, row); pixels off the sensor are ignored.
    pub fn at(sensor: Resolution, pixels: &[(u16, u16)]) -> Self {
        let width = usize::from(sensor.width);
        let mut marks = vec![0u8; width * usize::from(sensor.height)];
        for &(x, y) in pixels {
            if x < sensor.width && y < sensor.height {
                marks[usize::from(y) * width + usize::from(x)] = 1;
            }
        }
        Self::new(sensor, &marks)
    }
}

impl Rule for HotPixels {
    const NAME: &'static str = "hot-pixels";

    #[inline]
    fn accept(&mut self, event: &Event) -> bool {
        self.0.accept(event)
    }
}
