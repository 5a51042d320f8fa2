//! The network as a burn module, compiled for tests only: burn's autodiff and `Linear` layers are
//! the independent reference the hand-written training (`backprop.rs`) is tested against. The
//! product never runs burn (training and inference are hand-written, see `backprop.rs` and
//! `predictor.rs` for why), so burn is a dev-dependency and stays out of the release binary.

use burn::module::{Module, Param};
use burn::nn::{Linear, LinearConfig};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor, TensorData};

use crate::model::{Architecture, LAYERS, LayerParameters, Parameters, transpose};

/// A burn call failed, or the module does not fit an architecture.
pub type Error = String;

/// The network as a burn module: four [`Linear`] layers named `layers.0` .. `layers.3`, ReLU
/// between them and none after the last (late fusion as its block-diagonal first layer: the
/// same function, not the same gradients for the cross-branch weights).
///
/// burn's `Linear` stores its weight `[in, out]`; [`Mlp::from_parameters`] and
/// [`Mlp::parameters`] transpose to and from PyTorch's `[out, in]`.
#[derive(Module, Debug)]
pub struct Mlp {
    /// The linear layers, input first.
    pub layers: Vec<Linear>,
}

impl Mlp {
    /// Uploads `params` (PyTorch layout) to `device`.
    pub fn from_parameters(params: &Parameters, device: &Device) -> Result<Self, Error> {
        params.validate().map_err(|e| e.to_string())?;
        let sizes = params.architecture.layer_sizes();
        let layers = params
            .layers
            .iter()
            .zip(sizes.windows(2))
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

    /// Downloads the weights into PyTorch layout, as the weights of `architecture` (checked).
    pub fn parameters(&self, architecture: Architecture) -> Result<Parameters, Error> {
        let sizes = architecture.layer_sizes();
        if self.layers.len() != LAYERS {
            return Err(format!(
                "{} layers for {} ({LAYERS} expected)",
                self.layers.len(),
                architecture.describe()
            ));
        }
        let layers = self
            .layers
            .iter()
            .zip(sizes.windows(2))
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
        let params = Parameters {
            architecture,
            layers,
        };
        params.validate().map_err(|e| e.to_string())?;
        Ok(params)
    }

    /// Forward pass: `[batch, inputs]` features to `[batch, 2]` (pitch, roll).
    pub fn forward(&self, x: Tensor<2>) -> Tensor<2> {
        let last = self.layers.len().saturating_sub(1);
        self.layers.iter().enumerate().fold(x, |h, (i, linear)| {
            let z = linear.forward(h);
            if i < last { relu(z) } else { z }
        })
    }
}

/// A burn tensor's values as f32.
pub(crate) fn to_vec<const D: usize>(t: &Tensor<D>) -> Result<Vec<f32>, Error> {
    t.to_data()
        .try_into_vec::<f32>()
        .map_err(|e| format!("reading a tensor back from burn failed: {e:?}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{INPUTS, OUTPUTS};

    #[test]
    fn burn_round_trip_and_forward_match_the_reference() {
        let device = Device::flex();
        let p = Parameters::init(1);
        let mlp = Mlp::from_parameters(&p, &device).expect("fits");
        assert_eq!(mlp.parameters(Architecture::Mlp).expect("readback"), p);
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
}
