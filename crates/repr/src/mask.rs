//! [`Mask`]: the no-contact mask of the static representation.
//!
//! The paper records the sensor without contact, reads the static frame, and zeroes the pixels
//! that are non-zero in it before thresholding every static frame: pixels that fire without
//! contact (noise, flicker, pin edges) would otherwise stay set for ever under lazy decay.
//!
//! evtac's rule, exactly: run the no-contact recording through a [`StaticAccumulator`] with the
//! **same static config**, apply dv's `generateFrame` (synchronous decay if configured, then
//! the 8-bit mapping), and mask every pixel whose 8-bit value differs from the 8-bit value of
//! the neutral potential. With the default limits (min = neutral = 0) that is exactly "non-zero in
//! the frame"; comparing with the neutral level keeps the rule meaningful when `min < neutral`
//! (where an untouched pixel is not 0).

use crate::ReprError;
use crate::accumulator::StaticAccumulator;
use crate::config::StaticConfig;
use evtac_events::{Event, Resolution, Roi};

/// A per-pixel mask: masked pixels are forced to 0 in static binary frames (before the OR of
/// the combined representation; dynamic frames are not masked, as in the paper).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mask {
    resolution: Resolution,
    pixels: Vec<u8>,
}

impl Mask {
    /// A mask with no pixel masked.
    pub fn empty(resolution: Resolution) -> Self {
        Self {
            resolution,
            pixels: vec![0; resolution.pixels()],
        }
    }

    /// A mask from one value per pixel, row-major: non-zero means masked (e.g. read from a
    /// uint8 NPY of shape `height x width`).
    pub fn from_pixels(resolution: Resolution, pixels: &[u8]) -> Result<Self, ReprError> {
        if pixels.len() != resolution.pixels() {
            return Err(ReprError::BufferLength {
                what: "mask pixels",
                len: pixels.len(),
                expected: resolution.pixels(),
                width: resolution.width,
                height: resolution.height,
            });
        }
        Ok(Self {
            resolution,
            pixels: pixels.iter().map(|&p| u8::from(p != 0)).collect(),
        })
    }

    /// A mask given as a `rows x cols` grid (row-major, non-zero = masked; e.g. a 2-D uint8 or
    /// bool NPY) for the crop `frame`: an error naming both sizes when the grid is not the
    /// crop's (a transposed mask has the right length but not the right shape).
    pub fn from_grid(
        frame: Resolution,
        (rows, cols): (usize, usize),
        pixels: &[u8],
    ) -> Result<Self, ReprError> {
        if (rows, cols) != (usize::from(frame.height), usize::from(frame.width)) {
            let side = |n: usize| u16::try_from(n).unwrap_or(u16::MAX);
            return Err(ReprError::MaskSize {
                mask_width: side(cols),
                mask_height: side(rows),
                width: frame.width,
                height: frame.height,
            });
        }
        Self::from_pixels(frame, pixels)
    }

    /// The mask of a no-contact recording on the crop `roi` of its sensor: its events (sensor
    /// coordinates, time order) cropped to `roi` ([`Roi::crop_into`]), then
    /// [`Mask::from_no_contact`]: how `evtac represent` and the Python package build a mask from
    /// a recording. The experiments' datasets, which build one mask per config, crop once with
    /// the same `Roi::crop_into` and call [`Mask::from_no_contact`] for each.
    pub fn from_recording(
        roi: &Roi,
        config: &StaticConfig,
        events: &[Event],
    ) -> Result<Self, ReprError> {
        let mut cropped = Vec::with_capacity(events.len());
        roi.crop_into(events, &mut cropped);
        Self::from_no_contact(roi.size, config, &cropped)
    }

    /// The mask of a no-contact recording (events already cropped to `resolution`, in time
    /// order) under `config` (see the module docs for the exact rule).
    pub fn from_no_contact(
        resolution: Resolution,
        config: &StaticConfig,
        events: &[Event],
    ) -> Result<Self, ReprError> {
        let mut acc = StaticAccumulator::new(resolution, config)?;
        acc.accumulate(events)?;
        Ok(Self::from_accumulator(&mut acc))
    }

    /// The mask of an accumulator's current state (after its synchronous decay, if on).
    pub fn from_accumulator(acc: &mut StaticAccumulator) -> Self {
        acc.synchronize();
        let neutral = acc.frame_value(acc.params().neutral_potential);
        let pixels = acc
            .potentials()
            .iter()
            .map(|&v| u8::from(acc.frame_value(v) != neutral))
            .collect();
        Self {
            resolution: acc.resolution(),
            pixels,
        }
    }

    /// The frame size.
    pub fn resolution(&self) -> Resolution {
        self.resolution
    }

    /// Whether pixel `pixel` (`y * width + x`) is masked.
    ///
    /// # Panics
    /// When `pixel` is outside the frame.
    #[inline]
    pub fn is_masked(&self, pixel: usize) -> bool {
        self.pixels[pixel] != 0
    }

    /// One value per pixel, row-major: 1 masked, 0 kept.
    pub fn pixels(&self) -> &[u8] {
        &self.pixels
    }

    /// Number of masked pixels.
    pub fn count(&self) -> usize {
        self.pixels.iter().filter(|&&p| p != 0).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_contact_mask_marks_pixels_with_potential() {
        let ev = |t, x, polarity| Event {
            t,
            x,
            y: 0,
            polarity,
        };
        let res = Resolution::new(4, 1);
        let events = [ev(10, 0, true), ev(20, 1, false), ev(30, 2, true)];
        let mask = Mask::from_no_contact(res, &StaticConfig::default(), &events).unwrap();
        // The OFF event clamps at min 0: nothing to mask there.
        assert_eq!(mask.pixels(), &[1, 0, 1, 0]);
        assert_eq!(mask.count(), 2);
        // With min < neutral, untouched pixels are not masked but OFF ones are.
        let cfg = StaticConfig {
            min_potential: -1.0,
            ..StaticConfig::default()
        };
        let mask = Mask::from_no_contact(res, &cfg, &events).unwrap();
        assert_eq!(mask.pixels(), &[1, 1, 1, 0]);
        assert!(Mask::from_pixels(res, &[0; 3]).is_err());
    }
}
