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
//! The float32 layers use the panel layout and kernels that training uses too
//! (`panels.rs`): zero inputs skipped, compiled for AVX-512 and AVX2 besides the baseline,
//! with identical results on all three.

use crate::cell_layer::{self, CellLayer, CellSums};
use crate::model::{self, Architecture, LAYER_SIZES, MAX_INPUTS, Parameters};
use crate::panels::{self, Dense};

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The weights do not fit the architecture.
    #[error(transparent)]
    Model(#[from] model::Error),
    /// A batch is not a whole number of rows of the network's width.
    #[error("{len} feature values is not a multiple of {width} (one row per sample)")]
    RaggedFeatures {
        /// Number of values given.
        len: usize,
        /// Features per sample the network reads.
        width: usize,
    },
}

/// Width of the first hidden layer.
const H1: usize = LAYER_SIZES[1];

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
    architecture: Architecture,
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
        let sizes = params.architecture.layer_sizes();
        let dense = |i: usize| {
            let p = &params.layers[i];
            Dense::from_pytorch(&p.weight, &p.bias, sizes[i], sizes[i + 1])
        };
        let first = &params.layers[0];
        Ok(Self {
            architecture: params.architecture,
            cells: CellLayer::new(
                &model::transpose(&first.weight, LAYER_SIZES[1], sizes[0]),
                &first.bias,
            ),
            layers: [dense(0), dense(1), dense(2), dense(3)],
        })
    }

    /// The network it runs.
    pub fn architecture(&self) -> Architecture {
        self.architecture
    }

    /// Features per sample: 900, 1800 for the two-frame networks, `C x 900` for `C` channels.
    pub fn inputs(&self) -> usize {
        self.layers[0].fan_in
    }

    /// (pitch, roll) in degrees for one sample of [`Predictor::inputs`] features.
    /// Allocation-free. Pooled features (multiples of 1/64 in `[0, 1]`) go through the exact
    /// first layer (see the module docs), any others through the float32 one.
    ///
    /// # Panics
    ///
    /// When `features.len()` is not [`Predictor::inputs`]: feature vectors come from the
    /// representation code, so a wrong length is a programming error (use
    /// [`Predictor::predict`] for data from files).
    pub fn predict_one(&self, features: &[f32]) -> [f32; 2] {
        let inputs = self.inputs();
        assert_eq!(
            features.len(),
            inputs,
            "predict_one needs {inputs} features"
        );
        let mut h1 = [0.0_f32; H1];
        let mut counts = [0_u8; MAX_INPUTS];
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
        panels::after_first_layer(&self.layers, h1)
    }

    /// (pitch, roll) for the next sample of the stream whose state is `state`: bit for bit
    /// [`Predictor::predict_one`]. Features off the 1/64 grid take the float32 path and leave
    /// `state` as it was.
    ///
    /// # Panics
    /// When `features.len()` is not [`Predictor::inputs`], as [`Predictor::predict_one`].
    pub(crate) fn predict_streaming(&self, state: &mut CellSums, features: &[f32]) -> [f32; 2] {
        let inputs = self.inputs();
        assert_eq!(
            features.len(),
            inputs,
            "StreamingPredictor::predict needs {inputs} features"
        );
        let mut counts = [0_u8; MAX_INPUTS];
        if !cell_layer::cell_counts(features, &mut counts) {
            return self.predict_one(features);
        }
        let mut h1 = [0.0_f32; H1];
        state.update(&self.cells, &counts, &mut h1);
        self.after_first_layer(&h1)
    }

    /// (pitch, roll) for every row of `features` (n x [`Predictor::inputs`], flat).
    pub fn predict(&self, features: &[f32]) -> Result<Vec<[f32; 2]>, Error> {
        let width = self.inputs();
        if !features.len().is_multiple_of(width) {
            return Err(Error::RaggedFeatures {
                len: features.len(),
                width,
            });
        }
        // Rows in a set are mostly consecutive samples of a trial, which differ in few cells:
        // streaming through them gives the same results as one at a time, faster.
        let mut stream = CellSums::new();
        Ok(features
            .chunks_exact(width)
            .map(|row| self.predict_streaming(&mut stream, row))
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{INPUTS, OUTPUTS};

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

    /// The two-frame networks and those over several channels (up to [`MAX_INPUTS`]), on pooled
    /// and on other features, against the f64 reference; late fusion's zero cross-branch
    /// weights take part in neither path's result.
    #[test]
    fn two_frame_networks_match_the_f64_reference() {
        let wide = [
            Architecture::Stacked,
            Architecture::Late,
            Architecture::Channels(5),
            Architecture::Channels(MAX_INPUTS / INPUTS),
        ];
        for architecture in wide {
            let width = architecture.inputs();
            let params = Parameters::init_for(architecture, 12);
            let p = Predictor::new(&params).expect("valid");
            assert_eq!((p.inputs(), p.architecture()), (width, architecture));
            let pooled: Vec<f32> = (0..2 * width)
                .map(|i| ((i * 11) % 65) as f32 / 64.0)
                .collect();
            let off_grid: Vec<f32> = pooled.iter().map(|v| v * 0.9).collect();
            for x in [&pooled, &off_grid] {
                let got = p.predict(x).expect("rows");
                for (row, g) in x.chunks_exact(width).zip(&got) {
                    assert_eq!(*g, p.predict_one(row));
                    let r = params.forward_f64(row);
                    for k in 0..OUTPUTS {
                        assert!((f64::from(g[k]) - r[k]).abs() < 1e-4, "{g:?} vs {r:?}");
                    }
                }
            }
            assert!(matches!(
                p.predict(&pooled[..INPUTS]),
                Err(Error::RaggedFeatures { width: w, .. }) if w == width
            ));
        }
    }
}
