//! The regressor: the paper's 900 -> 256 -> 128 -> 64 -> 2 multi-layer perceptron with ReLU (or
//! one of the two-frame networks of [`crate::architecture`]), as plain host weights in PyTorch's
//! layout ([`Parameters`]).
//!
//! [`Parameters`] is the common currency: initialisation draws it from a seeded
//! [`ChaCha8Rng`], the bundle saves and loads it, the trainer updates it in place and the
//! [`crate::Predictor`] runs it. Its layout is PyTorch's `nn.Linear`: layer `i` has
//! `weight` `[out, in]` row-major and `bias` `[out]`, so a PyTorch
//! `nn.Sequential(Linear, ReLU, Linear, ReLU, Linear, ReLU, Linear)` whose linear layers are
//! named `layers.0` .. `layers.3` loads the saved tensors unchanged (late fusion's layout in
//! PyTorch is in `bundle.rs`).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub use crate::architecture::{Architecture, INPUTS, LAYERS, MAX_INPUTS, OUTPUTS};
use crate::architecture::{BRANCH, HIDDEN};

/// The paper's layer widths from input to output ([`Architecture::Mlp`]'s): 900, its three
/// hidden layers of 256, 128 and 64, and 2.
pub const LAYER_SIZES: [usize; LAYERS + 1] = [INPUTS, HIDDEN[0], HIDDEN[1], HIDDEN[2], OUTPUTS];
/// The hidden layers' activation, by name (for reports; the paper states none): every hidden
/// layer applies it, the output layer is linear. [`Parameters::forward_f64`], the training
/// passes and the [`crate::Predictor`] all apply `max(0, x)`.
pub const ACTIVATION: &str = "ReLU";

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A layer's weight or bias does not have the size the architecture requires.
    #[error("layer {layer} {tensor} has {got} values, the {architecture} network needs {expected}")]
    Shape {
        /// The network, e.g. `900-256-128-64-2`.
        architecture: String,
        /// Layer index (0 = input layer).
        layer: usize,
        /// `"weight"` or `"bias"`.
        tensor: &'static str,
        /// Number of values found.
        got: usize,
        /// Number of values required.
        expected: usize,
    },
    /// A weight or bias is NaN or infinite.
    #[error("layer {layer} {tensor} holds a non-finite value at index {index}")]
    NonFinite {
        /// Layer index.
        layer: usize,
        /// `"weight"` or `"bias"`.
        tensor: &'static str,
        /// Flat index of the first offending value.
        index: usize,
    },
    /// A late-fusion network has a weight between one branch's units and the other frame.
    #[error(
        "layer 0 weight [{unit}, {input}] is {value} but late fusion connects unit {unit} only \
         to the {frame} frame's inputs (a cross-branch weight must be 0)"
    )]
    CrossBranch {
        /// The hidden unit.
        unit: usize,
        /// The input.
        input: usize,
        /// The weight found.
        value: f32,
        /// `static` or `dynamic`: the frame the unit's branch reads.
        frame: &'static str,
    },
}

/// One linear layer's weights in PyTorch `nn.Linear` layout.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerParameters {
    /// Weight, `[out, in]` row-major.
    pub weight: Vec<f32>,
    /// Bias, `[out]`.
    pub bias: Vec<f32>,
}

/// All weights of the network in PyTorch layout (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Parameters {
    /// The network they belong to (sizes, and late fusion's zero cross-branch weights).
    pub architecture: Architecture,
    /// The four linear layers, input first.
    pub layers: Vec<LayerParameters>,
}

impl Parameters {
    /// The paper's MLP with PyTorch's default initial weights from `seed`
    /// ([`Parameters::init_for`] with [`Architecture::Mlp`]).
    pub fn init(seed: u64) -> Self {
        Self::init_for(Architecture::Mlp, seed)
    }

    /// PyTorch's default `nn.Linear` initialisation drawn from `ChaCha8Rng::seed_from_u64(seed)`:
    /// weights and biases uniform in `[-1/sqrt(fan_in), 1/sqrt(fan_in))` (Kaiming-uniform with
    /// `a = sqrt(5)` reduces to that bound). Values are drawn layer by layer, the weight
    /// row-major before the bias, so the same seed gives the same bytes on every machine. Late
    /// fusion draws its layers in PyTorch module order: the static branch (`900 x 128`, fan-in
    /// 900), the dynamic branch, then the head; the branches are placed in the block-diagonal
    /// first layer, whose cross-branch weights are zero.
    pub fn init_for(architecture: Architecture, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut draw = |fan_in: usize, fan_out: usize| -> LayerParameters {
            let bound = 1.0 / (fan_in as f32).sqrt();
            let mut values = |n: usize| -> Vec<f32> {
                (0..n).map(|_| rng.random_range(-bound..bound)).collect()
            };
            let weight = values(fan_out * fan_in);
            let bias = values(fan_out);
            LayerParameters { weight, bias }
        };
        let sizes = architecture.layer_sizes();
        let mut layers = Vec::with_capacity(LAYERS);
        if architecture == Architecture::Late {
            let branches = [draw(INPUTS, BRANCH), draw(INPUTS, BRANCH)];
            layers.push(join_branches(&branches));
        } else {
            layers.push(draw(sizes[0], sizes[1]));
        }
        for w in sizes[1..].windows(2) {
            layers.push(draw(w[0], w[1]));
        }
        Self {
            architecture,
            layers,
        }
    }

    /// Late fusion's two branches (static, dynamic), each `[BRANCH, 900]`, cut out of the
    /// block-diagonal first layer; `None` for the other architectures.
    pub fn branches(&self) -> Option<[LayerParameters; 2]> {
        if self.architecture != Architecture::Late {
            return None;
        }
        let first = self.layers.first()?;
        Some(std::array::from_fn(|b| {
            let units = b * BRANCH..(b + 1) * BRANCH;
            let inputs = b * INPUTS..(b + 1) * INPUTS;
            LayerParameters {
                weight: units
                    .clone()
                    .flat_map(|u| {
                        first.weight[u * 2 * INPUTS..][inputs.clone()]
                            .iter()
                            .copied()
                    })
                    .collect(),
                bias: first.bias[units].to_vec(),
            }
        }))
    }

    /// Checks the sizes against the architecture, that every value is finite and that late
    /// fusion's cross-branch weights are zero.
    pub fn validate(&self) -> Result<(), Error> {
        let sizes = self.architecture.layer_sizes();
        let architecture = self.architecture.describe();
        if self.layers.len() != LAYERS {
            return Err(Error::Shape {
                architecture,
                layer: self.layers.len().min(LAYERS),
                tensor: "weight",
                got: 0,
                expected: sizes[1] * sizes[0],
            });
        }
        for (layer, (p, w)) in self.layers.iter().zip(sizes.windows(2)).enumerate() {
            for (tensor, values, expected) in
                [("weight", &p.weight, w[0] * w[1]), ("bias", &p.bias, w[1])]
            {
                if values.len() != expected {
                    return Err(Error::Shape {
                        architecture,
                        layer,
                        tensor,
                        got: values.len(),
                        expected,
                    });
                }
                if let Some(index) = values.iter().position(|v| !v.is_finite()) {
                    return Err(Error::NonFinite {
                        layer,
                        tensor,
                        index,
                    });
                }
            }
        }
        let inputs = sizes[0];
        for (k, &value) in self.layers[0].weight.iter().enumerate() {
            let (unit, input) = (k / inputs, k % inputs);
            if value != 0.0 && !self.architecture.connects(unit, input) {
                let frame = if unit < BRANCH { "static" } else { "dynamic" };
                return Err(Error::CrossBranch {
                    unit,
                    input,
                    value,
                    frame,
                });
            }
        }
        Ok(())
    }

    /// Reference forward pass in f64 on one sample (slow; for tests and checks).
    pub fn forward_f64(&self, x: &[f32]) -> [f64; OUTPUTS] {
        let mut h: Vec<f64> = x.iter().map(|&v| f64::from(v)).collect();
        let sizes = self.architecture.layer_sizes();
        for (i, (p, w)) in self.layers.iter().zip(sizes.windows(2)).enumerate() {
            let (fan_in, fan_out) = (w[0], w[1]);
            h = (0..fan_out)
                .map(|o| {
                    let row = &p.weight[o * fan_in..(o + 1) * fan_in];
                    let z = row
                        .iter()
                        .zip(&h)
                        .map(|(&a, &b)| f64::from(a) * b)
                        .sum::<f64>()
                        + f64::from(p.bias[o]);
                    if i + 1 < LAYERS { z.max(0.0) } else { z }
                })
                .collect();
        }
        [h[0], h[1]]
    }
}

/// Late fusion's block-diagonal first layer (`[256, 1800]`) from its two branches (static,
/// dynamic; each `[BRANCH, 900]`): every cross-branch weight zero.
pub(crate) fn join_branches(branches: &[LayerParameters; 2]) -> LayerParameters {
    let mut weight = vec![0.0; HIDDEN[0] * 2 * INPUTS];
    let mut bias = Vec::with_capacity(HIDDEN[0]);
    for (b, branch) in branches.iter().enumerate() {
        for (u, row) in branch.weight.chunks_exact(INPUTS).enumerate() {
            weight[(b * BRANCH + u) * 2 * INPUTS + b * INPUTS..][..INPUTS].copy_from_slice(row);
        }
        bias.extend_from_slice(&branch.bias);
    }
    LayerParameters { weight, bias }
}

/// Row-major `[rows, cols]` to row-major `[cols, rows]`.
pub(crate) fn transpose(values: &[f32], rows: usize, cols: usize) -> Vec<f32> {
    let mut out = vec![0.0; values.len()];
    for r in 0..rows {
        for c in 0..cols {
            out[c * rows + r] = values[r * cols + c];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn init_bounds_follow_pytorch() {
        let p = Parameters::init(3);
        p.validate().expect("valid");
        for (layer, w) in p.layers.iter().zip(LAYER_SIZES.windows(2)) {
            let bound = 1.0 / (w[0] as f32).sqrt();
            assert!(layer.weight.iter().all(|v| v.abs() <= bound));
            assert!(layer.bias.iter().all(|v| v.abs() <= bound));
            // A uniform draw spans most of its range.
            let max = layer.weight.iter().fold(0.0_f32, |m, v| m.max(v.abs()));
            assert!(max > 0.9 * bound, "max {max} bound {bound}");
        }
        assert_eq!(p, Parameters::init(3));
        assert_ne!(p, Parameters::init(4));
    }

    #[test]
    fn late_fusion_is_two_branches_and_a_head() {
        let p = Parameters::init_for(Architecture::Late, 5);
        p.validate().expect("valid");
        let [s, d] = p.branches().expect("late");
        // The branches are drawn as two nn.Linear(900, 128), in module order.
        let bound = 1.0 / 30.0;
        assert!(s.weight.iter().chain(&d.weight).all(|v| v.abs() <= bound));
        assert_ne!(s.weight, d.weight);
        assert_eq!(join_branches(&[s.clone(), d.clone()]), p.layers[0]);
        // The network is the branches' ReLU outputs, concatenated, through the head.
        let x: Vec<f32> = (0..2 * INPUTS)
            .map(|i| ((i * 13) % 65) as f32 / 64.0)
            .collect();
        let branch = |b: &LayerParameters, x: &[f32]| -> Vec<f64> {
            (0..BRANCH)
                .map(|u| {
                    let row = &b.weight[u * INPUTS..][..INPUTS];
                    let z: f64 = row
                        .iter()
                        .zip(x)
                        .map(|(&w, &v)| f64::from(w) * f64::from(v))
                        .sum();
                    (z + f64::from(b.bias[u])).max(0.0)
                })
                .collect()
        };
        let mut h = [branch(&s, &x[..INPUTS]), branch(&d, &x[INPUTS..])].concat();
        for (i, layer) in p.layers[1..].iter().enumerate() {
            let fan_in = h.len();
            h = (0..layer.bias.len())
                .map(|o| {
                    let row = &layer.weight[o * fan_in..][..fan_in];
                    let z = row
                        .iter()
                        .zip(&h)
                        .map(|(&w, &v)| f64::from(w) * v)
                        .sum::<f64>()
                        + f64::from(layer.bias[o]);
                    if i < 2 { z.max(0.0) } else { z }
                })
                .collect();
        }
        let got = p.forward_f64(&x);
        for k in 0..OUTPUTS {
            assert!((got[k] - h[k]).abs() < 1e-9, "{got:?} vs {h:?}");
        }
        // A cross-branch weight is refused, naming it.
        let mut bad = p.clone();
        bad.layers[0].weight[3 * 2 * INPUTS + 1000] = 0.5;
        let msg = bad.validate().expect_err("cross-branch").to_string();
        assert!(msg.contains("[3, 1000]") && msg.contains("static"), "{msg}");
        // The stacked network is dense over 1800 inputs, drawn with fan-in 1800.
        let stacked = Parameters::init_for(Architecture::Stacked, 5);
        stacked.validate().expect("valid");
        assert_eq!(stacked.layers[0].weight.len(), 256 * 1800);
        assert!(stacked.branches().is_none());
    }

    #[test]
    fn validate_names_the_broken_layer() {
        let mut p = Parameters::init(0);
        p.layers[2].bias.pop();
        let msg = p.validate().expect_err("short bias").to_string();
        assert!(msg.contains("layer 2 bias has 63 values"), "{msg}");
        let mut p = Parameters::init(0);
        p.layers[1].weight[5] = f32::NAN;
        assert!(matches!(
            p.validate(),
            Err(Error::NonFinite {
                layer: 1,
                index: 5,
                ..
            })
        ));
    }
}
