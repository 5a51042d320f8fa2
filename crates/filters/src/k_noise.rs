//! `k-noise=DURATION`: dv-processing's `dv::noise::KNoiseFilter`
//! (`include/dv-processing/noise/k_noise_filter.hpp`), the O(N)-memory filter of Khodamoradi
//! and Kastner: one slot per column and one per row instead of one per pixel.
//!
//! A column's slot holds the last event in that column (its timestamp, row and polarity), a
//! row's slot the last event in that row (timestamp, column, polarity). An event at `(x, y)` is
//! kept when a slot of column `x - 1`, `x` or `x + 1` holds an event of the same polarity at a
//! row within 1 of `y`, or a slot of row `y - 1`, `y` or `y + 1` one at a column within 1 of `x`,
//! with `t - slot.t <= DURATION` (inclusive, unlike the background-activity filter's strict
//! comparison). Columns and rows beyond the sensor's edges are not looked at. Then, kept or not,
//! the event takes the slots of its column and its row.
//!
//! No copy of this filter's C++ source was at hand, so these rules were read off dv-processing
//! 2.0.4's binary (its Python `retain`, event by event on probing streams) and are checked
//! against it on random streams and a real recording (`tests/dv_processing.rs`). Among them:
//! slots start as (timestamp 0, coordinate 0, OFF), so an OFF event at `t <= DURATION` within
//! one pixel of row 0 or column 0 is kept; the difference is signed (a timestamp earlier than
//! the slot's counts as recent); the 3x3 neighbourhood includes the pixel itself.

use evtac_events::{Event, Resolution};

use crate::{Micros, Rule};

/// The last event of one column (`at` its row) or of one row (`at` its column).
#[derive(Debug, Clone, Copy)]
struct Slot {
    t: i64,
    at: u16,
    /// 0 (OFF) or 1 (ON); [`NO_POLARITY`] in the padding slots.
    polarity: u8,
}

/// The polarity of the slots beyond the sensor's edges, which no event has: a padding slot
/// never supports, whatever its timestamp (no timestamp could stand for "never" under the
/// wrapping subtraction).
const NO_POLARITY: u8 = 2;

impl Slot {
    /// dv-processing's starting slot: (0, 0, OFF).
    const START: Self = Self {
        t: 0,
        at: 0,
        polarity: 0,
    };
    const PADDING: Self = Self {
        polarity: NO_POLARITY,
        ..Self::START
    };

    fn of(event: &Event, at: u16) -> Self {
        Self {
            t: event.t,
            at,
            polarity: u8::from(event.polarity),
        }
    }
}

/// Keeps events supported by a recent event of the same polarity in the neighbouring columns'
/// or rows' slots.
#[derive(Debug, Clone)]
pub struct KNoise {
    /// Column `x`'s slot at `x + 1`, with a padding slot at each end, so that the three
    /// neighbouring slots are always there to read (no clipping at the edges); rows alike.
    columns: Vec<Slot>,
    rows: Vec<Slot>,
    duration: i64,
}

impl KNoise {
    /// The filter for `sensor`, with slots counted for `duration`.
    pub fn new(sensor: Resolution, duration: Micros) -> Self {
        let padded = |n: u16| {
            let mut slots = vec![Slot::START; usize::from(n) + 2];
            slots[0] = Slot::PADDING;
            slots[usize::from(n) + 1] = Slot::PADDING;
            slots
        };
        Self {
            columns: padded(sensor.width),
            rows: padded(sensor.height),
            duration: duration.get(),
        }
    }
}

/// The slots of `i - 1`, `i` and `i + 1` in `padded` (slot `i` at `i + 1`).
#[inline]
fn neighbours(padded: &[Slot], i: usize) -> &[Slot; 3] {
    padded[i..i + 3].try_into().expect("a range of three")
}

impl Rule for KNoise {
    const NAME: &'static str = "k-noise";

    fn accept(&mut self, event: &Event) -> bool {
        let (x, y) = (usize::from(event.x), usize::from(event.y));
        // Off the sensor dv-processing would index past its slots: removed here.
        if x + 2 >= self.columns.len() || y + 2 >= self.rows.len() {
            return false;
        }
        let polarity = u8::from(event.polarity);
        let near = |slot: &Slot, coordinate: u16| {
            (slot.polarity == polarity)
                & (slot.at.abs_diff(coordinate) <= 1)
                // Wrapping: dv-processing subtracts int64s as they come, whatever they are.
                & (event.t.wrapping_sub(slot.t) <= self.duration)
        };
        // All six slots tested and combined with `|`, not `any`: a short-circuit would branch
        // on data-dependent answers (polarity, distance, time), mispredicting often.
        let [c0, c1, c2] = neighbours(&self.columns, x);
        let [r0, r1, r2] = neighbours(&self.rows, y);
        let keep = near(c0, event.y)
            | near(c1, event.y)
            | near(c2, event.y)
            | near(r0, event.x)
            | near(r1, event.x)
            | near(r2, event.x);
        self.columns[x + 1] = Slot::of(event, event.y);
        self.rows[y + 1] = Slot::of(event, event.x);
        keep
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Filter;

    const T: i64 = 1_000_000;

    fn run(events: &[(i64, u16, u16, bool)]) -> Vec<bool> {
        let mut f = KNoise::new(Resolution::new(20, 20), Micros::new(1_000).unwrap()).counted();
        events
            .iter()
            .map(|&(t, x, y, polarity)| f.keep(&Event { t, x, y, polarity }))
            .collect()
    }

    #[test]
    fn the_three_by_three_neighbourhood_supports_inclusively() {
        for dy in -2i32..=2 {
            for dx in -2i32..=2 {
                let (x, y) = ((5 + dx) as u16, (5 + dy) as u16);
                let near = dx.abs() <= 1 && dy.abs() <= 1;
                assert_eq!(run(&[(T, 5, 5, true), (T + 10, x, y, true)])[1], near);
            }
        }
        assert_eq!(
            run(&[(T, 5, 5, true), (T + 1_000, 6, 6, true)]),
            [false, true]
        );
        assert_eq!(
            run(&[(T, 5, 5, true), (T + 1_001, 6, 6, true)]),
            [false, false]
        );
    }

    #[test]
    fn polarity_must_match() {
        assert_eq!(
            run(&[(T, 5, 5, true), (T + 10, 6, 5, false)]),
            [false, false]
        );
    }

    #[test]
    fn one_slot_per_column_and_per_row() {
        // (5, 15) takes column 5's slot; row 5's still supports (6, 6).
        assert_eq!(
            run(&[(T, 5, 5, true), (T + 1, 5, 15, true), (T + 10, 6, 6, true)]),
            [false, false, true]
        );
        // With (15, 5) taking row 5's slot as well, nothing is left.
        assert_eq!(
            run(&[
                (T, 5, 5, true),
                (T + 1, 5, 15, true),
                (T + 2, 15, 5, true),
                (T + 10, 6, 6, true)
            ]),
            [false, false, false, false]
        );
        // An OFF event takes the slots too.
        assert_eq!(
            run(&[
                (T, 5, 5, true),
                (T + 1, 5, 15, false),
                (T + 2, 15, 5, false),
                (T + 10, 6, 6, true)
            ]),
            [false, false, false, false]
        );
    }

    #[test]
    fn slots_start_as_an_off_event_at_zero_in_row_and_column_zero() {
        assert_eq!(run(&[(1_000, 5, 1, false)]), [true]);
        assert_eq!(run(&[(1_000, 1, 7, false)]), [true]);
        assert_eq!(run(&[(1_001, 5, 1, false)]), [false]);
        assert_eq!(run(&[(1_000, 5, 1, true)]), [false]);
        assert_eq!(run(&[(1_000, 5, 5, false)]), [false]);
    }

    #[test]
    fn edges_do_not_wrap_and_earlier_timestamps_count_as_recent() {
        assert_eq!(
            run(&[(T, 19, 5, true), (T + 1, 0, 5, true)]),
            [false, false]
        );
        assert_eq!(
            run(&[(T, 19, 19, true), (T + 1, 18, 18, true)]),
            [false, true]
        );
        assert_eq!(
            run(&[(T, 5, 5, true), (T - 5_000, 5, 5, true)]),
            [false, true]
        );
    }
}
