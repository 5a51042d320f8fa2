//! `mask=FILE`: dv-processing's `dv::EventMaskFilter` (`include/dv-processing/core/filters.hpp`),
//! which keeps the events whose pixel is non-zero in a uint8 mask the size of the sensor
//! (`mask.at<uint8_t>(y, x) > 0`), and removes the rest.

use evtac_events::{Event, Resolution};

use crate::Rule;

/// Keeps the events on the pixels a mask marks.
#[derive(Debug, Clone)]
pub struct Mask {
    width: usize,
    /// Row by row: whether each pixel's events are kept.
    keep: Vec<bool>,
}

impl Mask {
    /// Keeps the events of the pixels where `marks` (row by row, `sensor.width` a row) is
    /// non-zero. `marks` must hold one value a pixel (the caller checks the size, see
    /// [`crate::mask_file`]).
    pub fn new(sensor: Resolution, marks: &[u8]) -> Self {
        debug_assert_eq!(
            marks.len(),
            usize::from(sensor.width) * usize::from(sensor.height)
        );
        Self {
            width: usize::from(sensor.width),
            keep: marks.iter().map(|&m| m != 0).collect(),
        }
    }

    /// The opposite: removes the events of the marked pixels (a mask of hot pixels, say).
    pub fn removing(sensor: Resolution, marks: &[u8]) -> Self {
        let mut mask = Self::new(sensor, marks);
        mask.keep.iter_mut().for_each(|k| *k = !*k);
        mask
    }
}

impl Rule for Mask {
    const NAME: &'static str = "mask";

    #[inline]
    fn accept(&mut self, event: &Event) -> bool {
        // Events off the mask (which the readers' checks against the sensor rule out) are
        // removed rather than read out of bounds.
        let k = usize::from(event.y) * self.width + usize::from(event.x);
        usize::from(event.x) < self.width && self.keep.get(k).copied().unwrap_or(false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Filter;

    #[test]
    fn keeps_the_non_zero_pixels_row_by_row() {
        let sensor = Resolution::new(3, 2);
        let mut f = Mask::new(sensor, &[0, 1, 0, 0, 0, 255]).counted();
        let e = |x, y| Event {
            t: 0,
            x,
            y,
            polarity: true,
        };
        assert!(f.keep(&e(1, 0)));
        assert!(f.keep(&e(2, 1)));
        assert!(!f.keep(&e(0, 0)));
        assert!(!f.keep(&e(1, 1)));
        assert!(!f.keep(&e(3, 0)));
        assert_eq!(f.removed(), 3);
        let mut hot = Mask::removing(sensor, &[0, 1, 0, 0, 0, 255]).counted();
        assert!(!hot.keep(&e(1, 0)));
        assert!(hot.keep(&e(0, 0)));
    }
}
