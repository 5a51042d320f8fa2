//! `background-activity=DURATION`: dv-processing's `dv::noise::BackgroundActivityNoiseFilter`
//! (`include/dv-processing/noise/background_activity_noise_filter.hpp`).
//!
//! An event is kept when one of its 8 neighbours (the pixel itself is not one of them; off the
//! sensor there are none) had an event less than DURATION before it: `t - last < DURATION`,
//! strictly. Then the event's own pixel takes its timestamp, kept or not. Every pixel starts at
//! timestamp 0, as dv-processing's time surface does, so an event at `t < DURATION` is kept by
//! any neighbour that never fired; with camera-clock timestamps that never happens.

use evtac_events::{Event, Resolution};

use crate::surface::TimeSurface;
use crate::{Micros, Rule};

/// Keeps events supported by a recent event at a neighbouring pixel.
#[derive(Debug, Clone)]
pub struct BackgroundActivity {
    surface: TimeSurface,
    duration: i64,
}

impl BackgroundActivity {
    /// The filter for `sensor`, with neighbours counted for `duration`.
    pub fn new(sensor: Resolution, duration: Micros) -> Self {
        Self {
            surface: TimeSurface::new(sensor),
            duration: duration.get(),
        }
    }
}

impl Rule for BackgroundActivity {
    const NAME: &'static str = "background-activity";

    // `always`: with `#[inline]` alone LLVM judged it too big and kept a call per event.
    #[inline(always)]
    fn accept(&mut self, event: &Event) -> bool {
        // Off the sensor dv-processing would read and write outside its surface: removed here.
        let Some(i) = self.surface.index(event.x, event.y) else {
            return false;
        };
        // All 8 neighbours tested and the answers combined with `&` and `|`, not `any`: which
        // neighbour answers, and whether any does, is data-dependent, and a short-circuit
        // would branch on it. The padded surface makes the reads unconditional; the edges
        // mask the border out.
        // Wrapping: dv-processing subtracts int64s as they come, whatever they are.
        let recent = |last: i64| event.t.wrapping_sub(last) < self.duration;
        let edges = self.surface.edges(event.x, event.y);
        let [above, row, below] = self.surface.around(i);
        let three = |r: &[i64; 3]| {
            (edges.left & recent(r[0])) | recent(r[1]) | (edges.right & recent(r[2]))
        };
        let keep = (edges.up & three(above))
            | (edges.left & recent(row[0]))
            | (edges.right & recent(row[2]))
            | (edges.down & three(below));
        self.surface.set(i, event.t);
        keep
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Filter;

    const T: i64 = 1_000_000;

    fn run(events: &[(i64, u16, u16)]) -> Vec<bool> {
        let mut f =
            BackgroundActivity::new(Resolution::new(20, 10), Micros::new(2_000).unwrap()).counted();
        events
            .iter()
            .map(|&(t, x, y)| {
                f.keep(&Event {
                    t,
                    x,
                    y,
                    polarity: true,
                })
            })
            .collect()
    }

    #[test]
    fn a_neighbour_strictly_within_the_duration_supports() {
        assert_eq!(run(&[(T, 5, 5), (T + 1_999, 6, 6)]), [false, true]);
        assert_eq!(run(&[(T, 5, 5), (T + 2_000, 6, 6)]), [false, false]);
        assert_eq!(run(&[(T, 5, 5), (T, 4, 5)]), [false, true]);
    }

    #[test]
    fn the_pixel_itself_and_pixels_two_away_do_not() {
        assert_eq!(run(&[(T, 5, 5), (T + 1, 5, 5)]), [false, false]);
        assert_eq!(run(&[(T, 5, 5), (T + 1, 7, 5)]), [false, false]);
        assert_eq!(run(&[(T, 5, 5), (T + 1, 5, 3)]), [false, false]);
    }

    #[test]
    fn borders_have_no_neighbours_beyond_them() {
        assert_eq!(run(&[(T, 0, 0), (T + 1, 1, 1)]), [false, true]);
        assert_eq!(run(&[(T, 19, 9), (T + 1, 18, 8)]), [false, true]);
        // No wrap from the right edge to the left one.
        assert_eq!(run(&[(T, 19, 5), (T + 1, 0, 6)]), [false, false]);
        assert_eq!(run(&[(T, 0, 6), (T + 1, 19, 5)]), [false, false]);
    }

    #[test]
    fn pixels_start_at_timestamp_zero() {
        assert_eq!(run(&[(1_999, 5, 5)]), [true]);
        assert_eq!(run(&[(2_000, 5, 5)]), [false]);
    }

    #[test]
    fn removed_events_still_update_their_pixel_and_off_sensor_ones_count() {
        let mut f =
            BackgroundActivity::new(Resolution::new(20, 10), Micros::new(2_000).unwrap()).counted();
        let e = |t, x, y| Event {
            t,
            x,
            y,
            polarity: false,
        };
        assert!(!f.keep(&e(T, 3, 3)));
        assert!(f.keep(&e(T + 10, 4, 4)));
        assert!(!f.keep(&e(T + 20, 20, 4)));
        assert_eq!(f.removed(), 2);
    }
}
