//! The weight layout that inference and training share, and the kernels that work on it.
//!
//! A layer's weight is stored transposed, `[in, out]`, so that a layer is a sequence of
//! `y += x[i] * W[i, :]` row updates: they vectorise without horizontal sums and skip zero
//! inputs outright (the masked, binarised representations are mostly zeros, and so are the
//! ReLU outputs). When `out` is a multiple of [`BLOCK`] the rows are regrouped into panels
//! `[out / BLOCK][in][BLOCK]`, so the 64 outputs of a block stay in registers while one
//! contiguous panel streams past.
//!
//! Every kernel adds its products in a fixed order (input order, then sample order) with
//! separate multiplies and adds (no FMA; training's grouped first layer is the one exception,
//! fused on every target). The kernels are compiled for AVX-512 and AVX2 besides the baseline
//! and picked at run time, and all three give bit-identical results: a model evaluated on one
//! x86-64 machine gives the same outputs as on any other. (Training adds AdamW, which rounds
//! differently where the CPU lacks AVX-512F: a model is the same bytes on every CPU of one
//! kind, so a cluster whose nodes differ in it trains different last bits. See
//! [`crate::adamw`].) Where a kernel serves several samples at once (the grouped forward, the
//! input gradient) its AVX-512 form is written by hand in [`crate::grouped_tile`], with the
//! same operations in the same order, because LLVM keeps the portable form's register tile in
//! memory; the portable form sweeps a block a chunk of outputs at a time for the same reason.

use std::ops::Range;

use crate::model::{LAYER_SIZES, LAYERS, MAX_INPUTS, OUTPUTS};

/// Above this fraction of non-zero features in a batch, the first layer's forward pass reads
/// each weight row once for a group of samples ([`grouped_forward`]) instead of once
/// per sample over its non-zeros ([`sparse_forward`]). Measured (`benches/training.rs`):
/// at 75 % non-zero (dynamic, combined) a step takes 274 us grouped against 372 us, at 14 %
/// (static) 214 us against 184 us. The choice depends on the batch only, so it is reproducible.
pub(crate) const GROUPED_DENSITY: f64 = 0.35;

/// Width of the first hidden layer.
const H1: usize = LAYER_SIZES[1];

/// Outputs accumulated together: 64 floats, 4 AVX-512 or 8 AVX2 registers.
pub(crate) const BLOCK: usize = 64;

/// Lanes of the partial sums in [`input_grad`]'s dot products (one AVX-512 register).
const LANES: usize = 16;

/// One linear layer in the panel layout (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Dense {
    /// `[in, out]`, regrouped into `[out / BLOCK][in][BLOCK]` panels when `out` allows.
    pub weights: Vec<f32>,
    /// `[out]`.
    pub bias: Vec<f32>,
    /// Inputs.
    pub fan_in: usize,
    /// Outputs.
    pub fan_out: usize,
}

impl Dense {
    /// A layer from PyTorch's `nn.Linear` layout (`weight` `[out, in]` row-major).
    pub fn from_pytorch(weight: &[f32], bias: &[f32], fan_in: usize, fan_out: usize) -> Self {
        let mut weights = vec![0.0; fan_in * fan_out];
        for o in 0..fan_out {
            for i in 0..fan_in {
                weights[position(fan_in, fan_out, i, o)] = weight[o * fan_in + i];
            }
        }
        Self {
            weights,
            bias: bias.to_vec(),
            fan_in,
            fan_out,
        }
    }

    /// The weight back in PyTorch's layout (`[out, in]` row-major), and the bias.
    pub fn to_pytorch(&self) -> (Vec<f32>, Vec<f32>) {
        let (fan_in, fan_out) = (self.fan_in, self.fan_out);
        let mut weight = vec![0.0; fan_in * fan_out];
        for o in 0..fan_out {
            for i in 0..fan_in {
                weight[o * fan_in + i] = self.weights[position(fan_in, fan_out, i, o)];
            }
        }
        (weight, self.bias.clone())
    }

    /// A layer of the same shape holding zeros (a gradient).
    pub fn zeros_like(&self) -> Self {
        Self {
            weights: vec![0.0; self.weights.len()],
            bias: vec![0.0; self.bias.len()],
            ..*self
        }
    }

    /// `out = relu?(bias + x W)`, zero inputs skipped.
    #[inline]
    pub fn forward(&self, x: &[f32], out: &mut [f32], relu: bool) {
        dense_forward(&self.weights, &self.bias, x, out, relu);
    }
}

/// The layers after the first of the 900-256-128-64-2 network, from the first layer's output:
/// (pitch, roll). Shared by inference and training's validation pass.
pub(crate) fn after_first_layer(layers: &[Dense; LAYERS], h1: &[f32; H1]) -> [f32; OUTPUTS] {
    let mut h2 = [0.0_f32; LAYER_SIZES[2]];
    let mut h3 = [0.0_f32; LAYER_SIZES[3]];
    let mut out = [0.0_f32; OUTPUTS];
    let [_, l1, l2, l3] = layers;
    l1.forward(h1, &mut h2, true);
    l2.forward(&h2, &mut h3, true);
    l3.forward(&h3, &mut out, false);
    out
}

/// Where weight `(input i, output o)` lives in the layout of a `fan_in x fan_out` layer.
#[inline]
pub(crate) fn position(fan_in: usize, fan_out: usize, i: usize, o: usize) -> usize {
    if fan_out.is_multiple_of(BLOCK) {
        ((o / BLOCK) * fan_in + i) * BLOCK + o % BLOCK
    } else {
        i * fan_out + o
    }
}

/// `out = relu?(bias + x W)` with `W` in the panel layout; inputs equal to zero are skipped
/// (exactly: they would add `0 * w = 0`).
#[multiversion::multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
pub(crate) fn dense_forward(weights: &[f32], bias: &[f32], x: &[f32], out: &mut [f32], relu: bool) {
    let width = out.len();
    out.copy_from_slice(bias);
    if width.is_multiple_of(BLOCK) {
        let panels = weights.chunks_exact(x.len() * BLOCK);
        for (out, panel) in out.chunks_exact_mut(BLOCK).zip(panels) {
            let mut acc = [0.0_f32; BLOCK];
            acc.copy_from_slice(out);
            for (&xi, row) in x.iter().zip(panel.chunks_exact(BLOCK)) {
                if xi != 0.0 {
                    for (a, &w) in acc.iter_mut().zip(row) {
                        *a += xi * w;
                    }
                }
            }
            out.copy_from_slice(&acc);
        }
    } else {
        for (&xi, row) in x.iter().zip(weights.chunks_exact(width)) {
            if xi != 0.0 {
                for (o, &w) in out.iter_mut().zip(row) {
                    *o += xi * w;
                }
            }
        }
    }
    if relu {
        for o in out.iter_mut() {
            *o = o.max(0.0);
        }
    }
}

/// [`dense_forward`] with ReLU of every row of `x` (`n x fan_in`) into `out` (`n x fan_out`),
/// the same bits as one row at a time. A paneled layer takes [`GROUP`] rows at a time without
/// fused multiply-adds if they are dense enough (as training's forward pass decides,
/// [`GROUPED_DENSITY`]), on [`crate::grouped_tile`] where the CPU has AVX-512F and on
/// [`grouped_forward_portable`] elsewhere: it reads each weight row once for the group (one
/// sample at a time, the 900 x 256 weights stream from beyond L2 for every sample), and where
/// one sample has a zero that another has not it adds `0 * w`, which can only turn a `-0.0` sum
/// into `+0.0`, a difference the ReLU erases. Other rows of a paneled layer go one at a time
/// through their non-zeros ([`sparse_relu_forward`]).
pub(crate) fn relu_forward_batch(layer: &Dense, x: &[f32], out: &mut [f32]) {
    let (fan_in, fan_out) = (layer.fan_in, layer.fan_out);
    // Rows that are not grouped: through their non-zeros where the layer is paneled and its
    // inputs fit [`sparse_relu_forward`]'s buffers.
    let through_non_zeros = fan_out.is_multiple_of(BLOCK) && fan_in <= MAX_INPUTS;
    let groups = x
        .chunks(GROUP * fan_in)
        .zip(out.chunks_mut(GROUP * fan_out));
    for (x, out) in groups {
        if x.len() == GROUP * fan_in && fan_out.is_multiple_of(BLOCK) && dense_enough(x) {
            #[cfg(target_arch = "x86_64")]
            if crate::grouped_tile::available() {
                let layer_weights = (&layer.weights[..], &layer.bias[..]);
                tile_blocks::<false>(layer_weights, x, out, 0..fan_out, 0..fan_in);
                relu_units(out, fan_out, 0..fan_out);
                continue;
            }
            let (weights, bias) = (&layer.weights[..], &layer.bias[..]);
            let shape = (0..fan_out, 0..fan_in);
            let sums = Sums::MultiplyThenAdd;
            grouped_forward_portable(weights, bias, (x, GROUP), out, shape, (true, sums));
            continue;
        }
        for (x, out) in x.chunks_exact(fan_in).zip(out.chunks_exact_mut(fan_out)) {
            if through_non_zeros {
                sparse_relu_forward(layer, x, out);
            } else {
                layer.forward(x, out, true);
            }
        }
    }
}

/// [`dense_forward`] with ReLU of one sample of a paneled layer, through its non-zero entries
/// ([`sparse_forward`]: the same products in the same order, so the same bits). Why: on sparse
/// features [`dense_forward`] tests every input of every block, and at 14 % non-zero (the
/// static representation) the branch mispredicts about one input in seven; gathered once, the
/// non-zeros serve all blocks. This is validation's path for sparse groups, 13 % of a sparse
/// training run on an AVX2-only CPU (AMD Zen 3). At most [`MAX_INPUTS`] inputs (two pooled
/// frames), gathered on the stack.
fn sparse_relu_forward(layer: &Dense, x: &[f32], out: &mut [f32]) {
    let mut index = [0_u16; MAX_INPUTS];
    let mut value = [0.0_f32; MAX_INPUTS];
    // Branch-free compaction: every value is written, the cursor advances past non-zeros only.
    let mut n = 0;
    for (i, &v) in x.iter().enumerate() {
        // `fan_in <= MAX_INPUTS` (7200) fits in u16; `n <= i`.
        index[n] = i as u16;
        value[n] = v;
        n += usize::from(v != 0.0);
    }
    let entries = (&index[..n], &value[..n]);
    let (weights, bias, fan_in) = (&layer.weights[..], &layer.bias[..], layer.fan_in);
    sparse_forward(weights, bias, fan_in, entries, out, 0..layer.fan_out, true);
}

/// [`dense_forward`] of a paneled layer on an input given as its non-zero entries (`index`
/// ascending, `value`): the same products in the same order, so the same bits, without
/// visiting the zeros. Only the outputs `units` (whole blocks) are computed, from the entries
/// given (late fusion passes each branch's units with its frame's entries; see
/// [`crate::architecture`]).
#[multiversion::multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
pub(crate) fn sparse_forward(
    weights: &[f32],
    bias: &[f32],
    fan_in: usize,
    (index, value): (&[u16], &[f32]),
    out: &mut [f32],
    units: Range<usize>,
    relu: bool,
) {
    debug_assert!(out.len().is_multiple_of(BLOCK) && units.start.is_multiple_of(BLOCK));
    let panels = weights
        .chunks_exact(fan_in * BLOCK)
        .skip(units.start / BLOCK);
    let outs = out[units.clone()].chunks_exact_mut(BLOCK);
    for ((out, panel), bias) in outs
        .zip(panels)
        .zip(bias[units.clone()].chunks_exact(BLOCK))
    {
        let mut acc = [0.0_f32; BLOCK];
        acc.copy_from_slice(bias);
        for (&i, &xi) in index.iter().zip(value) {
            let row = &panel[usize::from(i) * BLOCK..][..BLOCK];
            for (a, &w) in acc.iter_mut().zip(row) {
                *a += xi * w;
            }
        }
        out.copy_from_slice(&acc);
    }
    if relu {
        for o in out[units].iter_mut() {
            *o = o.max(0.0);
        }
    }
}

/// Samples that share one pass over a paneled layer's weight rows in [`grouped_forward`].
pub(crate) const GROUP: usize = 4;

/// `out = relu?(bias + x W)` for a batch of samples (`x` their dense rows, `rows` of them),
/// [`GROUP`] samples at a time: each weight row is read once for a group rather than once per
/// sample, which is what bounds the first layer when most inputs are non-zero. Rows that every
/// sample of a group has at zero are skipped; a zero of one sample where another is not adds
/// `0 * w`, a zero. Fused multiply-adds, correctly rounded on every target (`f32::mul_add`).
/// Only the outputs `units` (whole blocks) are computed, from the inputs `inputs` (late
/// fusion's branches: see [`crate::architecture`]).
///
/// Whole groups run on [`crate::grouped_tile`] where the CPU has AVX-512F (LLVM spills the
/// portable kernel's accumulators to the stack; the tile keeps them in registers, same bits);
/// elsewhere the whole batch goes to [`grouped_forward_portable`], which takes every group
/// through one [`SPAN`] of inputs before the next.
pub(crate) fn grouped_forward(
    weights: &[f32],
    bias: &[f32],
    (x, rows): (&[f32], usize),
    out: &mut [f32],
    (units, inputs): (Range<usize>, Range<usize>),
    relu: bool,
) {
    if rows == 0 {
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if crate::grouped_tile::available() {
        let (fan_in, fan_out) = (x.len() / rows, bias.len());
        let groups = x
            .chunks(GROUP * fan_in)
            .zip(out.chunks_mut(GROUP * fan_out));
        for (x, out) in groups {
            let group = x.len() / fan_in;
            if group == GROUP {
                tile_blocks::<true>((weights, bias), x, out, units.clone(), inputs.clone());
                if relu {
                    relu_units(out, fan_out, units.clone());
                }
            } else {
                let shape = (units.clone(), inputs.clone());
                let how = (relu, Sums::Fused);
                grouped_forward_portable(weights, bias, (x, group), out, shape, how);
            }
        }
        return;
    }
    let shape = (units, inputs);
    grouped_forward_portable(weights, bias, (x, rows), out, shape, (relu, Sums::Fused));
}

/// The outputs `units` (whole blocks) of one whole group of samples (`x`, `GROUP x fan_in`)
/// from the inputs `inputs`, on [`crate::grouped_tile::tile`], into `out` (rows `fan_out` wide,
/// before any ReLU). The caller has checked [`crate::grouped_tile::available`].
#[cfg(target_arch = "x86_64")]
fn tile_blocks<const FUSED: bool>(
    (weights, bias): (&[f32], &[f32]),
    x: &[f32],
    out: &mut [f32],
    units: Range<usize>,
    inputs: Range<usize>,
) {
    let (fan_in, fan_out) = (x.len() / GROUP, bias.len());
    for b in units.start / BLOCK..units.end / BLOCK {
        let panel = &weights[b * fan_in * BLOCK..][..fan_in * BLOCK];
        let block_bias = &bias[b * BLOCK..][..BLOCK];
        // SAFETY: the caller checked that the CPU has AVX-512F.
        let tile =
            unsafe { crate::grouped_tile::tile::<FUSED>(panel, block_bias, x, inputs.clone()) };
        for (k, sample) in tile.iter().enumerate() {
            out[k * fan_out + b * BLOCK..][..BLOCK].copy_from_slice(sample);
        }
    }
}

/// Outputs of a block that [`grouped_forward_portable`] accumulates at once: the group's
/// tile of `GROUP x CHUNK` sums is 8 AVX2 (or 4 AVX-512) registers. A whole block's tile
/// (`GROUP x BLOCK`, 32 AVX2 registers) does not fit the 16 that AVX2 has, and LLVM then keeps
/// it on the stack, loading and storing every sum at every input: perf on the paper's static
/// tuning on an AVX2-only CPU (AMD Zen 3) put 35 % of a dense run there.
const CHUNK: usize = 16;

/// Inputs that [`grouped_forward_portable`] takes every group of a batch through before the
/// next: their weight rows (`SPAN x 256` floats of the first layer, 256 KB) stay in a 512 KB L2
/// while the batch's groups pass, where the whole 900 x 256 layer (921 KB) streamed from L3
/// once per group. Each group's values of the span are gathered once (on the stack), with the
/// test of whether every sample has an input at zero, rather than once per chunk of outputs.
const SPAN: usize = 256;

/// How [`grouped_forward_portable`] adds each product to its sum: the two forward passes round
/// differently, and each must keep its own bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Sums {
    /// One fused multiply-add per product (training's forward pass, as [`grouped_forward`]).
    Fused,
    /// The product rounded, then added (validation's, as [`dense_forward`] and `predict_one`).
    MultiplyThenAdd,
}

/// [`grouped_forward`] in portable code (any number of samples, any CPU), each product added to
/// its sum as `sums` says. Each output's sum is the same operations in the same input order as
/// [`crate::grouped_tile::tile`]'s, so the same bits: the inputs are taken [`SPAN`] at a time,
/// every group of [`GROUP`] samples through a span before the next span, the outputs a
/// [`CHUNK`] at a time (so that the sums stay in registers), and a chunk's sums wait in `out`
/// between spans.
#[multiversion::multiversion(targets("x86_64+avx512f+fma", "x86_64+avx2+fma"))]
pub(crate) fn grouped_forward_portable(
    weights: &[f32],
    bias: &[f32],
    (x, rows): (&[f32], usize),
    out: &mut [f32],
    (units, inputs): (Range<usize>, Range<usize>),
    (relu, sums): (bool, Sums),
) {
    if rows == 0 {
        return;
    }
    let fan_out = bias.len();
    let fan_in = x.len() / rows;
    for sample in out[..rows * fan_out].chunks_exact_mut(fan_out) {
        sample[units.clone()].copy_from_slice(&bias[units.clone()]);
    }
    let mut active = [0_usize; SPAN];
    let mut values = [[0.0_f32; GROUP]; SPAN];
    for start in inputs.clone().step_by(SPAN) {
        for first_row in (0..rows).step_by(GROUP) {
            let group = (rows - first_row).min(GROUP);
            let x = &x[first_row * fan_in..][..group * fan_in];
            let out = &mut out[first_row * fan_out..][..group * fan_out];
            // The span's inputs that some sample of the group has non-zero, with their values.
            let mut n = 0;
            for i in start..(start + SPAN).min(inputs.end) {
                let mut xs = [0.0_f32; GROUP];
                for (k, v) in xs.iter_mut().enumerate().take(group) {
                    *v = x[k * fan_in + i];
                }
                if xs.iter().any(|&v| v != 0.0) {
                    (active[n], values[n]) = (i, xs);
                    n += 1;
                }
            }
            for b in units.start / BLOCK..units.end / BLOCK {
                let panel = &weights[b * fan_in * BLOCK..][..fan_in * BLOCK];
                for first in (b * BLOCK..(b + 1) * BLOCK).step_by(CHUNK) {
                    let within = first - b * BLOCK;
                    let mut acc = [[0.0_f32; CHUNK]; GROUP];
                    for (k, a) in acc.iter_mut().enumerate().take(group) {
                        a.copy_from_slice(&out[k * fan_out + first..][..CHUNK]);
                    }
                    for (&i, xs) in active[..n].iter().zip(&values[..n]) {
                        let row = &panel[i * BLOCK + within..][..CHUNK];
                        for (a, &xk) in acc.iter_mut().zip(xs) {
                            match sums {
                                Sums::Fused => {
                                    for (a, &w) in a.iter_mut().zip(row) {
                                        *a = xk.mul_add(w, *a);
                                    }
                                }
                                Sums::MultiplyThenAdd => {
                                    for (a, &w) in a.iter_mut().zip(row) {
                                        *a += xk * w;
                                    }
                                }
                            }
                        }
                    }
                    for (k, a) in acc.iter().enumerate().take(group) {
                        out[k * fan_out + first..][..CHUNK].copy_from_slice(a);
                    }
                }
            }
        }
    }
    if relu {
        relu_units(&mut out[..rows * fan_out], fan_out, units);
    }
}

/// Whether more than [`GROUPED_DENSITY`] of `x` is non-zero.
pub(crate) fn dense_enough(x: &[f32]) -> bool {
    let non_zero = x.iter().filter(|&&v| v != 0.0).count();
    non_zero as f64 > GROUPED_DENSITY * x.len() as f64
}

/// ReLU on the outputs `units` of each sample's row (`fan_out` wide) of `out`.
fn relu_units(out: &mut [f32], fan_out: usize, units: Range<usize>) {
    for sample in out.chunks_exact_mut(fan_out) {
        for o in sample[units.clone()].iter_mut() {
            *o = o.max(0.0);
        }
    }
}

/// The gradient at a ReLU layer's input: `dx[i] = (W[i, :] . d)` where the layer's input `h[i]`
/// (a ReLU output) is positive, else 0 (PyTorch's `threshold_backward`: no gradient where the
/// ReLU was off, including exactly at 0).
///
/// Each dot product keeps [`LANES`] partial sums, adds them output by output in order, and
/// reduces them in one fixed tree, so every target gives the same bits.
#[multiversion::multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
pub(crate) fn input_grad(weights: &[f32], fan_out: usize, d: &[f32], h: &[f32], dx: &mut [f32]) {
    let fan_in = h.len();
    if fan_out.is_multiple_of(BLOCK) {
        for (i, (&hi, dxi)) in h.iter().zip(dx.iter_mut()).enumerate() {
            if hi <= 0.0 {
                *dxi = 0.0;
                continue;
            }
            let mut acc = [0.0_f32; LANES];
            for (b, db) in d.chunks_exact(BLOCK).enumerate() {
                let row = &weights[(b * fan_in + i) * BLOCK..][..BLOCK];
                for (w, dd) in row.chunks_exact(LANES).zip(db.chunks_exact(LANES)) {
                    for l in 0..LANES {
                        acc[l] += w[l] * dd[l];
                    }
                }
            }
            *dxi = reduce(acc);
        }
    } else {
        for ((&hi, dxi), row) in h
            .iter()
            .zip(dx.iter_mut())
            .zip(weights.chunks_exact(fan_out))
        {
            *dxi = if hi > 0.0 {
                row.iter().zip(d).fold(0.0, |s, (&w, &dd)| s + w * dd)
            } else {
                0.0
            };
        }
    }
}

/// The sum of the lanes in a fixed pairwise order.
#[inline(always)]
fn reduce(mut acc: [f32; LANES]) -> f32 {
    let mut width = LANES;
    while width > 1 {
        width /= 2;
        for l in 0..width {
            acc[l] += acc[l + width];
        }
    }
    acc[0]
}

/// `grad_w += x (outer) d` for one sample: input `x` of the layer (zeros skipped), `d` the
/// gradient at its output; `grad_w` in the panel layout of a `x.len() x d.len()` layer.
#[multiversion::multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
pub(crate) fn add_outer(grad_w: &mut [f32], x: &[f32], d: &[f32]) {
    let (fan_in, fan_out) = (x.len(), d.len());
    if fan_out.is_multiple_of(BLOCK) {
        for (panel, db) in grad_w
            .chunks_exact_mut(fan_in * BLOCK)
            .zip(d.chunks_exact(BLOCK))
        {
            for (&xi, row) in x.iter().zip(panel.chunks_exact_mut(BLOCK)) {
                if xi != 0.0 {
                    for (g, &dd) in row.iter_mut().zip(db) {
                        *g += xi * dd;
                    }
                }
            }
        }
    } else {
        for (&xi, row) in x.iter().zip(grad_w.chunks_exact_mut(fan_out)) {
            if xi != 0.0 {
                for (g, &dd) in row.iter_mut().zip(d) {
                    *g += xi * dd;
                }
            }
        }
    }
}

/// `sum += d` element by element (a bias gradient over samples).
#[inline]
pub(crate) fn add_to(sum: &mut [f32], d: &[f32]) {
    for (s, &v) in sum.iter_mut().zip(d) {
        *s += v;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pytorch_layout_round_trips_through_the_panels() {
        for (fan_in, fan_out) in [(900, 256), (64, 2), (3, 64)] {
            let weight: Vec<f32> = (0..fan_in * fan_out).map(|k| k as f32).collect();
            let bias: Vec<f32> = (0..fan_out).map(|k| -(k as f32)).collect();
            let layer = Dense::from_pytorch(&weight, &bias, fan_in, fan_out);
            assert_eq!(layer.to_pytorch(), (weight.clone(), bias));
            // Row i of the transposed weight is input i's contributions, output by output.
            assert_eq!(layer.weights[position(fan_in, fan_out, 1, 0)], weight[1]);
        }
    }

    /// The grouped kernel, swept a chunk of outputs at a time, is each output's fused
    /// multiply-adds (or multiplies then adds) in input order (inputs every sample of the
    /// sample's group has at zero skipped), bit for bit, for every batch size up to three groups
    /// and for late fusion's input and unit ranges, over inputs that take several spans.
    #[test]
    fn the_grouped_kernel_is_the_sums_in_input_order() {
        let (fan_in, fan_out) = (2 * SPAN + 88, 128);
        // Its own xorshift rather than `grouped_tile::tests::floats`: that module is x86-64
        // only, and this kernel runs on every target.
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        };
        let weight: Vec<f32> = (0..fan_in * fan_out).map(|_| next()).collect();
        let bias: Vec<f32> = (0..fan_out).map(|_| next()).collect();
        let layer = Dense::from_pytorch(&weight, &bias, fan_in, fan_out);
        // Inputs 3 and 300 are zero in every sample, input 5 in all but the last of the first
        // group, input 7 in every sample after the first group.
        let x: Vec<f32> = (0..3 * GROUP * fan_in)
            .map(|k| match (k / fan_in, k % fan_in) {
                (_, 3 | 300) => 0.0,
                (s, 5) if s + 1 < GROUP => 0.0,
                (s, 7) if s >= GROUP => 0.0,
                _ => next(),
            })
            .collect();
        let ranges = [(0..fan_out, 0..fan_in), (64..128, 200..530)];
        let modes = [Sums::Fused, Sums::MultiplyThenAdd];
        for (rows, sums) in (1..=3 * GROUP).flat_map(|rows| modes.map(|sums| (rows, sums))) {
            for (units, inputs) in ranges.clone() {
                let mut got = vec![f32::NAN; rows * fan_out];
                let shape = (units.clone(), inputs.clone());
                let x = &x[..rows * fan_in];
                grouped_forward_portable(
                    &layer.weights,
                    &layer.bias,
                    (x, rows),
                    &mut got,
                    shape,
                    (false, sums),
                );
                for s in 0..rows {
                    let group = s / GROUP * GROUP..(s / GROUP * GROUP + GROUP).min(rows);
                    for o in units.clone() {
                        let mut want = bias[o];
                        for i in inputs.clone() {
                            if group.clone().all(|t| x[t * fan_in + i] == 0.0) {
                                continue;
                            }
                            let (xi, w) = (x[s * fan_in + i], weight[o * fan_in + i]);
                            want = match sums {
                                Sums::Fused => xi.mul_add(w, want),
                                Sums::MultiplyThenAdd => want + xi * w,
                            };
                        }
                        let got = got[s * fan_out + o];
                        assert_eq!(
                            got.to_bits(),
                            want.to_bits(),
                            "rows {rows}, {sums:?}, sample {s}, output {o}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn kernels_match_the_plain_formulas() {
        let (fan_in, fan_out) = (5, 128);
        let weight: Vec<f32> = (0..fan_in * fan_out)
            .map(|k| ((k * 37) % 101) as f32 / 50.0 - 1.0)
            .collect();
        let bias: Vec<f32> = (0..fan_out).map(|k| (k % 7) as f32 / 10.0).collect();
        let layer = Dense::from_pytorch(&weight, &bias, fan_in, fan_out);
        let x = [0.5, 0.0, -1.25, 0.0, 2.0];
        let mut out = vec![0.0; fan_out];
        layer.forward(&x, &mut out, false);
        let mut sparse = vec![0.0; fan_out];
        sparse_forward(
            &layer.weights,
            &layer.bias,
            fan_in,
            (&[0, 2, 4], &[0.5, -1.25, 2.0]),
            &mut sparse,
            0..fan_out,
            false,
        );
        assert_eq!(out, sparse);
        // Two samples through the grouped kernel: the same values to rounding (FMA).
        let second = [0.0, 1.0, 0.0, 0.0, -0.5];
        let mut grouped = vec![0.0; 2 * fan_out];
        let rows = [x, second].concat();
        grouped_forward(
            &layer.weights,
            &layer.bias,
            (&rows, 2),
            &mut grouped,
            (0..fan_out, 0..fan_in),
            false,
        );
        for (k, xs) in [x, second].iter().enumerate() {
            let mut want = vec![0.0; fan_out];
            layer.forward(xs, &mut want, false);
            for (g, w) in grouped[k * fan_out..][..fan_out].iter().zip(&want) {
                assert!(
                    (g - w).abs() <= 1e-6 * w.abs().max(1.0),
                    "sample {k}: {g} vs {w}"
                );
            }
        }
        for o in 0..fan_out {
            let want: f64 = f64::from(bias[o])
                + (0..fan_in)
                    .map(|i| f64::from(x[i]) * f64::from(weight[o * fan_in + i]))
                    .sum::<f64>();
            assert!((f64::from(out[o]) - want).abs() < 1e-5);
        }
        let d: Vec<f32> = (0..fan_out).map(|k| (k as f32 - 60.0) / 64.0).collect();
        let h = [1.0, 0.0, 2.0, -0.0, 3.0];
        let mut dx = [9.0; 5];
        input_grad(&layer.weights, fan_out, &d, &h, &mut dx);
        for i in 0..fan_in {
            let want: f64 = if h[i] > 0.0 {
                (0..fan_out)
                    .map(|o| f64::from(weight[o * fan_in + i]) * f64::from(d[o]))
                    .sum()
            } else {
                0.0
            };
            assert!(
                (f64::from(dx[i]) - want).abs() < 1e-5,
                "{i}: {} {want}",
                dx[i]
            );
        }
        let mut grad = layer.zeros_like();
        add_outer(&mut grad.weights, &x, &d);
        let (gw, _) = grad.to_pytorch();
        for o in 0..fan_out {
            for i in 0..fan_in {
                assert_eq!(gw[o * fan_in + i], x[i] * d[o]);
            }
        }
    }
}
