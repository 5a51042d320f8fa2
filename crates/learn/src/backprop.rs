//! One training step of the MLP, written by hand: forward pass, SmoothL1 gradient, backward
//! pass and the AdamW update, on the panel layout of [`crate::panels`].
//!
//! Why not burn's autodiff, which trained evtac before: the paper's sweep is about 19,500
//! epochs of 35,000 samples, and at batch 32 burn spent 0.9 ms a step (1.0 s an epoch) on dense
//! matrix products over inputs that are mostly zero (the pooled, thresholded representations)
//! plus per-operation dispatch and tensor allocation. No crate multiplies a sparse batch by a
//! dense weight and fuses the optimiser into the gradient the way this needs; here:
//!
//! - the first layer's forward pass visits only each sample's non-zero features, or, when most
//!   features are non-zero (dynamic and combined representations), reads each weight row once
//!   for four samples ([`crate::panels::GROUPED_DENSITY`]);
//! - its weight gradient is built row by row from the batch's non-zeros (a column-major index
//!   built once per step) and handed straight to AdamW, so the 900 x 256 gradient is never
//!   stored and rows no sample reached take the zero-gradient update; a dense batch's is
//!   formed four input rows at a time from its dense rows instead ([`crate::gradient_tile`],
//!   on x86-64);
//! - the other layers skip the zeros of the ReLU outputs forward and backward.
//!
//! The arithmetic is PyTorch's up to rounding (the order of additions, fused multiply-adds,
//! AdamW's refined estimates: [`crate::adamw`]); tested against burn's autodiff gradients
//! below, against PyTorch's losses step by step in `tests/pytorch.rs` and against whole
//! PyTorch runs in `tests/converges.rs`. It is deterministic: a given binary on a given CPU
//! takes the same path for the same batch and gives the same bits (x86-64 CPUs without
//! AVX-512F round AdamW's step differently, and other architectures a dense batch's gradient).

use crate::adamw::{self, AdamW, StepScalars};
use crate::model::{
    Architecture, LAYER_SIZES, LAYERS, LayerParameters, MAX_INPUTS, OUTPUTS, Parameters,
};
use crate::panels::{self, BLOCK, Dense, GROUP};

const H1: usize = LAYER_SIZES[1];

// Late fusion's branches are whole panels of the first layer, so a block of units is in one
// branch (see `first_layer_rows`).
const _: () = assert!(crate::architecture::BRANCH.is_multiple_of(BLOCK));

/// The weights being trained, in the panel layout.
#[derive(Debug, Clone)]
pub(crate) struct Network {
    /// Which network (input count; late fusion's first layer is block-diagonal).
    pub architecture: Architecture,
    /// The four layers, input first.
    pub layers: [Dense; LAYERS],
}

impl Network {
    /// The network of `params` (PyTorch layout; validated by the caller).
    pub fn new(params: &Parameters) -> Self {
        let sizes = params.architecture.layer_sizes();
        Self {
            architecture: params.architecture,
            layers: std::array::from_fn(|i| {
                let p = &params.layers[i];
                Dense::from_pytorch(&p.weight, &p.bias, sizes[i], sizes[i + 1])
            }),
        }
    }

    /// Features per sample.
    pub fn inputs(&self) -> usize {
        self.layers[0].fan_in
    }

    /// The weights in PyTorch layout.
    pub fn parameters(&self) -> Parameters {
        Parameters {
            architecture: self.architecture,
            layers: self
                .layers
                .iter()
                .map(|l| {
                    let (weight, bias) = l.to_pytorch();
                    LayerParameters { weight, bias }
                })
                .collect(),
        }
    }

    /// (pitch, roll) for one sample, one layer at a time: the reference [`Network::predict`]
    /// is tested against.
    #[cfg(test)]
    pub fn predict_one(&self, x: &[f32]) -> [f32; OUTPUTS] {
        let mut h1 = [0.0_f32; H1];
        self.layers[0].forward(x, &mut h1, true);
        panels::after_first_layer(&self.layers, &h1)
    }

    /// (pitch, roll) for every row of `x` (n x inputs, flat): one sample at a time's bits,
    /// the first layer computed for [`GROUP`] samples at a time
    /// ([`panels::relu_forward_batch`]: validation's forward pass, 7,500 samples an epoch at
    /// the paper's scale).
    pub fn predict(&self, x: &[f32]) -> Vec<[f32; OUTPUTS]> {
        let inputs = self.inputs();
        let mut out = Vec::with_capacity(x.len() / inputs);
        let mut h1 = [0.0_f32; GROUP * H1];
        // The last group may be short: `relu_forward_batch` takes its rows one at a time.
        for group in x.chunks(GROUP * inputs) {
            let h1 = &mut h1[..group.len() / inputs * H1];
            panels::relu_forward_batch(&self.layers[0], group, h1);
            for h1 in h1.chunks_exact(H1) {
                let h1 = h1.try_into().expect("H1 wide");
                out.push(panels::after_first_layer(&self.layers, h1));
            }
        }
        out
    }
}

/// The buffers of a step, kept between steps so that training allocates nothing per step.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    /// Non-zero features of each sample: `row_start[s]..row_start[s + 1]` into `index`/`value`.
    row_start: Vec<usize>,
    index: Vec<u16>,
    value: Vec<f32>,
    /// The same non-zeros by feature: `col_start[i]..col_start[i + 1]` into `col_sample` and
    /// `col_value`, samples ascending.
    col_start: Vec<usize>,
    col_sample: Vec<u16>,
    col_value: Vec<f32>,
    /// Activations (`h[k]` is layer `k`'s output, after ReLU but for the last), `n x width`.
    h: [Vec<f32>; LAYERS],
    /// Gradients at each layer's output, `n x width`.
    d: [Vec<f32>; LAYERS],
    /// Weight and bias gradients of layers 1 to 3 (layer 0's weight gradient is never stored).
    grads: Vec<Dense>,
    /// Layer 0's bias gradient.
    bias0: Vec<f32>,
}

/// SmoothL1 with threshold `beta`: the loss of one difference `e`, and PyTorch's gradient
/// (`smooth_l1_backward`) scaled by `norm` (1 / the number of elements, for the mean).
#[inline]
fn smooth_l1(e: f32, beta: f32, norm: f32) -> (f32, f32) {
    let loss = if e.abs() < beta {
        0.5 * e * e / beta
    } else {
        e.abs() - 0.5 * beta
    };
    let grad = if e <= -beta {
        -norm
    } else if e >= beta {
        norm
    } else {
        norm * e / beta
    };
    (loss, grad)
}

impl Scratch {
    /// Indexes the non-zeros of the batch `x` (`n x width`) by sample and by feature.
    fn index_batch(&mut self, x: &[f32], n: usize, width: usize) {
        // Branch-free compaction: every value is written, the cursor advances past non-zeros
        // only (a branch per value mispredicts on these sparse rows). Local slices keep the
        // buffers' pointers in registers (through `self` they are reloaded on every write).
        self.index.resize(x.len(), 0);
        self.value.resize(x.len(), 0.0);
        self.row_start.clear();
        self.row_start.push(0);
        let mut counts = [0_usize; MAX_INPUTS];
        let counts = &mut counts[..width];
        let mut len = 0;
        {
            let (index, value) = (&mut self.index[..], &mut self.value[..]);
            for row in x.chunks_exact(width) {
                let (index, value) = (&mut index[len..len + width], &mut value[len..len + width]);
                let mut k = 0;
                for (i, (&v, count)) in row.iter().zip(counts.iter_mut()).enumerate() {
                    let nonzero = usize::from(v != 0.0);
                    // `width <= MAX_INPUTS` (7200) fits in u16; `k <= i < width`.
                    index[k] = i as u16;
                    value[k] = v;
                    *count += nonzero;
                    k += nonzero;
                }
                len += k;
                self.row_start.push(len);
            }
        }
        self.index.truncate(len);
        self.value.truncate(len);
        // The same entries by feature: a counting sort, samples stay ascending.
        self.col_start.clear();
        self.col_start.push(0);
        let mut next = [0_usize; MAX_INPUTS];
        let mut start = 0;
        for (next, &c) in next.iter_mut().zip(counts.iter()) {
            *next = start;
            start += c;
            self.col_start.push(start);
        }
        self.col_sample.resize(len, 0);
        self.col_value.resize(len, 0.0);
        let (col_sample, col_value) = (&mut self.col_sample[..], &mut self.col_value[..]);
        for s in 0..n {
            let entries = self.row_start[s]..self.row_start[s + 1];
            for (&i, &v) in self.index[entries.clone()].iter().zip(&self.value[entries]) {
                let slot = &mut next[usize::from(i)];
                // Batches are at most `MAX_BATCH` samples (checked by the caller).
                col_sample[*slot] = s as u16;
                col_value[*slot] = v;
                *slot += 1;
            }
        }
    }
}

/// The most samples one step takes (sample numbers are stored as u16).
pub(crate) const MAX_BATCH: usize = u16::MAX as usize;

/// One AdamW step of `net` on the batch `x` (`n x inputs`), `y` (`n x 2`) with SmoothL1 threshold
/// `beta`; returns the batch's mean loss before the update. Sizes are checked by the caller.
pub(crate) fn step(
    net: &mut Network,
    optimizer: &mut AdamW,
    scratch: &mut Scratch,
    x: &[f32],
    y: &[f32],
    beta: f32,
) -> f32 {
    let n = y.len() / OUTPUTS;
    let inputs = net.inputs();
    debug_assert!(n <= MAX_BATCH && x.len() == n * inputs);
    let dense = panels::dense_enough(x);
    // A dense batch's first-layer gradient comes from its dense rows (`gradient_tile`); the
    // per-sample and per-feature indexes of its non-zeros are for sparse batches.
    let tiled_gradient = dense && tiled_gradient_runs(inputs);
    if !tiled_gradient {
        scratch.index_batch(x, n, inputs);
    }
    for k in 0..LAYERS {
        scratch.h[k].resize(n * LAYER_SIZES[k + 1], 0.0);
        scratch.d[k].resize(n * LAYER_SIZES[k + 1], 0.0);
    }
    let [l0, l1, l2, l3] = &net.layers;

    // Forward.
    let [h1, h2, h3, out] = &mut scratch.h;
    // Each block of the first layer from its inputs only (late fusion: a branch per frame).
    let blocks = net.architecture.first_layer_blocks();
    if dense {
        for block in &blocks {
            panels::grouped_forward(&l0.weights, &l0.bias, (x, n), h1, block.clone(), true);
        }
    } else {
        for (s, h) in h1.chunks_exact_mut(H1).enumerate() {
            let nz = scratch.row_start[s]..scratch.row_start[s + 1];
            let (index, value) = (&scratch.index[nz.clone()], &scratch.value[nz]);
            for (units, block_inputs) in &blocks {
                // The sample's entries in the block's inputs (`index` is ascending).
                let from = index.partition_point(|&i| usize::from(i) < block_inputs.start);
                let to = index.partition_point(|&i| usize::from(i) < block_inputs.end);
                let entries = (&index[from..to], &value[from..to]);
                let (w, b) = (&l0.weights, &l0.bias);
                panels::sparse_forward(w, b, inputs, entries, h, units.clone(), true);
            }
        }
    }
    // Layers 2 and 3 four samples at a time where the CPU allows (the same bits), the output
    // layer sample by sample.
    for (a, b) in h1.chunks_exact(H1).zip(h2.chunks_exact_mut(l1.fan_out)) {
        l1.forward(a, b, true);
    }
    for (a, b) in h2
        .chunks_exact(l1.fan_out)
        .zip(h3.chunks_exact_mut(l2.fan_out))
    {
        l2.forward(a, b, true);
    }
    for (c, o) in h3
        .chunks_exact(l2.fan_out)
        .zip(out.chunks_exact_mut(OUTPUTS))
    {
        l3.forward(c, o, false);
    }

    // Loss and its gradient at the output.
    let norm = 1.0 / (n * OUTPUTS) as f32;
    let mut loss = 0.0_f32;
    for ((d, &p), &t) in scratch.d[3].iter_mut().zip(out.iter()).zip(y) {
        let (l, g) = smooth_l1(p - t, beta, norm);
        loss += l;
        *d = g;
    }

    // Backward through layers 3, 2 and 1, sample by sample.
    if scratch.grads.len() != 3 {
        scratch.grads = vec![l1.zeros_like(), l2.zeros_like(), l3.zeros_like()];
    }
    for g in &mut scratch.grads {
        g.weights.fill(0.0);
        g.bias.fill(0.0);
    }
    scratch.bias0.clear();
    scratch.bias0.resize(H1, 0.0);
    let [d1, d2, d3, d4] = &mut scratch.d;
    let [g1, g2, g3] = &mut scratch.grads[..] else {
        unreachable!("three gradient layers were made above")
    };
    for s in 0..n {
        let (w1, w2, w3) = (l1.fan_out, l2.fan_out, l3.fan_out);
        let (a, b, c) = (
            &h1[s * H1..][..H1],
            &h2[s * w1..][..w1],
            &h3[s * w2..][..w2],
        );
        let (e1, e2, e3, e4) = (
            &mut d1[s * H1..][..H1],
            &mut d2[s * w1..][..w1],
            &mut d3[s * w2..][..w2],
            &d4[s * w3..][..w3],
        );
        panels::add_outer(&mut g3.weights, c, e4);
        panels::add_to(&mut g3.bias, e4);
        panels::input_grad(&l3.weights, w3, e4, c, e3);
        panels::add_outer(&mut g2.weights, b, e3);
        panels::add_to(&mut g2.bias, e3);
        panels::input_grad(&l2.weights, w2, e3, b, e2);
        panels::add_outer(&mut g1.weights, a, e2);
        panels::add_to(&mut g1.bias, e2);
        panels::input_grad(&l1.weights, w1, e2, a, e1);
        panels::add_to(&mut scratch.bias0, e1);
    }

    // The update: layers 1 to 3 from their gradients, layer 0 fused with its gradient.
    let s = optimizer.begin_step();
    for (k, g) in scratch.grads.iter().enumerate() {
        let layer = &mut net.layers[k + 1];
        optimizer.update(&s, 2 * (k + 1), &mut layer.weights, &g.weights);
        optimizer.update(&s, 2 * (k + 1) + 1, &mut layer.bias, &g.bias);
    }
    let gradient = if tiled_gradient {
        Gradient::Dense(x)
    } else {
        Gradient::Columns(Columns {
            start: &scratch.col_start,
            sample: &scratch.col_sample,
            value: &scratch.col_value,
        })
    };
    first_layer_update(net, optimizer, &s, gradient, d1, &scratch.bias0);
    loss * norm
}

/// Whether a dense batch of `inputs` features takes [`crate::gradient_tile`] (x86-64, and whole
/// tiles of input rows).
fn tiled_gradient_runs(inputs: usize) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        inputs.is_multiple_of(crate::gradient_tile::ROWS)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = inputs;
        false
    }
}

/// What the first layer's weight gradient is formed from.
enum Gradient<'a> {
    /// The batch's non-zero features by feature (sparse batches).
    Columns(Columns<'a>),
    /// The batch's dense rows (`n x inputs`), on [`crate::gradient_tile`].
    Dense(&'a [f32]),
}

/// The batch's non-zero features by feature (see [`Scratch`]).
struct Columns<'a> {
    start: &'a [usize],
    sample: &'a [u16],
    value: &'a [f32],
}

/// AdamW on the first layer: each row's gradient (`sum over samples of x[s, i] * d1[s, :]`,
/// samples in order) is formed a block at a time in registers and applied at once.
fn first_layer_update(
    net: &mut Network,
    optimizer: &mut AdamW,
    s: &StepScalars,
    gradient: Gradient,
    d1: &[f32],
    bias_grad: &[f32],
) {
    let architecture = net.architecture;
    let layer = &mut net.layers[0];
    let (m, v) = optimizer.moments(0, layer.weights.len());
    let rows = FirstLayer {
        fan_in: layer.fan_in,
        architecture,
    };
    match gradient {
        Gradient::Columns(columns) => {
            first_layer_rows(s, &columns, d1, rows, &mut layer.weights, m, v)
        }
        #[cfg(target_arch = "x86_64")]
        Gradient::Dense(x) => first_layer_tiles(s, x, d1, rows, &mut layer.weights, m, v),
        #[cfg(not(target_arch = "x86_64"))]
        Gradient::Dense(_) => unreachable!("the tiled gradient runs on x86-64 only"),
    }
    optimizer.update(s, 1, &mut layer.bias, bias_grad);
}

/// [`first_layer_rows`] for a dense batch `x` (`n x fan_in`): the gradient of four input rows
/// of a block at a time on [`crate::gradient_tile`], then their update. The caller has checked
/// [`tiled_gradient_runs`].
#[cfg(target_arch = "x86_64")]
fn first_layer_tiles(
    s: &StepScalars,
    x: &[f32],
    d1: &[f32],
    layer: FirstLayer,
    weights: &mut [f32],
    m: &mut [f32],
    v: &mut [f32],
) {
    use crate::gradient_tile::{ROWS, gradient};
    let fan_in = layer.fan_in;
    let mut g = [0.0_f32; ROWS * BLOCK];
    for b in 0..weights.len() / (fan_in * BLOCK) {
        for first in (0..fan_in).step_by(ROWS) {
            // A tile's rows are all in one frame (`fan_in` and the branches' 900 inputs are
            // multiples of ROWS): a cross-branch tile is skipped whole, as in the column path.
            if !layer.architecture.connects(b * BLOCK, first) {
                continue;
            }
            gradient((x, fan_in), first, (&d1[b * BLOCK..], H1), &mut g);
            let rows = (b * fan_in + first) * BLOCK..(b * fan_in + first + ROWS) * BLOCK;
            let (p, m, v) = (
                &mut weights[rows.clone()],
                &mut m[rows.clone()],
                &mut v[rows],
            );
            adamw::update(s, p, &g, m, v);
        }
    }
}

/// The first layer's shape as [`first_layer_rows`] needs it.
#[derive(Clone, Copy)]
struct FirstLayer {
    fan_in: usize,
    architecture: Architecture,
}

/// The loop of [`first_layer_update`] over the weight's rows, compiled for AVX-512 and AVX2
/// besides the baseline (the gradient's sums have the same bits on each: see
/// [`crate::panels`]); each row's update is [`adamw::update`].
///
/// Late fusion's cross-branch rows (a block of one branch's units and an input of the other
/// frame) are skipped: they get no gradient, and AdamW with a zero gradient and zero moments
/// would keep their zero weights exactly zero anyway (decay of 0 is 0, the moments stay 0, the
/// step is `0 / eps`), so skipping them changes no bit and halves late fusion's update.
#[multiversion::multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
fn first_layer_rows(
    s: &StepScalars,
    columns: &Columns,
    d1: &[f32],
    layer: FirstLayer,
    weights: &mut [f32],
    m: &mut [f32],
    v: &mut [f32],
) {
    let rows = weights
        .chunks_exact_mut(BLOCK)
        .zip(m.chunks_exact_mut(BLOCK))
        .zip(v.chunks_exact_mut(BLOCK));
    let fan_in = layer.fan_in;
    // Chunk `c` of the panel layout is block `c / fan_in`, input row `c % fan_in`.
    for (c, ((p, m), v)) in rows.enumerate() {
        let (b, i) = (c / fan_in, c % fan_in);
        let mut g = [0.0_f32; BLOCK];
        // A block's units are all in one branch (`BRANCH` is a multiple of `BLOCK`). A
        // cross-branch row is zero with zero moments: AdamW would leave it so, skip it.
        if !layer.architecture.connects(b * BLOCK, i) {
            continue;
        }
        for k in columns.start[i]..columns.start[i + 1] {
            let (sample, xi) = (usize::from(columns.sample[k]), columns.value[k]);
            let d = &d1[sample * H1 + b * BLOCK..][..BLOCK];
            for (g, &dd) in g.iter_mut().zip(d) {
                *g += xi * dd;
            }
        }
        // A row no sample reached has a zero gradient: the same update as any other.
        adamw::update(s, p, &g, m, v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::adamw::AdamWConfig;
    use crate::burn_reference::Mlp;
    use burn::nn::loss::{HuberLossConfig, Reduction};
    use burn::tensor::{Device, Tensor, TensorData};

    /// A batch of `n` samples of `width` features, a fraction `density` of them non-zero,
    /// labels within +-20 degrees.
    fn batch(n: usize, width: usize, seed: u64, density: f32) -> (Vec<f32>, Vec<f32>) {
        let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let x = (0..n * width)
            .map(|_| if next() >= density { 0.0 } else { next() })
            .collect();
        let y = (0..n * OUTPUTS).map(|_| 40.0 * next() - 20.0).collect();
        (x, y)
    }

    /// burn's autodiff gradients of the mean SmoothL1 loss (beta 1), in PyTorch layout.
    fn burn_gradients(params: &Parameters, x: &[f32], y: &[f32]) -> (f32, Parameters) {
        let device = Device::flex().autodiff();
        let mlp = Mlp::from_parameters(params, &device).expect("fits");
        let n = y.len() / OUTPUTS;
        let sizes = params.architecture.layer_sizes();
        let x = Tensor::<2>::from_data(TensorData::new(x.to_vec(), [n, sizes[0]]), &device);
        let y = Tensor::<2>::from_data(TensorData::new(y.to_vec(), [n, OUTPUTS]), &device);
        let loss = HuberLossConfig::new(1.0)
            .init()
            .forward(mlp.forward(x), y, Reduction::Mean);
        let grads = loss.backward();
        let value = crate::burn_reference::to_vec(&loss).expect("loss")[0];
        let layers = mlp
            .layers
            .iter()
            .zip(sizes.windows(2))
            .map(|(l, w)| {
                let gw = l.weight.val().grad(&grads).expect("weight grad");
                let gb = l.bias.as_ref().and_then(|b| b.val().grad(&grads));
                let gw = gw.into_data().try_to_vec::<f32>().expect("f32");
                let gb = gb
                    .expect("bias grad")
                    .into_data()
                    .try_to_vec::<f32>()
                    .expect("f32");
                LayerParameters {
                    weight: crate::model::transpose(&gw, w[0], w[1]),
                    bias: gb,
                }
            })
            .collect();
        let architecture = params.architecture;
        (
            value,
            Parameters {
                architecture,
                layers,
            },
        )
    }

    /// The hand-written gradients equal burn's autodiff ones. The first layer's gradient is
    /// never stored, so it is read from the step itself: with beta1 = beta2 = 0, no decay and
    /// a huge eps, AdamW's first step is `p -= lr * g / (|g| + eps)`, i.e. `(lr / eps) * g` to
    /// a relative 1e-5 while |g| < 1e-2 * eps.
    ///
    /// Late fusion as burn sees it is a dense network with zero cross-branch weights, whose
    /// gradients are not zero: the step must leave those weights at exactly zero and match
    /// burn on every other weight (the branches' and the head's gradients are the same in the
    /// two views).
    #[test]
    fn gradients_match_burn_autodiff() {
        // Dense batches take the grouped first layer, sparse ones the per-sample one.
        let (mlp, stacked, late) = (Architecture::Mlp, Architecture::Stacked, Architecture::Late);
        for (architecture, n, seed, density) in [
            (mlp, 32, 1, 0.75),
            (mlp, 7, 2, 0.5),
            (mlp, 1, 3, 0.6),
            (mlp, 32, 4, 0.1),
            (mlp, 5, 5, 0.2),
            (stacked, 32, 6, 0.75),
            (stacked, 9, 7, 0.15),
            (late, 32, 8, 0.75),
            (late, 9, 9, 0.15),
        ] {
            let params = Parameters::init_for(architecture, seed);
            let (x, y) = batch(n, architecture.inputs(), seed, density);
            let (burn_loss, want) = burn_gradients(&params, &x, &y);
            let cfg = AdamWConfig {
                learning_rate: 1.0,
                weight_decay: 0.0,
                beta1: 0.0,
                beta2: 0.0,
                epsilon: 1e3,
            };
            let mut net = Network::new(&params);
            let mut optimizer = AdamW::new(cfg);
            let mut scratch = Scratch::default();
            let loss = step(&mut net, &mut optimizer, &mut scratch, &x, &y, 1.0);
            assert!(
                (loss - burn_loss).abs() <= 1e-5 * burn_loss.abs(),
                "{loss} {burn_loss}"
            );
            let after = net.parameters();
            let scale = cfg.epsilon / cfg.learning_rate;
            for (k, ((b, a), w)) in params
                .layers
                .iter()
                .zip(&after.layers)
                .zip(&want.layers)
                .enumerate()
            {
                for (name, before, after, want) in [
                    ("weight", &b.weight, &a.weight, &w.weight),
                    ("bias", &b.bias, &a.bias, &w.bias),
                ] {
                    let peak = want.iter().fold(0.0_f64, |m, g| m.max(f64::from(g.abs())));
                    let inputs = architecture.inputs();
                    for (j, ((&p0, &p1), &g)) in before.iter().zip(after).zip(want).enumerate() {
                        if k == 0
                            && name == "weight"
                            && !architecture.connects(j / inputs, j % inputs)
                        {
                            assert_eq!(p1.to_bits(), 0, "cross-branch weight [{j}] moved");
                            continue;
                        }
                        let got = (f64::from(p0) - f64::from(p1)) * scale;
                        // Summation order differs from burn's (1e-3 of the layer's largest
                        // gradient), and the new weight is rounded to f32 (one ulp, scaled).
                        let ulp = f64::from(p0.abs().max(p1.abs())) * f64::from(f32::EPSILON);
                        let tolerance = 1e-3 * peak + ulp * scale;
                        assert!(
                            (got - f64::from(g)).abs() <= tolerance,
                            "n {n}, layer {k} {name} [{j}]: {got} vs burn {g} (peak {peak})"
                        );
                    }
                }
            }
        }
    }

    /// Validation's batch prediction (the first layer four samples at a time) gives
    /// `predict_one`'s bits, sample by sample, for every architecture and for a batch that
    /// does not fill its last group; rows of zeros and rows with zeros where the other samples
    /// of their group have none are among them.
    #[test]
    fn batch_prediction_has_predict_ones_bits() {
        let (mlp, stacked, late) = (Architecture::Mlp, Architecture::Stacked, Architecture::Late);
        for (architecture, n, seed, density) in [
            (mlp, 37, 11, 0.75),
            (mlp, 8, 12, 0.1),
            (stacked, 9, 13, 0.5),
            (late, 10, 14, 0.75),
            (late, 6, 15, 0.1),
        ] {
            let params = Parameters::init_for(architecture, seed);
            let net = Network::new(&params);
            let inputs = architecture.inputs();
            let (mut x, _) = batch(n, inputs, seed, density);
            x[..inputs].fill(0.0);
            let got: Vec<[u32; OUTPUTS]> = net
                .predict(&x)
                .iter()
                .map(|p| p.map(f32::to_bits))
                .collect();
            let want: Vec<[u32; OUTPUTS]> = x
                .chunks_exact(inputs)
                .map(|x| net.predict_one(x).map(f32::to_bits))
                .collect();
            assert_eq!(got, want, "{architecture:?}, {n} samples");
        }
    }
}
