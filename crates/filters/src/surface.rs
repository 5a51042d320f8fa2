//! The last timestamp at each pixel, as dv-processing's `dv::TimeSurface`: row-major, and 0
//! (not "never") before a pixel's first event, because the filters that match dv-processing
//! compare against that 0 just as it does.

use evtac_events::Resolution;

/// Per-pixel timestamps of a `width x height` sensor, all 0 at first.
#[derive(Debug, Clone)]
pub(crate) struct TimeSurface {
    width: usize,
    height: usize,
    t: Vec<i64>,
}

impl TimeSurface {
    /// A surface for `sensor`, every pixel at 0.
    pub(crate) fn new(sensor: Resolution) -> Self {
        Self {
            width: usize::from(sensor.width),
            height: usize::from(sensor.height),
            t: vec![0; sensor.pixels()],
        }
    }

    /// The index of `(x, y)`, or `None` off the sensor.
    #[inline]
    pub(crate) fn index(&self, x: u16, y: u16) -> Option<usize> {
        let (x, y) = (usize::from(x), usize::from(y));
        (x < self.width && y < self.height).then_some(y * self.width + x)
    }

    /// The sensor's width (columns).
    #[inline]
    pub(crate) fn width(&self) -> usize {
        self.width
    }

    /// The sensor's height (rows).
    #[inline]
    pub(crate) fn height(&self) -> usize {
        self.height
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
