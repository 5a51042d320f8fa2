//! `refractory=DURATION`: a refractory period per pixel, as dv-processing's C++
//! `dv::RefractoryPeriodFilter` (`include/dv-processing/core/filters.hpp`; its Python bindings
//! do not expose it, so the tests check it against a reference of their own).
//!
//! An event is kept when its pixel's previous event came at least DURATION before it:
//! `t - last >= DURATION`. Every event restarts its pixel's period, kept or not (a pixel that
//! fires faster than DURATION keeps nothing after its first event, as the C++ class does).
//! Pixels start at timestamp 0, as there, so a pixel's first event is kept unless it comes
//! before `t = DURATION`.

use evtac_events::{Event, Resolution};

use crate::surface::TimeSurface;
use crate::{Micros, Rule};

/// Removes events that follow their pixel's previous event within the period.
#[derive(Debug, Clone)]
pub struct Refractory {
    surface: TimeSurface,
    period: i64,
}

impl Refractory {
    /// The filter for `sensor`, with a refractory `period`.
    pub fn new(sensor: Resolution, period: Micros) -> Self {
        Self {
            surface: TimeSurface::new(sensor),
            period: period.get(),
        }
    }
}

impl Rule for Refractory {
    const NAME: &'static str = "refractory";

    #[inline]
    fn accept(&mut self, event: &Event) -> bool {
        // Off the sensor there is no pixel to hold a period: removed.
        self.surface.index(event.x, event.y).is_some_and(|i| {
            let keep = event.t.wrapping_sub(self.surface.at(i)) >= self.period;
            self.surface.set(i, event.t);
            keep
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Filter;

    #[test]
    fn every_event_restarts_its_pixel_s_period() {
        let mut f = Refractory::new(Resolution::new(4, 4), Micros::new(100).unwrap()).counted();
        let e = |t, x| Event {
            t,
            x,
            y: 1,
            polarity: true,
        };
        assert!(f.keep(&e(1_000, 0)));
        assert!(!f.keep(&e(1_099, 0)));
        // 99 after the removed event, 198 after the kept one: the removed one counts.
        assert!(!f.keep(&e(1_198, 0)));
        assert!(f.keep(&e(1_298, 0)));
        assert!(f.keep(&e(1_299, 1)));
        assert!(!f.keep(&e(1_299, 4)));
        assert_eq!(f.removed(), 3);
    }

    #[test]
    fn pixels_start_at_timestamp_zero() {
        let mut f = Refractory::new(Resolution::new(4, 4), Micros::new(100).unwrap()).counted();
        let e = |t, x| Event {
            t,
            x,
            y: 0,
            polarity: false,
        };
        assert!(!f.keep(&e(99, 0)));
        assert!(f.keep(&e(100, 1)));
    }
}
