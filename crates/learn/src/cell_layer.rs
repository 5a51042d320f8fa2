//! The first layer on pooled cell counts, in exact arithmetic, so that it can be kept up to date
//! from the cells that changed.
//!
//! Every representation evtac builds pools a binary frame over 8x8 cells: each feature is
//! `count / 64` with `count` in `0..=64`. On such inputs the first layer is computed from the
//! counts with its weights in fixed point, `q = round(W * 2^s)` as `i32`, `s` the largest power
//! that keeps every `|q| <= 2^30`:
//!
//! ```text
//! z_j = f32( f64(bias_j) + (sum_i count_i * q_ij) * 2^-s / 64 )
//! ```
//!
//! The sum has at most 7200 terms (`MAX_INPUTS`: eight pooled frames side by side) of at most
//! `64 * 2^30`, so it and every partial sum are integers below `2^49` in magnitude: exact in
//! `f64`, whatever the order of the terms. That is the point: adding `(new - old) * q_i` for the cells that changed since the previous
//! sample gives the same bits as summing every cell from scratch, so a live estimator only
//! touches the rows of the few cells that changed (50-85 of 900 per millisecond at 3 M
//! events/s) instead of streaming all 0.9 MB of weights through the cache for every estimate
//! ([`crate::StreamingPredictor`]). The scaling by a power of two is exact, the bias is added
//! with one rounding in `f64`, then one rounding to `f32`. It is also the same on every CPU.
//!
//! Fixed point moves each weight by at most `2^-30` of the largest weight (`s` puts the largest
//! above `2^29`), so a pre-activation moves by at most `900 * 2^-30` (8e-7) of the largest
//! weight per frame: the size of the rounding a float32 sum of 900 terms makes anyway. Late
//! fusion's zero cross-branch weights stay exactly zero in fixed point.

use crate::model::{LAYER_SIZES, MAX_INPUTS};

/// Width of the first hidden layer: the number of sums.
const H1: usize = LAYER_SIZES[1];

/// Cells pooled per feature: a feature is `count / CELL_PIXELS`.
pub const CELL_PIXELS: u8 = 64;

/// The largest fixed-point weight magnitude, `2^30`: with counts up to 64 and 7200 inputs, sums
/// stay below `2^49`, well inside `f64`'s 53-bit integers.
const Q_MAX: f64 = (1u64 << 30) as f64;

/// Writes the pooled cell counts behind `features` (`count = x * 64`) into the first
/// `features.len()` of `counts`; `false` when a feature is not a multiple of 1/64 in `[0, 1]`
/// (then `counts` means nothing).
pub(crate) fn cell_counts(features: &[f32], counts: &mut [u8; MAX_INPUTS]) -> bool {
    let mut on_grid = true;
    for (c, &x) in counts.iter_mut().zip(features) {
        // Exact for every multiple of 1/64: multiplying by a power of two only moves the
        // exponent. The round trip through an integer is the grid test: `as u8` saturates
        // (NaN to 0), so anything off the grid or outside [0, 64] comes back different.
        // (Not `fract`, which is a libm call per value on the baseline target.)
        let scaled = x * f32::from(CELL_PIXELS);
        *c = scaled as u8;
        on_grid &= f32::from(*c) == scaled && *c <= CELL_PIXELS;
    }
    on_grid
}

/// A stream's state: the cell counts of the latest pooled sample and the first layer's exact
/// sums for them ([`crate::StreamingPredictor`] keeps one; [`crate::Predictor::predict`] streams
/// a batch through one). Kept apart from the layer, so a batch needs no copy of the weights.
#[derive(Debug, Clone)]
pub(crate) struct CellSums {
    /// The counts of the layer's inputs (the first `fan_in`; the rest stay 0).
    counts: [u8; MAX_INPUTS],
    sums: [f64; H1],
}

impl CellSums {
    /// All-zero counts, whose sums are all zero.
    pub(crate) fn new() -> Self {
        Self {
            counts: [0; MAX_INPUTS],
            sums: [0.0; H1],
        }
    }

    /// Moves the state to `counts` (the first `fan_in` of them), updating the sums from the
    /// cells that changed, and writes the layer's output for them into `h1`.
    pub(crate) fn update(
        &mut self,
        layer: &CellLayer,
        counts: &[u8; MAX_INPUTS],
        h1: &mut [f32; H1],
    ) {
        let fan_in = layer.fan_in();
        let cells = counts[..fan_in].iter().zip(&mut self.counts[..fan_in]);
        for (cell, (&new, old)) in cells.enumerate() {
            if new != *old {
                layer.add_cell(&mut self.sums, cell, i32::from(new) - i32::from(*old));
                *old = new;
            }
        }
        layer.output(&self.sums, h1);
    }
}

/// The first layer in fixed point (see the module docs): weights `[in][out]` row-major, so
/// the row of one input cell is contiguous.
#[derive(Debug, Clone)]
pub(crate) struct CellLayer {
    q: Vec<i32>,
    fan_out: usize,
    /// `2^-s / 64`: one count times one weight unit.
    unit: f64,
    bias: Vec<f32>,
}

impl CellLayer {
    /// From the transposed weight `[in, out]` (finite values) and the bias `[out]`.
    pub(crate) fn new(weight_t: &[f32], bias: &[f32]) -> Self {
        let fan_out = bias.len();
        let largest = weight_t
            .iter()
            .fold(0.0_f64, |m, &w| m.max(f64::from(w).abs()));
        let s = scale_exponent(largest);
        let scale = 2.0_f64.powi(s);
        let q = weight_t
            .iter()
            // |w| * 2^s <= 2^30 by the choice of `s`: the cast neither saturates nor wraps.
            .map(|&w| (f64::from(w) * scale).round() as i32)
            .collect();
        Self {
            q,
            fan_out,
            unit: 2.0_f64.powi(-s) / f64::from(CELL_PIXELS),
            bias: bias.to_vec(),
        }
    }

    /// `acc += delta * q[cell]`: the change of the integer sums when `cell`'s count changes
    /// by `delta`.
    #[inline]
    pub(crate) fn add_cell(&self, acc: &mut [f64], cell: usize, delta: i32) {
        let row = &self.q[cell * self.fan_out..(cell + 1) * self.fan_out];
        add_row(acc, row, f64::from(delta));
    }

    /// Inputs (cells) of the layer.
    pub(crate) fn fan_in(&self) -> usize {
        self.q.len() / self.fan_out
    }

    /// The integer sums of `counts` (the first `fan_in` of them) from scratch.
    pub(crate) fn sums(&self, counts: &[u8; MAX_INPUTS], acc: &mut [f64]) {
        sums(&self.q, self.fan_out, &counts[..self.fan_in()], acc);
    }

    /// The layer's output from its integer sums: `relu(f32(bias + sum * unit))`.
    pub(crate) fn output(&self, acc: &[f64], out: &mut [f32]) {
        for ((o, &a), &b) in out.iter_mut().zip(acc).zip(&self.bias) {
            *o = ((f64::from(b) + a * self.unit) as f32).max(0.0);
        }
    }
}

/// The largest `s` with `largest * 2^s <= 2^30` (0 for an all-zero layer).
fn scale_exponent(largest: f64) -> i32 {
    if largest == 0.0 {
        return 0;
    }
    // `log2` can be off by one near a power of two: settle it with exact comparisons (scaling
    // by a power of two is exact).
    let mut s = (Q_MAX / largest).log2().floor() as i32;
    while largest * 2.0_f64.powi(s) > Q_MAX {
        s -= 1;
    }
    while largest * 2.0_f64.powi(s + 1) <= Q_MAX {
        s += 1;
    }
    s
}

/// Outputs summed together by [`sums`]: 64 `f64` stay in eight AVX-512 registers while the
/// cells stream past, instead of loading and storing every output for every cell.
const BLOCK: usize = 64;

/// `acc = sum_cell counts[cell] * q[cell]` (rows of `fan_out`), a block of outputs at a time
/// when `fan_out` is a multiple of [`BLOCK`]; compiled for AVX-512 and AVX2 as well as the
/// baseline. Exact, so the result does not depend on the order or the CPU.
#[multiversion::multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
fn sums(q: &[i32], fan_out: usize, counts: &[u8], acc: &mut [f64]) {
    acc.fill(0.0);
    if !fan_out.is_multiple_of(BLOCK) {
        for (row, &c) in q.chunks_exact(fan_out).zip(counts) {
            if c != 0 {
                add_scaled(acc, row, f64::from(c));
            }
        }
        return;
    }
    for (b, out) in acc.chunks_exact_mut(BLOCK).enumerate() {
        let mut block = [0.0_f64; BLOCK];
        for (row, &c) in q.chunks_exact(fan_out).zip(counts) {
            if c != 0 {
                add_scaled(&mut block, &row[b * BLOCK..(b + 1) * BLOCK], f64::from(c));
            }
        }
        out.copy_from_slice(&block);
    }
}

/// `acc[j] += delta * row[j]`, compiled for AVX-512 and AVX2 as well as the baseline. Every
/// value is an integer below `2^53`, so the result is exact on all of them.
#[multiversion::multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
fn add_row(acc: &mut [f64], row: &[i32], delta: f64) {
    add_scaled(acc, row, delta);
}

/// The one loop behind [`add_row`] and [`sums`], inlined into each compiled version so that it
/// vectorises with that version's instructions.
#[inline(always)]
fn add_scaled(acc: &mut [f64], row: &[i32], delta: f64) {
    for (a, &q) in acc.iter_mut().zip(row) {
        *a += delta * f64::from(q);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_puts_the_largest_weight_just_under_two_to_the_thirty() {
        for largest in [1e-30, 0.013, 0.5, 1.0, 3.0, 1e20] {
            let s = scale_exponent(largest);
            let q = largest * 2.0_f64.powi(s);
            assert!(q <= Q_MAX && q * 2.0 > Q_MAX, "{largest}: s = {s}, q = {q}");
        }
        assert_eq!(scale_exponent(0.0), 0);
    }

    #[test]
    fn counts_are_read_only_from_multiples_of_a_64th() {
        let mut counts = [0; MAX_INPUTS];
        let mut x = [0.0_f32; MAX_INPUTS];
        x[3] = 1.0;
        x[7] = 5.0 / 64.0;
        assert!(cell_counts(&x, &mut counts));
        assert_eq!((counts[3], counts[7], counts[0]), (64, 5, 0));
        for bad in [0.1, -1.0 / 64.0, 65.0 / 64.0, f32::NAN, f32::INFINITY] {
            x[5] = bad;
            assert!(!cell_counts(&x, &mut counts), "{bad}");
        }
    }

    #[test]
    fn changed_cells_give_the_same_sums_as_from_scratch() {
        let (fan_in, fan_out) = (MAX_INPUTS, 8);
        let w: Vec<f32> = (0..fan_in * fan_out)
            .map(|i| ((i * 7919) % 2003) as f32 / 1000.0 - 1.0)
            .collect();
        let layer = CellLayer::new(&w, &[0.25; 8]);
        let mut counts = [0u8; MAX_INPUTS];
        let mut kept = vec![0.0; fan_out];
        let mut fresh = vec![0.0; fan_out];
        for step in 0..50_usize {
            let cell = (step * 131) % MAX_INPUTS;
            let new = ((step * 37) % 65) as u8;
            layer.add_cell(&mut kept, cell, i32::from(new) - i32::from(counts[cell]));
            counts[cell] = new;
            layer.sums(&counts, &mut fresh);
            assert_eq!(kept, fresh);
        }
    }
}
