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

/// The last events of the columns (each `at` its row) or of the rows (each `at` its column),
/// slot `i` at `i + 1` with a padding slot at each end, so that the three neighbouring slots
/// are always there to read (no clipping at the edges).
#[derive(Debug, Clone)]
struct Slots(Vec<Slot>);

/// One slot: its event's timestamp and [`key_of`] its polarity and coordinate.
#[derive(Debug, Clone, Copy)]
struct Slot {
    t: i64,
    key: u32,
}

/// A slot's polarity and coordinate in one number, `polarity << 17 | at`, so that "same
/// polarity and `at` within 1 of `c`" is one test: `key + 1 - key_of(polarity, c) <= 2` in
/// wrapping u32 arithmetic. With equal polarities that is `at - c` in `{-1, 0, 1}`; with
/// different ones (at least 2^17 apart against coordinates at most 2^16 - 1 apart) it never
/// holds.
fn key_of(polarity: u8, at: u16) -> u32 {
    u32::from(polarity) << 17 | u32::from(at)
}

/// The polarity of the padding slots, which no event has: a padding slot never supports,
/// whatever its timestamp (no timestamp could stand for "never" under the wrapping
/// subtraction).
const NO_POLARITY: u8 = 2;

impl Slots {
    /// `n` slots at dv-processing's start, (timestamp 0, coordinate 0, OFF), and the padding.
    fn new(n: u16) -> Self {
        let n = usize::from(n);
        let start = Slot {
            t: 0,
            key: key_of(0, 0),
        };
        let padding = Slot {
            t: 0,
            key: key_of(NO_POLARITY, 0),
        };
        let mut slots = vec![start; n + 2];
        slots[0] = padding;
        slots[n + 1] = padding;
        Self(slots)
    }

    /// Whether slot `i - 1`, `i` or `i + 1` holds an event of `event`'s polarity within 1 of
    /// `at` and at most `duration` before `event`. All three are tested and combined with `|`,
    /// not `any`: a short-circuit would branch on data-dependent answers (polarity, distance,
    /// time), mispredicting often.
    #[inline(always)]
    fn support(&self, i: usize, event: &Event, at: u16, duration: i64) -> bool {
        let slots: &[Slot; 3] = self.0[i..i + 3].try_into().expect("a range of three");
        let want = key_of(u8::from(event.polarity), at);
        let near = |slot: &Slot| {
            // Wrapping: dv-processing subtracts int64s as they come, whatever they are.
            (slot.key.wrapping_add(1).wrapping_sub(want) <= 2)
                & (event.t.wrapping_sub(slot.t) <= duration)
        };
        near(&slots[0]) | near(&slots[1]) | near(&slots[2])
    }

    /// Slot `i` takes `event`, `at` its row or column.
    #[inline(always)]
    fn take(&mut self, i: usize, event: &Event, at: u16) {
        self.0[i + 1] = Slot {
            t: event.t,
            key: key_of(u8::from(event.polarity), at),
        };
    }

    /// The number of slots, padding excluded.
    fn len(&self) -> usize {
        self.0.len() - 2
    }
}

/// Keeps events supported by a recent event of the same polarity in the neighbouring columns'
/// or rows' slots.
#[derive(Debug, Clone)]
pub struct KNoise {
    columns: Slots,
    rows: Slots,
    duration: i64,
}

impl KNoise {
    /// The filter for `sensor`, with slots counted for `duration`.
    pub fn new(sensor: Resolution, duration: Micros) -> Self {
        Self {
            columns: Slots::new(sensor.width),
            rows: Slots::new(sensor.height),
            duration: duration.get(),
        }
    }
}

impl Rule for KNoise {
    const NAME: &'static str = "k-noise";

    // `always`: with `#[inline]` alone LLVM judged it too big and kept a call per event.
    #[inline(always)]
    fn accept(&mut self, event: &Event) -> bool {
        let (x, y) = (usize::from(event.x), usize::from(event.y));
        // Off the sensor dv-processing would index past its slots: removed here.
        if x >= self.columns.len() || y >= self.rows.len() {
            return false;
        }
        let keep = self.columns.support(x, event, event.y, self.duration)
            | self.rows.support(y, event, event.x, self.duration);
        self.columns.take(x, event, event.y);
        self.rows.take(y, event, event.x);
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
    fn one_key_test_is_same_polarity_and_within_one() {
        let coordinates = [0u16, 1, 2, 3, 1000, 65533, 65534, 65535];
        for slot_polarity in [0, 1, NO_POLARITY] {
            for event_polarity in [0, 1] {
                for &at in &coordinates {
                    for &c in &coordinates {
                        let key = key_of(slot_polarity, at);
                        let one_test =
                            key.wrapping_add(1).wrapping_sub(key_of(event_polarity, c)) <= 2;
                        let expected = slot_polarity == event_polarity && at.abs_diff(c) <= 1;
                        assert_eq!(
                            one_test, expected,
                            "{slot_polarity} {event_polarity} {at} {c}"
                        );
                    }
                }
            }
        }
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
