//! Voxel grids: `B` temporal bins over the window `[t_k - W, t_k)`, tonic's
//! `to_voxel_grid_numpy` weighting, normalized to the window.
//!
//! An event at `t` sits at `ts = B (t - t0) / W` (`t0 = t_k - W`) and gives `w (1 - frac)` to
//! bin `floor(ts)` and `w frac` to the next bin (dropped past the last), with `w` -1 for OFF and
//! +1 for ON, exactly as tonic splits it. tonic normalizes by the first and last event it is
//! given; here the window's own edges are, so a bin always means the same stretch of time
//! before `t_k` whatever the events (tonic gives the same with an event at each edge of the
//! window, which its tests here add: the one at `t0` cancelled by an opposite one, the one at
//! `t_k` weightless at `ts = B`).
//!
//! # Incremental pooling, exactly
//! As `t_k` moves, every event's `ts` moves, so no value stays put; but a bin's total is linear
//! in the events' times. For the events of interval `j` (`j <= ts < j + 1`) keep `S0 = sum w`
//! and `P = sum w t`; with `Q = P - t0 S0 = sum w (t - t0)`,
//! `bin_j = (1 + j) S0_j - (j - 1) S0_{j-1} + B (Q_{j-1} - Q_j) / W`.
//! The sums are integers, kept per cell and interval in wrapping i64 arithmetic: `P` of
//! timestamps since the epoch overflows, but `Q` and `B (Q_{j-1} - Q_j)` are exact modulo 2^64
//! and their true values fit an i64 (below `B W` times the window's events in a cell: 2^63 only
//! past 10^8 events per cell in a 1000 s window of 64 bins), so the wrapped results are the
//! exact ones. The `B - 1`
//! boundaries between intervals are cursors into the window's events that only move forward:
//! an event crosses each once. Frames are built on request from the window's events in tonic's
//! own order of operations (all left shares, then all right shares, float64).

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use super::{Channels, Placed};
use crate::ReprError;

/// The most bins a voxel grid may have (the features grow by 900 per bin).
const MAX_BINS: u32 = 64;

/// Settings of a voxel grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VoxelGridConfig {
    /// The window before each sample time, in milliseconds (a whole number of microseconds).
    pub window_ms: f64,
    /// Temporal bins (tonic's `n_time_bins`), 1 to 64.
    pub bins: u32,
}

impl Default for VoxelGridConfig {
    /// The paper's dynamic window, 640 ms, in 5 bins (evtac's choice: 4500 features, within
    /// what the networks read), as the starting point (`tune` searches around it).
    fn default() -> Self {
        Self {
            window_ms: 640.0,
            bins: 5,
        }
    }
}

impl VoxelGridConfig {
    /// Checks the window and the bins.
    pub fn validate(&self) -> Result<(), ReprError> {
        super::whole_us("window_ms", self.window_ms)?;
        if !(1..=MAX_BINS).contains(&self.bins) {
            return Err(ReprError::InvalidConfig {
                field: "bins",
                value: self.bins.to_string(),
                reason: "must be 1 to 64",
            });
        }
        Ok(())
    }

    /// `voxel-grid-w<window_ms>-b<bins>`.
    pub fn cache_key(&self) -> String {
        format!("voxel-grid-w{}-b{}", self.window_ms, self.bins)
    }
}

/// One event in the window: where it is and its weight.
#[derive(Debug, Clone, Copy)]
struct Entry {
    t: i64,
    pixel: u32,
    cell: u32,
    w: i8,
}

/// A voxel grid's state.
pub(super) struct VoxelGrid {
    window_us: i64,
    bins: usize,
    cells: usize,
    /// The events in the window, oldest first; `base` is the index (since the start) of the
    /// front one.
    queue: VecDeque<Entry>,
    base: u64,
    /// `cursor[j]` (j >= 1): the index of the first event in interval `j` or later.
    cursor: Vec<u64>,
    /// Per interval and cell: the sum of weights, and of weights times times (wrapping, see
    /// the module docs).
    s0: Vec<i64>,
    p: Vec<i64>,
}

impl VoxelGrid {
    pub(super) fn new(config: VoxelGridConfig, cells: usize) -> Self {
        let bins = config.bins as usize;
        Self {
            window_us: super::whole_us("window_ms", config.window_ms).expect("validated"),
            bins,
            cells,
            queue: VecDeque::new(),
            base: 0,
            cursor: vec![0; bins],
            s0: vec![0; bins * cells],
            p: vec![0; bins * cells],
        }
    }

    /// Adds (`sign` 1) or removes (-1) `e` to interval `j`'s sums.
    #[inline]
    fn account(&mut self, j: usize, e: Entry, sign: i64) {
        let at = j * self.cells + e.cell as usize;
        let w = i64::from(e.w) * sign;
        self.s0[at] += w;
        self.p[at] = self.p[at].wrapping_add(w.wrapping_mul(e.t));
    }
}

impl Channels for VoxelGrid {
    fn enter(&mut self, events: &[Placed]) {
        for e in events {
            let entry = Entry {
                t: e.t,
                pixel: e.pixel,
                cell: e.cell,
                w: if e.on { 1 } else { -1 },
            };
            // Past every cursor, so in the last interval until `settle` moves it down.
            self.queue.push_back(entry);
            self.account(self.bins - 1, entry, 1);
        }
    }

    fn settle(&mut self, t_k: i64) {
        let t0 = i128::from(t_k) - i128::from(self.window_us);
        let (b, w) = (self.bins as i128, i128::from(self.window_us));
        let end = self.base + self.queue.len() as u64;
        // From the last boundary down, so an event can fall through several intervals.
        for j in (1..self.bins).rev() {
            while self.cursor[j] < end {
                let e = self.queue[(self.cursor[j] - self.base) as usize];
                if b * (i128::from(e.t) - t0) >= j as i128 * w {
                    break;
                }
                self.account(j, e, -1);
                self.account(j - 1, e, 1);
                self.cursor[j] += 1;
            }
        }
        // Events before the window's start are in interval 0 (every cursor has passed them).
        while let Some(&e) = self.queue.front() {
            if i128::from(e.t) >= t0 {
                break;
            }
            self.account(0, e, -1);
            self.queue.pop_front();
            self.base += 1;
        }
        for c in &mut self.cursor[1..] {
            *c = (*c).max(self.base);
        }
    }

    fn features(&self, t_k: i64, out: &mut [f32]) {
        let t0 = t_k.wrapping_sub(self.window_us);
        let (b, w) = (self.bins as i64, self.window_us as f64);
        for c in 0..self.cells {
            // Interval j-1's sums, carried from the previous bin (none before bin 0).
            let (mut s0_prev, mut q_prev) = (0i64, 0i64);
            for j in 0..self.bins {
                let at = j * self.cells + c;
                let s0 = self.s0[at];
                let q = self.p[at].wrapping_sub(t0.wrapping_mul(s0));
                let whole = (1 + j as i64) * s0 - (j as i64 - 1) * s0_prev;
                let num = q_prev.wrapping_sub(q).wrapping_mul(b) as f64;
                out[at] = ((whole as f64 + num / w) / 64.0) as f32;
                (s0_prev, q_prev) = (s0, q);
            }
        }
    }

    fn frame(&self, t_k: i64, out: &mut [f32]) {
        let t0 = t_k - self.window_us;
        let pixels = out.len() / self.bins;
        let mut grid = vec![0.0f64; out.len()];
        let (n, span) = (self.bins as f64, self.window_us as f64);
        let split = |e: &Entry| {
            let ts = (n * (e.t as f64 - t0 as f64)) / span;
            let ti = ts as usize;
            (ti, ts - ti as f64, f64::from(e.w))
        };
        // tonic's order: every left share, then every right share.
        for e in &self.queue {
            let (ti, frac, w) = split(e);
            if ti < self.bins {
                grid[ti * pixels + e.pixel as usize] += w * (1.0 - frac);
            }
        }
        for e in &self.queue {
            let (ti, frac, w) = split(e);
            if ti + 1 < self.bins {
                grid[(ti + 1) * pixels + e.pixel as usize] += w * frac;
            }
        }
        for (v, g) in out.iter_mut().zip(grid) {
            *v = g as f32;
        }
    }

    fn reset(&mut self) {
        self.queue.clear();
        self.base = 0;
        self.cursor.fill(0);
        self.s0.fill(0);
        self.p.fill(0);
    }
}
