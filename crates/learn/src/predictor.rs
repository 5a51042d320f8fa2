//! Fast CPU inference of a trained MLP, one sample or a batch at a time.
//!
//! The forward pass is written by hand here, from the same weights burn trains, because burn's
//! per-call overhead dominates a single 900-feature sample: creating input tensors, dispatching
//! eight operations and reading the result back allocates on every call and costs tens of
//! microseconds before any arithmetic (measured in `benches/inference.rs`, which times both). The
//! hand-written pass is allocation-free: activations live in fixed-size stack arrays.
//!
//! The first layer has two forms:
//! - on pooled features (every feature a multiple of 1/64 in `[0, 1]`, which is what every
//!   evtac representation produces) it is computed exactly from the cell counts with
//!   fixed-point weights ([`crate::cell_layer`]), so that [`crate::StreamingPredictor`] can
//!   update it from the cells that changed and still give the same bits;
//! - on any other input, in float32 like the other layers.
//!
//! The float32 layers are sequences of `y += x[i] * W[i, :]` row updates over the transposed
//! weight (`[in, out]`), 64 outputs at a time held in registers, which vectorises without
//! horizontal sums and skips zero inputs outright. The weights of each 64-output block are
//! stored together (`[block][in][64]`), so a block streams through one contiguous panel. They
//! are compiled for AVX-512 and AVX2 besides the baseline and dispatched at run time, with
//! identical results on all three. Training stays on burn.

use crate::cell_layer::{self, CellLayer, CellSums};
use crate::model::{self, INPUTS, LAYER_SIZES, OUTPUTS, Parameters};

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The weights do not fit the architecture.
    #[error(transparent)]
    Model(#[from] model::Error),
    /// A batch is not a whole number of 900-value rows.
    #[error("{len} feature values is not a multiple of {INPUTS} (one row per sample)")]
    RaggedFeatures {
        /// Number of values given.
        len: usize,
    },
}

/// Width of the first hidden layer.
const H1: usize = LAYER_SIZES[1];
const H2: usize = LAYER_SIZES[2];
const H3: usize = LAYER_SIZES[3];

/// One layer: its weight transposed to `[in, out]` row-major, then, when `out` is a multiple of
/// [`BLOCK`], regrouped into panels `[out / BLOCK][in][BLOCK]`.
#[derive(Debug, Clone)]
struct Dense {
    weights: Vec<f32>,
    bias: Vec<f32>,
}

/// `[in, out]` to `[out / BLOCK][in][BLOCK]` when `out` is a multiple of [`BLOCK`] (else as is).
fn into_panels(weight_t: Vec<f32>, fan_out: usize) -> Vec<f32> {
    if !fan_out.is_multiple_of(BLOCK) {
        return weight_t;
    }
    let mut panels = Vec::with_capacity(weight_t.len());
    for b in 0..fan_out / BLOCK {
        for row in weight_t.chunks_exact(fan_out) {
            panels.extend_from_slice(&row[b * BLOCK..(b + 1) * BLOCK]);
        }
    }
    panels
}

impl Dense {
    #[inline]
    fn forward(&self, x: &[f32], out: &mut [f32], relu: bool) {
        dense_forward(&self.weights, &self.bias, x, out, relu);
    }
}

/// Outputs accumulated together: 64 floats stay in registers (4 AVX-512 or 8 AVX2 registers)
/// while every input row streams past, instead of loading and storing the whole output row for
/// each input.
const BLOCK: usize = 64;

/// `out = relu?(bias + x W)` with `W` laid out as in [`Dense`], compiled for AVX-512 and AVX2 as
/// well as the baseline and picked at run time.
///
/// Every output is still `bias` plus the products added in input order, with separate
/// multiplies and adds (no FMA), so all versions give bit-identical results: estimates do not
/// depend on the CPU they ran on.
#[multiversion::multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
fn dense_forward(weights: &[f32], bias: &[f32], x: &[f32], out: &mut [f32], relu: bool) {
    let width = out.len();
    out.copy_from_slice(bias);
    if width.is_multiple_of(BLOCK) {
        let panels = weights.chunks_exact(x.len() * BLOCK);
        for (out, panel) in out.chunks_exact_mut(BLOCK).zip(panels) {
            let mut acc = [0.0_f32; BLOCK];
            acc.copy_from_slice(out);
            for (&xi, row) in x.iter().zip(panel.chunks_exact(BLOCK)) {
                // Zero inputs contribute exactly zero (weights are finite, checked on load),
                // and the masked, binarised representations are mostly zeros.
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

/// A trained model ready for inference. Cheap to clone; `Send + Sync`, so one predictor can be
/// shared by reference across threads.
///
/// ```
/// use evtac_learn::{Parameters, Predictor};
/// let predictor = Predictor::new(&Parameters::init(0)).unwrap();
/// let [pitch, roll] = predictor.predict_one(&[0.0; 900]);
/// assert!(pitch.is_finite() && roll.is_finite());
/// ```
#[derive(Debug, Clone)]
pub struct Predictor {
    /// The first layer in fixed point, for pooled features.
    cells: CellLayer,
    layers: [Dense; 4],
}

impl Predictor {
    /// Prepares `params` (PyTorch layout) for inference and flushes subnormals on the calling
    /// thread (call [`crate::flush_denormals`] yourself on other inference threads).
    pub fn new(params: &Parameters) -> Result<Self, Error> {
        params.validate()?;
        crate::ftz::flush_denormals();
        let dense = |i: usize| {
            let (fan_in, fan_out) = (LAYER_SIZES[i], LAYER_SIZES[i + 1]);
            Dense {
                weights: into_panels(
                    model::transpose(&params.layers[i].weight, fan_out, fan_in),
                    fan_out,
                ),
                bias: params.layers[i].bias.clone(),
            }
        };
        let first = &params.layers[0];
        Ok(Self {
            cells: CellLayer::new(
                &model::transpose(&first.weight, LAYER_SIZES[1], INPUTS),
                &first.bias,
            ),
            layers: [dense(0), dense(1), dense(2), dense(3)],
        })
    }

    /// (pitch, roll) in degrees for one sample of 900 features. Allocation-free. Pooled
    /// features (multiples of 1/64 in `[0, 1]`) go through the exact first layer (see the
    /// module docs), any others through the float32 one.
    ///
    /// # Panics
    ///
    /// When `features.len() != 900`: feature vectors come from the representation code, so a
    /// wrong length is a programming error (use [`Predictor::predict`] for data from files).
    pub fn predict_one(&self, features: &[f32]) -> [f32; 2] {
        assert_eq!(
            features.len(),
            INPUTS,
            "predict_one needs {INPUTS} features"
        );
        let mut h1 = [0.0_f32; H1];
        let mut counts = [0_u8; INPUTS];
        if cell_layer::cell_counts(features, &mut counts) {
            let mut sums = [0.0_f64; H1];
            self.cells.sums(&counts, &mut sums);
            self.cells.output(&sums, &mut h1);
        } else {
            self.layers[0].forward(features, &mut h1, true);
        }
        self.after_first_layer(&h1)
    }

    /// The layers after the first, from its output.
    fn after_first_layer(&self, h1: &[f32; H1]) -> [f32; 2] {
        let mut h2 = [0.0_f32; H2];
        let mut h3 = [0.0_f32; H3];
        let mut out = [0.0_f32; OUTPUTS];
        let [_, l1, l2, l3] = &self.layers;
        l1.forward(h1, &mut h2, true);
        l2.forward(&h2, &mut h3, true);
        l3.forward(&h3, &mut out, false);
        out
    }

    /// (pitch, roll) for the next sample of the stream whose state is `state`: bit for bit
    /// [`Predictor::predict_one`]. Features off the 1/64 grid take the float32 path and leave
    /// `state` as it was.
    ///
    /// # Panics
    /// When `features.len() != 900`, as [`Predictor::predict_one`].
    pub(crate) fn predict_streaming(&self, state: &mut CellSums, features: &[f32]) -> [f32; 2] {
        assert_eq!(
            features.len(),
            INPUTS,
            "StreamingPredictor::predict needs {INPUTS} features"
        );
        let mut counts = [0_u8; INPUTS];
        if !cell_layer::cell_counts(features, &mut counts) {
            return self.predict_one(features);
        }
        let mut h1 = [0.0_f32; H1];
        state.update(&self.cells, &counts, &mut h1);
        self.after_first_layer(&h1)
    }

    /// (pitch, roll) for every row of `features` (n x 900, flat).
    pub fn predict(&self, features: &[f32]) -> Result<Vec<[f32; 2]>, Error> {
        if !features.len().is_multiple_of(INPUTS) {
            return Err(Error::RaggedFeatures {
                len: features.len(),
            });
        }
        // Rows in a set are mostly consecutive samples of a trial, which differ in few cells:
        // streaming through them gives the same results as one at a time, faster.
        let mut stream = CellSums::new();
        Ok(features
            .chunks_exact(INPUTS)
            .map(|row| self.predict_streaming(&mut stream, row))
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_f64_reference() {
        let params = Parameters::init(11);
        let p = Predictor::new(&params).expect("valid");
        let x: Vec<f32> = (0..3 * INPUTS)
            .map(|i| {
                if i % 3 == 0 {
                    0.0
                } else {
                    ((i * 7) % 13) as f32 / 13.0
                }
            })
            .collect();
        let got = p.predict(&x).expect("rows");
        for (row, g) in x.chunks_exact(INPUTS).zip(&got) {
            let r = params.forward_f64(row);
            for k in 0..OUTPUTS {
                assert!((f64::from(g[k]) - r[k]).abs() < 1e-4, "{g:?} vs {r:?}");
            }
        }
        // Pooled features take the exact first layer.
        let pooled: Vec<f32> = (0..INPUTS).map(|i| ((i * 11) % 65) as f32 / 64.0).collect();
        let (g, r) = (p.predict_one(&pooled), params.forward_f64(&pooled));
        for k in 0..OUTPUTS {
            assert!((f64::from(g[k]) - r[k]).abs() < 1e-4, "{g:?} vs {r:?}");
        }
        assert!(matches!(
            p.predict(&x[1..]),
            Err(Error::RaggedFeatures { .. })
        ));
    }
}
