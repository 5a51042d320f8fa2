//! [`Pool8`]: 8x8 mean pooling of a binary frame, kept up to date from pixel flips.
//!
//! The paper pools the binary 240x240 frame into 30x30 = 900 features (row-major). Recomputing
//! that per sample reads 57 600 pixels; here each cell keeps its count of set pixels, a flip
//! changes one count and one feature (`count / 64`, exact in float32), so a sample costs only the
//! flips since the previous one. [`pool8`] is the straightforward version the tests compare with.

use crate::ReprError;
use evtac_events::Resolution;

/// Side of a pooling cell in pixels.
pub const CELL: usize = 8;

/// A binary frame (0/1 per pixel) with its 8x8 mean-pooled features, maintained incrementally.
///
/// ```
/// use evtac_events::Resolution;
/// use evtac_repr::Pool8;
///
/// let mut pool = Pool8::new(Resolution::new(16, 8)).unwrap();
/// pool.set(9, true); // x = 9, y = 0: the second cell
/// assert_eq!(pool.features(), &[0.0, 1.0 / 64.0]);
/// assert_eq!(pool.frame()[9], 1);
/// ```
#[derive(Debug, Clone)]
pub struct Pool8 {
    resolution: Resolution,
    /// Cell index of every pixel: a lookup is cheaper than two divisions per flip.
    cell_of: Vec<u32>,
    bits: Vec<u8>,
    counts: Vec<u8>,
    features: Vec<f32>,
}

impl Pool8 {
    /// An all-zero frame of `resolution`, whose sides must be non-zero multiples of 8.
    pub fn new(resolution: Resolution) -> Result<Self, ReprError> {
        let (w, h) = poolable_sides(resolution)?;
        let (cell_of, cells) = cell_map(resolution)?;
        Ok(Self {
            resolution,
            cell_of,
            bits: vec![0; w * h],
            counts: vec![0; cells],
            features: vec![0.0; cells],
        })
    }

    /// The frame size.
    pub fn resolution(&self) -> Resolution {
        self.resolution
    }

    /// Sets pixel `pixel` (`y * width + x`) to `on`, updating its cell when the pixel flips.
    /// Returns whether it flipped.
    ///
    /// # Panics
    /// When `pixel` is outside the frame.
    #[inline]
    pub fn set(&mut self, pixel: usize, on: bool) -> bool {
        if (self.bits[pixel] != 0) == on {
            return false;
        }
        self.flip(pixel, on);
        true
    }

    /// Sets pixel `pixel`, which is known to be `!on`, to `on` (what [`Self::set`] does after
    /// its check, for callers that already know the pixel flips).
    ///
    /// # Panics
    /// When `pixel` is outside the frame; in debug builds also when the pixel is already `on`.
    #[inline]
    pub fn flip(&mut self, pixel: usize, on: bool) {
        let bit = &mut self.bits[pixel];
        debug_assert_ne!(*bit != 0, on, "Pool8::flip on a pixel that does not flip");
        *bit = u8::from(on);
        let cell = self.cell_of[pixel] as usize;
        let count = &mut self.counts[cell];
        if on {
            *count += 1;
        } else {
            *count -= 1;
        }
        self.features[cell] = f32::from(*count) / 64.0;
    }

    /// Whether pixel `pixel` is set.
    #[inline]
    pub fn get(&self, pixel: usize) -> bool {
        self.bits[pixel] != 0
    }

    /// The binary frame, row-major, 0 or 1 per pixel.
    pub fn frame(&self) -> &[u8] {
        &self.bits
    }

    /// The pooled features, row-major over cells: `(width / 8) * (height / 8)` values in [0, 1].
    pub fn features(&self) -> &[f32] {
        &self.features
    }

    /// Clears every pixel.
    pub fn clear(&mut self) {
        self.bits.fill(0);
        self.counts.fill(0);
        self.features.fill(0.0);
    }
}

/// The cell of every pixel of a `resolution` frame (row-major over cells, as the features are)
/// and the number of cells: a lookup is cheaper than two divisions per event. [`Pool8`] and the
/// real-valued kinds ([`crate::dense`]) pool through it.
pub(crate) fn cell_map(resolution: Resolution) -> Result<(Vec<u32>, usize), ReprError> {
    let (w, h) = poolable_sides(resolution)?;
    let cells_x = w / CELL;
    let cell_of = (0..w * h)
        .map(|p| ((p / w / CELL) * cells_x + (p % w) / CELL) as u32)
        .collect();
    Ok((cell_of, cells_x * (h / CELL)))
}

/// The frame's sides in pixels, if both are non-zero multiples of [`CELL`] (the one check
/// [`Pool8`] and [`pool8`] share).
fn poolable_sides(resolution: Resolution) -> Result<(usize, usize), ReprError> {
    let (w, h) = (
        usize::from(resolution.width),
        usize::from(resolution.height),
    );
    if w == 0 || h == 0 || w % CELL != 0 || h % CELL != 0 {
        return Err(ReprError::FrameNotPoolable {
            width: resolution.width,
            height: resolution.height,
        });
    }
    Ok((w, h))
}

/// Straightforward 8x8 mean pooling of a binary (0/non-zero) frame, row-major over cells: the
/// reference [`Pool8`] is tested against, and a one-shot helper.
pub fn pool8(resolution: Resolution, frame: &[u8]) -> Result<Vec<f32>, ReprError> {
    let (w, h) = poolable_sides(resolution)?;
    if frame.len() != w * h {
        return Err(ReprError::BufferLength {
            what: "frame pixels",
            len: frame.len(),
            expected: w * h,
            width: resolution.width,
            height: resolution.height,
        });
    }
    let mut out = Vec::with_capacity((w / CELL) * (h / CELL));
    for cy in 0..h / CELL {
        for cx in 0..w / CELL {
            let mut n = 0u32;
            for y in cy * CELL..(cy + 1) * CELL {
                for x in cx * CELL..(cx + 1) * CELL {
                    n += u32::from(frame[y * w + x] != 0);
                }
            }
            out.push(n as f32 / 64.0);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn frames_not_divisible_by_8_are_rejected() {
        assert!(matches!(
            Pool8::new(Resolution::new(20, 16)),
            Err(ReprError::FrameNotPoolable { width: 20, .. })
        ));
        assert!(pool8(Resolution::new(8, 8), &[0; 3]).is_err());
    }

    proptest! {
        #[test]
        fn incremental_pooling_equals_reference(
            flips in proptest::collection::vec((0usize..24 * 16, any::<bool>()), 0..400)
        ) {
            let res = Resolution::new(24, 16);
            let mut pool = Pool8::new(res).unwrap();
            for (p, on) in flips {
                pool.set(p, on);
            }
            prop_assert_eq!(pool.features(), &pool8(res, pool.frame()).unwrap()[..]);
        }
    }
}
