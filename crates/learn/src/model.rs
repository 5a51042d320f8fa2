//! The regressor: a 900 -> 256 -> 128 -> 64 -> 2 multi-layer perceptron with ReLU, as a burn
//! module ([`Mlp`]) and as plain host weights in PyTorch's layout ([`Parameters`]).
//!
//! [`Parameters`] is the common currency: initialisation draws it from a seeded
//! [`ChaCha8Rng`], the bundle saves and loads it, the trainer uploads it into burn and the
//! [`crate::Predictor`] runs it. Its layout is PyTorch's `nn.Linear`: layer `i` has
//! `weight` `[out, in]` row-major and `bias` `[out]`, so a PyTorch
//! `nn.Sequential(Linear, ReLU, Linear, ReLU, Linear, ReLU, Linear)` whose linear layers are
//! named `layers.0` .. `layers.3` loads the saved tensors unchanged.

use burn::module::{Module, Param};
use burn::nn::{Linear, LinearConfig};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor, TensorData};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Number of input features (a 30 x 30 pooled representation, row-major).
pub const INPUTS: usize = 900;
/// Number of outputs: (pitch, roll) in degrees.
pub const OUTPUTS: usize = 2;
/// Layer widths from input to output: the paper's three hidden layers of 256, 128 and 64.
pub const LAYER_SIZES: [usize; 5] = [INPUTS, 256, 128, 64, OUTPUTS];
/// Number of linear layers.
pub const LAYERS: usize = LAYER_SIZES.len() - 1;
/// The hidden layers' activation, by name (for reports; the paper states none): every hidden
/// layer applies it, the output layer is linear. [`Mlp::forward`], [`Parameters::forward_f64`]
/// and the [`crate::Predictor`] all apply `max(0, x)`.
pub const ACTIVATION: &str = "ReLU";

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A layer's weight or bias does not have the size the architecture requires.
    #[error(
        "layer {layer} {tensor} has {got} values, the 900-256-128-64-2 architecture needs {expected}"
    )]
    Shape {
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
    /// burn returned tensor data of an unexpected type.
    #[error("reading a tensor back from burn failed: {0}")]
    Readback(String),
}

/// One linear layer's weights in PyTorch `nn.Linear` layout.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerParameters {
    /// Weight, `[out, in]` row-major.
    pub weight: Vec<f32>,
    /// Bias, `[out]`.
    pub bias: Vec<f32>,
}

/// All weights of the MLP in PyTorch layout (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Parameters {
    /// The four linear layers, input first.
    pub layers: Vec<LayerParameters>,
}

impl Parameters {
    /// PyTorch's default `nn.Linear` initialisation drawn from `ChaCha8Rng::seed_from_u64(seed)`:
    /// weights and biases uniform in `[-1/sqrt(fan_in), 1/sqrt(fan_in))` (Kaiming-uniform with
    /// `a = sqrt(5)` reduces to that bound). Values are drawn layer by layer, the weight
    /// row-major before the bias, so the same seed gives the same bytes on every machine.
    pub fn init(seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let layers = LAYER_SIZES
            .windows(2)
            .map(|w| {
                let (fan_in, fan_out) = (w[0], w[1]);
                let bound = 1.0 / (fan_in as f32).sqrt();
                let mut draw = |n: usize| -> Vec<f32> {
                    (0..n).map(|_| rng.random_range(-bound..bound)).collect()
                };
                let weight = draw(fan_out * fan_in);
                let bias = draw(fan_out);
                LayerParameters { weight, bias }
            })
            .collect();
        Self { layers }
    }

    /// Checks the sizes against the architecture and that every value is finite.
    pub fn validate(&self) -> Result<(), Error> {
        if self.layers.len() != LAYERS {
            return Err(Error::Shape {
                layer: self.layers.len().min(LAYERS),
                tensor: "weight",
                got: 0,
                expected: LAYER_SIZES[1] * LAYER_SIZES[0],
            });
        }
        for (layer, (p, w)) in self.layers.iter().zip(LAYER_SIZES.windows(2)).enumerate() {
            for (tensor, values, expected) in
                [("weight", &p.weight, w[0] * w[1]), ("bias", &p.bias, w[1])]
            {
                if values.len() != expected {
                    return Err(Error::Shape {
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
        Ok(())
    }

    /// Reference forward pass in f64 on one sample (slow; for tests and checks).
    pub fn forward_f64(&self, x: &[f32]) -> [f64; OUTPUTS] {
        let mut h: Vec<f64> = x.iter().map(|&v| f64::from(v)).collect();
        for (i, (p, w)) in self.layers.iter().zip(LAYER_SIZES.windows(2)).enumerate() {
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

/// The MLP as a burn module: four [`Linear`] layers named `layers.0` .. `layers.3`, ReLU between
/// them and none after the last.
///
/// burn's `Linear` stores its weight `[in, out]`; [`Mlp::from_parameters`] and
/// [`Mlp::parameters`] transpose to and from PyTorch's `[out, in]`.
#[derive(Module, Debug)]
pub struct Mlp {
    /// The linear layers, input first.
    pub layers: Vec<Linear>,
}

impl Mlp {
    /// A model with PyTorch-default initial weights from `seed` (see [`Parameters::init`]).
    pub fn new(seed: u64, device: &Device) -> Self {
        // Sizes come from the architecture constants, so the freshly drawn weights always fit.
        Self::from_parameters(&Parameters::init(seed), device)
            .unwrap_or_else(|e| unreachable!("initial parameters fit the architecture: {e}"))
    }

    /// Uploads `params` (PyTorch layout) to `device`.
    pub fn from_parameters(params: &Parameters, device: &Device) -> Result<Self, Error> {
        params.validate()?;
        let layers = params
            .layers
            .iter()
            .zip(LAYER_SIZES.windows(2))
            .map(|(p, w)| {
                let (fan_in, fan_out) = (w[0], w[1]);
                let mut linear = LinearConfig::new(fan_in, fan_out).init(device);
                let weight = Tensor::<2>::from_data(
                    TensorData::new(transpose(&p.weight, fan_out, fan_in), [fan_in, fan_out]),
                    device,
                );
                let bias =
                    Tensor::<1>::from_data(TensorData::new(p.bias.clone(), [fan_out]), device);
                linear.weight = Param::from_tensor(weight);
                linear.bias = Some(Param::from_tensor(bias));
                linear
            })
            .collect();
        Ok(Self { layers })
    }

    /// Downloads the weights into PyTorch layout.
    pub fn parameters(&self) -> Result<Parameters, Error> {
        let layers = self
            .layers
            .iter()
            .zip(LAYER_SIZES.windows(2))
            .map(|(linear, w)| {
                let (fan_in, fan_out) = (w[0], w[1]);
                let weight = to_vec(&linear.weight.val())?;
                let bias = match &linear.bias {
                    Some(b) => to_vec(&b.val())?,
                    None => vec![0.0; fan_out],
                };
                Ok(LayerParameters {
                    weight: transpose(&weight, fan_in, fan_out),
                    bias,
                })
            })
            .collect::<Result<Vec<_>, Error>>()?;
        Ok(Parameters { layers })
    }

    /// Forward pass: `[batch, 900]` features to `[batch, 2]` (pitch, roll).
    pub fn forward(&self, x: Tensor<2>) -> Tensor<2> {
        let last = self.layers.len().saturating_sub(1);
        self.layers.iter().enumerate().fold(x, |h, (i, linear)| {
            let z = linear.forward(h);
            if i < last { relu(z) } else { z }
        })
    }
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

/// A burn tensor's values as f32.
pub(crate) fn to_vec<const D: usize>(t: &Tensor<D>) -> Result<Vec<f32>, Error> {
    t.to_data()
        .try_into_vec::<f32>()
        .map_err(|e| Error::Readback(format!("{e:?}")))
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
    fn burn_round_trip_and_forward_match_the_reference() {
        let device = Device::flex();
        let p = Parameters::init(1);
        let mlp = Mlp::from_parameters(&p, &device).expect("fits");
        assert_eq!(mlp.parameters().expect("readback"), p);
        let x: Vec<f32> = (0..2 * INPUTS).map(|i| ((i % 17) as f32) * 0.1).collect();
        let out = to_vec(&mlp.forward(Tensor::from_data(
            TensorData::new(x.clone(), [2, INPUTS]),
            &device,
        )))
        .expect("readback");
        for s in 0..2 {
            let r = p.forward_f64(&x[s * INPUTS..(s + 1) * INPUTS]);
            for k in 0..OUTPUTS {
                assert!((f64::from(out[s * OUTPUTS + k]) - r[k]).abs() < 1e-4);
            }
        }
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
