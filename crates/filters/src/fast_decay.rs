//! `fast-decay=HALF_LIFE[,SUBDIVISION[,THRESHOLD]]`: dv-processing's
//! `dv::noise::FastDecayNoiseFilter` (`include/dv-processing/noise/fast_decay_noise_filter.hpp`),
//! defaults 10 ms, 4 and 6 as there.
//!
//! The sensor is cut into cells of `SUBDIVISION x SUBDIVISION` pixels (`x / SUBDIVISION`,
//! `y / SUBDIVISION`, integer division; the grid is `width / SUBDIVISION + 1` by
//! `height / SUBDIVISION + 1` cells, the `+ 1` as dv-processing sizes it). Each cell holds a
//! float32 count that halves every HALF_LIFE: at an event, in float32 as dv-processing computes
//! it, `count = count * exp2(-(float)(t - last) / (float)HALF_LIFE) + 1`, and `last = t`; the
//! event is kept when `count > THRESHOLD`, strictly. Every cell starts at count 0 and `last` 0.
//! `exp2` is the platform's `exp2f` (glibc's on Linux, the one dv-processing calls), and the
//! multiply and add stay two roundings (no fused multiply-add), as in dv-processing's build.

use evtac_events::{Event, Resolution};

use crate::{Micros, Rule};

/// Keeps events in cells of the sensor with enough recent, decaying activity.
#[derive(Debug, Clone)]
pub struct FastDecay {
    /// Each column's cell column, and each row's first cell: `x / SUBDIVISION` and
    /// `y / SUBDIVISION * columns`, looked up rather than divided per event (a division by a
    /// number known only at run time is the slowest integer instruction), and only for the
    /// sensor's pixels, so a lookup that fails is an event off the sensor.
    cell_of_column: Vec<u32>,
    cell_of_row: Vec<u32>,
    cells: Vec<Cell>,
    half_life: f32,
    threshold: f32,
}

/// One cell's decaying count and the time it was last updated, side by side: an event reads
/// and writes both.
#[derive(Debug, Clone, Copy, Default)]
struct Cell {
    last: i64,
    count: f32,
}

impl FastDecay {
    /// dv-processing's defaults: 10 ms half-life, 4x4-pixel cells, threshold 6.
    pub const DEFAULT_HALF_LIFE_US: i64 = 10_000;
    /// The default cell size, in pixels.
    pub const DEFAULT_SUBDIVISION: u16 = 4;
    /// The default threshold on a cell's count.
    pub const DEFAULT_THRESHOLD: f32 = 6.0;

    /// The filter for `sensor`: counts halving every `half_life`, cells of `subdivision` pixels
    /// (at least 1: a cell has pixels), events kept above `threshold`.
    ///
    /// # Panics
    /// When `subdivision` is 0 ([`crate::FilterSpec`] refuses it with an error).
    pub fn new(sensor: Resolution, half_life: Micros, subdivision: u16, threshold: f32) -> Self {
        assert!(subdivision > 0, "a fast-decay cell has at least one pixel");
        let columns = u32::from(sensor.width / subdivision) + 1;
        let rows = u32::from(sensor.height / subdivision) + 1;
        let sub = u32::from(subdivision);
        Self {
            cell_of_column: (0..u32::from(sensor.width)).map(|x| x / sub).collect(),
            cell_of_row: (0..u32::from(sensor.height))
                .map(|y| y / sub * columns)
                .collect(),
            cells: vec![Cell::default(); (columns * rows) as usize],
            // dv-processing keeps the half-life as a float32 number of microseconds.
            half_life: half_life.get() as f32,
            threshold,
        }
    }
}

impl Rule for FastDecay {
    const NAME: &'static str = "fast-decay";

    #[inline]
    fn accept(&mut self, event: &Event) -> bool {
        // Off the sensor: removed, as by the other filters (dv-processing's grid has a spare
        // row and column, but an event there is no event of this sensor).
        let (Some(column), Some(row)) = (
            self.cell_of_column.get(usize::from(event.x)),
            self.cell_of_row.get(usize::from(event.y)),
        ) else {
            return false;
        };
        let cell = &mut self.cells[(row + column) as usize];
        let elapsed = event.t.wrapping_sub(cell.last) as f32;
        let decay = (-elapsed / self.half_life).exp2();
        cell.last = event.t;
        let count = cell.count * decay + 1.0;
        cell.count = count;
        count > self.threshold
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Filter;

    const T: i64 = 1_000_000;

    fn filter(threshold: f32) -> crate::Counted<FastDecay> {
        FastDecay::new(
            Resolution::new(21, 10),
            Micros::new(10_000).unwrap(),
            4,
            threshold,
        )
        .counted()
    }

    fn e(t: i64, x: u16, y: u16) -> Event {
        Event {
            t,
            x,
            y,
            polarity: true,
        }
    }

    #[test]
    fn a_cell_passes_once_its_count_exceeds_the_threshold() {
        let mut f = filter(6.0);
        let kept: Vec<bool> = (0..8)
            .map(|i| f.keep(&e(T + i, 4 + (i % 4) as u16, 5)))
            .collect();
        // Counts 1, 2, ... decayed a little: above 6 from the seventh event on.
        assert_eq!(kept, [false, false, false, false, false, false, true, true]);
        assert_eq!(f.removed(), 6);
    }

    #[test]
    fn cells_are_whole_subdivisions_and_the_threshold_is_strict() {
        let mut f = filter(3.0);
        // x = 3 and x = 4 are in different cells: three events each, neither count above 3.
        let kept: Vec<bool> = (0..6)
            .map(|i| f.keep(&e(T, 3 + (i % 2) as u16, 5)))
            .collect();
        assert_eq!(kept, [false; 6]);
        // Equal timestamps: no decay, so the third event's count is exactly 3, not above it.
        let mut f = filter(3.0);
        assert!(!f.keep(&e(T, 8, 8)));
        assert!(!f.keep(&e(T, 9, 9)));
        assert!(!f.keep(&e(T, 10, 8)));
        assert!(f.keep(&e(T, 11, 9)));
    }

    #[test]
    fn the_last_partial_column_is_a_cell_of_its_own() {
        // Width 21 with cells of 4: x = 20 is the sixth column's only pixel.
        let mut f = filter(1.5);
        assert!(!f.keep(&e(T, 20, 0)));
        assert!(!f.keep(&e(T, 19, 0)));
        assert!(f.keep(&e(T, 20, 1)));
        assert!(!f.keep(&e(T, 21, 0)));
    }

    #[test]
    fn counts_halve_every_half_life() {
        let mut f = filter(1.5);
        assert!(!f.keep(&e(T, 0, 0)));
        // 1 * 0.5 + 1 = 1.5, not above 1.5.
        assert!(!f.keep(&e(T + 10_000, 0, 0)));
        // 1.5 * 0.5^0.5 + 1 = 2.06.
        assert!(f.keep(&e(T + 15_000, 0, 0)));
    }
}
