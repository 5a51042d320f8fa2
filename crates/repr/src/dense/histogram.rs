//! Polarity histograms: event counts per polarity and pixel over the window `[t_k - W, t_k)`,
//! tonic's `to_frame_numpy` with `time_window` (its slice ending at `t_k`).
//!
//! Every event enters once and leaves once, through a FIFO; each cell keeps the sum of its
//! pixels' counts, so the pooled feature `sum / 64` is exact and a sample costs only the events
//! that moved.

use serde::{Deserialize, Serialize};

use super::{Channels, Placed};
use crate::ReprError;
use crate::fifo::Fifo;

/// Settings of a polarity histogram.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HistogramConfig {
    /// The window before each sample time, in milliseconds (a whole number of microseconds).
    pub window_ms: f64,
}

impl Default for HistogramConfig {
    /// The paper's dynamic window, 640 ms, as the starting point (`tune` searches around it).
    fn default() -> Self {
        Self { window_ms: 640.0 }
    }
}

impl HistogramConfig {
    /// Checks the window.
    pub fn validate(&self) -> Result<(), ReprError> {
        super::whole_us("window_ms", self.window_ms).map(|_| ())
    }

    /// `histogram-w<window_ms>`.
    pub fn cache_key(&self) -> String {
        format!("histogram-w{}", self.window_ms)
    }
}

/// The histogram's state: counts per channel and pixel, sums per channel and cell, and the
/// events in the window.
pub(super) struct Histogram {
    window_us: i64,
    pixels: usize,
    cells: usize,
    counts: Vec<u32>,
    sums: Vec<u32>,
    queue: Fifo<Placed>,
}

impl Histogram {
    pub(super) fn new(config: HistogramConfig, pixels: usize, cells: usize) -> Self {
        Self {
            window_us: super::whole_us("window_ms", config.window_ms).expect("validated"),
            pixels,
            cells,
            counts: vec![0; 2 * pixels],
            sums: vec![0; 2 * cells],
            queue: Fifo::new(),
        }
    }
}

impl Channels for Histogram {
    fn enter(&mut self, events: &[Placed]) {
        for e in events {
            let channel = usize::from(e.on);
            self.counts[channel * self.pixels + e.pixel as usize] += 1;
            self.sums[channel * self.cells + e.cell as usize] += 1;
            self.queue.push_back(*e);
        }
    }

    fn settle(&mut self, t_k: i64) {
        let start = t_k.saturating_sub(self.window_us);
        let (counts, sums) = (&mut self.counts, &mut self.sums);
        let (pixels, cells) = (self.pixels, self.cells);
        self.queue.pop_while(
            |e| e.t < start,
            |e| {
                let channel = usize::from(e.on);
                counts[channel * pixels + e.pixel as usize] -= 1;
                sums[channel * cells + e.cell as usize] -= 1;
            },
        );
    }

    fn features(&self, _t_k: i64, out: &mut [f32]) {
        for (f, &n) in out.iter_mut().zip(&self.sums) {
            *f = n as f32 / 64.0;
        }
    }

    fn frame(&self, _t_k: i64, out: &mut [f32]) {
        for (v, &n) in out.iter_mut().zip(&self.counts) {
            *v = n as f32;
        }
    }

    fn reset(&mut self) {
        self.counts.fill(0);
        self.sums.fill(0);
        self.queue.clear();
    }
}
