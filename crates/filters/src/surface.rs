//! The last timestamp at each pixel, as dv-processing's `dv::TimeSurface`: row-major, and 0
//! (not "never") before a pixel's first event, because the filters that match dv-processing
//! compare against that 0 just as it does.
//!
//! The surface has a border one pixel wide around the sensor, so that a pixel's 3x3
//! neighbourhood is always three whole rows of three ([`TimeSurface::around`]) and a filter
//! reads it without clipping rows and columns at the sensor's edges (a data-dependent branch or
//! two per event). No timestamp in the border can stand for "never" under dv-processing's
//! wrapping subtraction (for any stored value some timestamp is within the duration of it), so
//! the border is never written and a filter masks the neighbours beyond the sensor out
//! ([`Edges`]) instead of trusting what the border holds.

use evtac_events::Resolution;

/// Per-pixel timestamps of a `width x height` sensor, all 0 at first, in a surface padded by
/// one pixel on every side.
#[derive(Debug, Clone)]
pub(crate) struct TimeSurface {
    width: usize,
    height: usize,
    t: Vec<i64>,
}

/// Which of a pixel's neighbours lie on the sensor: the row above, the row below, the column
/// to the left and the one to the right.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Edges {
    pub(crate) up: bool,
    pub(crate) down: bool,
    pub(crate) left: bool,
    pub(crate) right: bool,
}

impl TimeSurface {
    /// A surface for `sensor`, every pixel at 0.
    pub(crate) fn new(sensor: Resolution) -> Self {
        let (width, height) = (usize::from(sensor.width), usize::from(sensor.height));
        Self {
            width,
            height,
            t: vec![0; (width + 2) * (height + 2)],
        }
    }

    /// The index of `(x, y)` in the padded surface, or `None` off the sensor.
    #[inline]
    pub(crate) fn index(&self, x: u16, y: u16) -> Option<usize> {
        let (x, y) = (usize::from(x), usize::from(y));
        (x < self.width && y < self.height).then_some((y + 1) * (self.width + 2) + x + 1)
    }

    /// Which neighbours of `(x, y)` (on the sensor) are on the sensor too.
    #[inline]
    pub(crate) fn edges(&self, x: u16, y: u16) -> Edges {
        let (x, y) = (usize::from(x), usize::from(y));
        Edges {
            up: y > 0,
            down: y + 1 < self.height,
            left: x > 0,
            right: x + 1 < self.width,
        }
    }

    /// The 3x3 timestamps around `index` (from [`Self::index`]), row above first; entries
    /// beyond the sensor are the border's, meaningless (see [`Edges`]).
    #[inline]
    pub(crate) fn around(&self, index: usize) -> [&[i64; 3]; 3] {
        let stride = self.width + 2;
        let row = |start: usize| -> &[i64; 3] {
            self.t[start..start + 3]
                .try_into()
                .expect("a range of three")
        };
        [
            row(index - stride - 1),
            row(index - 1),
            row(index + stride - 1),
        ]
    }

    /// The timestamp at `index`.
    #[inline]
    pub(crate) fn at(&self, index: usize) -> i64 {
        self.t[index]
    }

    /// Sets the timestamp at `index`.
    #[inline]
    pub(crate) fn set(&mut self, index: usize, t: i64) {
        self.t[index] = t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbourhoods_are_whole_at_every_corner() {
        let mut s = TimeSurface::new(Resolution::new(3, 2));
        let corners = [(0, 0), (2, 0), (0, 1), (2, 1)];
        for (k, &(x, y)) in corners.iter().enumerate() {
            s.set(s.index(x, y).unwrap(), 10 + k as i64);
        }
        // (1, 0)'s row below holds (0, 1), (1, 1), (2, 1); its row above is the border.
        let [above, row, below] = s.around(s.index(1, 0).unwrap());
        assert_eq!((*above, *row, *below), ([0; 3], [10, 0, 11], [12, 0, 13]));
        assert!(s.index(3, 0).is_none() && s.index(0, 2).is_none());
        let e = s.edges(2, 1);
        assert!(e.up && !e.down && e.left && !e.right);
    }
}
