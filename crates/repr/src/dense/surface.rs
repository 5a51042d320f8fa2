//! Time surfaces: per polarity and pixel, `exp(-(t_k - t_last) / tau)` with `t_last` the
//! pixel's latest event before `t_k` (0 where it has none), tonic's `to_timesurface_numpy` at
//! its slice ends; and the binarized form, 1 where that value is above a threshold.
//!
//! # Continuous: pooled without recomputing every pixel
//! Every pixel's value decays at every sample, so pooling the frame afresh would cost 115 200
//! exponentials per sample. Instead each cell keeps `A = sum over its pixels of
//! exp((t_last - t_ref) / tau)` for a reference time `t_ref`; the pooled value at `t_k` is
//! `exp(-(t_k - t_ref) / tau) * A / 64`. An event replaces its pixel's term. `t_ref` moves
//! forward (and `A` is recomputed exactly from the pixels' times) before the terms could
//! overflow and after every [`REFRESH_EVENTS`] events, so rounding cannot pile up: the pooled
//! features agree with the mean of the frame's float64 values to far below float32's rounding.
//!
//! # Binarized: a window in disguise
//! `exp(-d / tau) > X` holds exactly for the ages `d` below the smallest whole `d` where it
//! fails, found once with the same `exp`. A pixel is set while its latest event is younger
//! than that, which is a sliding window: the counts are exact and a sample costs only the
//! events that entered or aged out.

use serde::{Deserialize, Serialize};

use super::{Channels, Placed};
use crate::ReprError;
use crate::fifo::Fifo;

/// Events between two exact recomputations of the cells' sums (see the module docs).
const REFRESH_EVENTS: u32 = 1 << 22;
/// How far (in units of tau) events may run ahead of the reference time before it moves:
/// `exp(40)` is about 2e17, far from float64's limit, and a cell of 64 such terms keeps 15
/// digits.
const REBASE_TAUS: f64 = 40.0;

/// Settings of a time surface.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSurfaceConfig {
    /// The decay constant in milliseconds (tonic's `tau`, there in the events' time unit).
    pub tau_ms: f64,
    /// Binarize: a pixel is 1 where its value is strictly above this (in (0, 1)), else 0.
    /// `None` keeps the continuous values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<f64>,
}

impl Default for TimeSurfaceConfig {
    /// evtac's starting point, where the paper states none: tau 100 ms (a pin's events fade
    /// over about the time a contact phase changes), continuous values. `tune` searches
    /// around it.
    fn default() -> Self {
        Self {
            tau_ms: 100.0,
            threshold: None,
        }
    }
}

impl TimeSurfaceConfig {
    /// Checks tau (finite, > 0) and the threshold (in (0, 1)).
    pub fn validate(&self) -> Result<(), ReprError> {
        if !(self.tau_ms.is_finite() && self.tau_ms > 0.0) {
            return Err(ReprError::InvalidConfig {
                field: "tau_ms",
                value: self.tau_ms.to_string(),
                reason: "must be finite and > 0",
            });
        }
        if let Some(x) = self.threshold
            && !(x > 0.0 && x < 1.0)
        {
            return Err(ReprError::InvalidConfig {
                field: "threshold",
                value: x.to_string(),
                reason: "must be in (0, 1): time surface values lie in [0, 1]",
            });
        }
        Ok(())
    }

    /// `time-surface-tau<tau_ms>` (`-th<threshold>` when binarized).
    pub fn cache_key(&self) -> String {
        match self.threshold {
            Some(x) => format!("time-surface-tau{}-th{x}", self.tau_ms),
            None => format!("time-surface-tau{}", self.tau_ms),
        }
    }

    /// tau in microseconds, as tonic divides by it.
    pub fn tau_us(&self) -> f64 {
        self.tau_ms * 1000.0
    }

    /// The value of a pixel whose latest event is `age` microseconds old: tonic's
    /// `np.exp(-(T - memory) / tau)` in float64 (the difference is exact for integer times).
    #[inline]
    pub fn value(&self, age: i64) -> f64 {
        (-(age as f64) / self.tau_us()).exp()
    }

    /// For a binarized surface, the smallest age in microseconds at which the value is no
    /// longer above the threshold (`None` when continuous). `value` only falls with age, so a
    /// pixel is set exactly while its latest event is younger than this.
    pub fn set_below_age(&self) -> Option<i64> {
        let x = self.threshold?;
        // A first guess from the inverse, then the same `exp` decides at the boundary.
        let guess = (-self.tau_us() * x.ln()).ceil().clamp(0.0, 1e17) as i64;
        let mut d = guess;
        while d > 0 && self.value(d - 1) <= x {
            d -= 1;
        }
        while self.value(d) > x {
            d += 1;
        }
        Some(d)
    }
}

/// The latest event time of a pixel that has none.
const NEVER: i64 = i64::MIN;

/// A time surface's state.
pub(super) struct TimeSurface {
    config: TimeSurfaceConfig,
    tau_us: f64,
    pixels: usize,
    cells: usize,
    /// The latest event time per channel and pixel ([`NEVER`] for none).
    last: Vec<i64>,
    /// The cell of each pixel (for the exact recomputation).
    cell_of: Vec<u32>,
    mode: Mode,
}

enum Mode {
    /// Per channel and cell, the sum of `exp((t_last - t_ref) / tau)` over its pixels.
    Continuous {
        t_ref: i64,
        sums: Vec<f64>,
        since_refresh: u32,
    },
    /// Events younger than `set_below`, and per channel the pixels' and cells' counts of them.
    Binarized {
        set_below: i64,
        counts: Vec<u32>,
        on: Vec<u32>,
        queue: Fifo<Placed>,
    },
}

impl TimeSurface {
    pub(super) fn new(config: TimeSurfaceConfig, cell_of: &[u32], cells: usize) -> Self {
        let pixels = cell_of.len();
        let mode = match config.set_below_age() {
            Some(set_below) => Mode::Binarized {
                set_below,
                counts: vec![0; 2 * pixels],
                on: vec![0; 2 * cells],
                queue: Fifo::new(),
            },
            None => Mode::Continuous {
                t_ref: 0,
                sums: vec![0.0; 2 * cells],
                since_refresh: 0,
            },
        };
        Self {
            config,
            tau_us: config.tau_us(),
            pixels,
            cells,
            last: vec![NEVER; 2 * pixels],
            cell_of: cell_of.to_vec(),
            mode,
        }
    }

    /// The continuous sums recomputed exactly at reference time `t_ref`.
    fn refresh(&mut self, t_ref: i64) {
        let Mode::Continuous {
            t_ref: r,
            sums,
            since_refresh,
        } = &mut self.mode
        else {
            return;
        };
        sums.fill(0.0);
        for channel in 0..2 {
            for p in 0..self.pixels {
                let t = self.last[channel * self.pixels + p];
                if t != NEVER {
                    let cell = self.cell_of[p] as usize;
                    sums[channel * self.cells + cell] += ((t - t_ref) as f64 / self.tau_us).exp();
                }
            }
        }
        *r = t_ref;
        *since_refresh = 0;
    }
}

impl Channels for TimeSurface {
    fn enter(&mut self, events: &[Placed]) {
        for e in events {
            let (channel, pixel) = (usize::from(e.on), e.pixel as usize);
            let slot = channel * self.pixels + pixel;
            let old = std::mem::replace(&mut self.last[slot], e.t);
            let refresh = match &mut self.mode {
                Mode::Continuous {
                    t_ref,
                    sums,
                    since_refresh,
                } => {
                    let ahead = (e.t - *t_ref) as f64 > REBASE_TAUS * self.tau_us;
                    if !ahead && *since_refresh < REFRESH_EVENTS {
                        let sum = &mut sums[channel * self.cells + e.cell as usize];
                        if old != NEVER {
                            *sum -= ((old - *t_ref) as f64 / self.tau_us).exp();
                        }
                        *sum += ((e.t - *t_ref) as f64 / self.tau_us).exp();
                        *since_refresh += 1;
                    }
                    ahead || *since_refresh >= REFRESH_EVENTS
                }
                Mode::Binarized {
                    counts, on, queue, ..
                } => {
                    let count = &mut counts[slot];
                    *count += 1;
                    if *count == 1 {
                        on[channel * self.cells + e.cell as usize] += 1;
                    }
                    queue.push_back(*e);
                    false
                }
            };
            if refresh {
                // Recomputed from `last`, which already holds this event.
                self.refresh(e.t);
            }
        }
    }

    fn settle(&mut self, t_k: i64) {
        let (pixels, cells) = (self.pixels, self.cells);
        if let Mode::Binarized {
            set_below,
            counts,
            on,
            queue,
        } = &mut self.mode
        {
            // Set while `t_k - t < set_below`: events with `t <= t_k - set_below` have aged out.
            let oldest = t_k.saturating_sub(*set_below);
            queue.pop_while(
                |e| e.t <= oldest,
                |e| {
                    let channel = usize::from(e.on);
                    let count = &mut counts[channel * pixels + e.pixel as usize];
                    *count -= 1;
                    if *count == 0 {
                        on[channel * cells + e.cell as usize] -= 1;
                    }
                },
            );
        }
    }

    fn features(&self, t_k: i64, out: &mut [f32]) {
        match &self.mode {
            Mode::Continuous { t_ref, sums, .. } => {
                let decay = (-((t_k - t_ref) as f64) / self.tau_us).exp();
                for (f, &a) in out.iter_mut().zip(sums) {
                    // Never below 0: a cell whose pixels have all decayed may keep a rounding
                    // residue of either sign.
                    *f = (a * decay / 64.0).max(0.0) as f32;
                }
            }
            Mode::Binarized { on, .. } => {
                for (f, &n) in out.iter_mut().zip(on) {
                    *f = n as f32 / 64.0;
                }
            }
        }
    }

    fn frame(&self, t_k: i64, out: &mut [f32]) {
        match &self.mode {
            Mode::Continuous { .. } => {
                for (v, &t) in out.iter_mut().zip(&self.last) {
                    *v = if t == NEVER {
                        0.0
                    } else {
                        self.config.value(t_k - t) as f32
                    };
                }
            }
            Mode::Binarized { counts, .. } => {
                for (v, &n) in out.iter_mut().zip(counts) {
                    *v = if n > 0 { 1.0 } else { 0.0 };
                }
            }
        }
    }

    fn reset(&mut self) {
        self.last.fill(NEVER);
        match &mut self.mode {
            Mode::Continuous {
                t_ref,
                sums,
                since_refresh,
            } => {
                *t_ref = 0;
                sums.fill(0.0);
                *since_refresh = 0;
            }
            Mode::Binarized {
                counts, on, queue, ..
            } => {
                counts.fill(0);
                on.fill(0);
                queue.clear();
            }
        }
    }
}
