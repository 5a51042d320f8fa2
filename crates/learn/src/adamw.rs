//! AdamW with PyTorch's exact update (`torch.optim.AdamW`, single-tensor CPU path), on burn
//! tensors.
//!
//! burn's own `AdamW` differs from PyTorch in details that change the numbers: it computes the
//! bias corrections `1 - beta^t` in f32 (PyTorch in f64 on the host), divides by the corrected
//! second moment before the square root (PyTorch divides `sqrt(v)` by `sqrt(1 - beta2^t)`),
//! updates the first moment as `beta1*m + (1-beta1)*g` (PyTorch uses `lerp`), and defaults to
//! `eps = 1e-5`. This module follows PyTorch step for step so that the per-step losses match a
//! PyTorch run to f32 rounding (see `tests/pytorch.rs`):
//!
//! ```text
//! p  <- p * (1 - lr * wd)                      decoupled weight decay, before the Adam step
//! m  <- m + (1 - b1) * (g - m)                 exp_avg.lerp_(grad, 1 - beta1)
//! v  <- v * b2 + (1 - b2) * g * g              exp_avg_sq.mul_(beta2).addcmul_(grad, grad, 1 - beta2)
//! p  <- p - lr / (1 - b1^t) * m / (sqrt(v) / sqrt(1 - b2^t) + eps)
//! ```

use burn::tensor::Tensor;
use serde::{Deserialize, Serialize};

/// AdamW hyper-parameters; the defaults are the paper's (lr 5e-3, weight decay 1e-4) and
/// PyTorch's (betas 0.9 / 0.999, eps 1e-8).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AdamWConfig {
    /// Learning rate.
    pub learning_rate: f64,
    /// Decoupled weight decay (multiplied by the learning rate).
    pub weight_decay: f64,
    /// First-moment decay.
    pub beta1: f64,
    /// Second-moment decay.
    pub beta2: f64,
    /// Added to the bias-corrected root second moment.
    pub epsilon: f64,
}

impl Default for AdamWConfig {
    fn default() -> Self {
        Self {
            learning_rate: 5e-3,
            weight_decay: 1e-4,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-8,
        }
    }
}

/// The moments of one parameter tensor.
#[derive(Debug, Clone)]
struct Moments<const D: usize> {
    m: Tensor<D>,
    v: Tensor<D>,
}

/// AdamW state for a model whose parameters are visited in a fixed order each step.
#[derive(Debug, Clone)]
pub struct AdamW {
    config: AdamWConfig,
    step: u64,
    matrices: Vec<Moments<2>>,
    vectors: Vec<Moments<1>>,
}

/// Scalars of one step, computed in f64 as PyTorch does on the host.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepScalars {
    decay: f64,
    one_minus_beta1: f64,
    beta2: f64,
    one_minus_beta2: f64,
    step_size: f64,
    bias_correction2_sqrt: f64,
    epsilon: f64,
}

impl AdamW {
    /// A fresh optimiser (step 0, moments allocated lazily as zeros).
    pub fn new(config: AdamWConfig) -> Self {
        Self {
            config,
            step: 0,
            matrices: Vec::new(),
            vectors: Vec::new(),
        }
    }

    /// The number of steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// Starts a step: advances the step count and returns its scalars.
    pub(crate) fn begin_step(&mut self) -> StepScalars {
        self.step += 1;
        let c = &self.config;
        // PyTorch keeps `step` as a float tensor and computes these on the host in f64.
        let t = self.step as f64;
        let bias_correction1 = 1.0 - c.beta1.powf(t);
        let bias_correction2 = 1.0 - c.beta2.powf(t);
        StepScalars {
            decay: 1.0 - c.learning_rate * c.weight_decay,
            one_minus_beta1: 1.0 - c.beta1,
            beta2: c.beta2,
            one_minus_beta2: 1.0 - c.beta2,
            step_size: c.learning_rate / bias_correction1,
            bias_correction2_sqrt: bias_correction2.sqrt(),
            epsilon: c.epsilon,
        }
    }

    /// Updates the `index`-th matrix parameter with its gradient; returns the new value.
    pub(crate) fn update_matrix(
        &mut self,
        s: &StepScalars,
        index: usize,
        param: Tensor<2>,
        grad: Tensor<2>,
    ) -> Tensor<2> {
        if self.matrices.len() <= index {
            let zeros = grad.zeros_like();
            self.matrices.push(Moments {
                m: zeros.clone(),
                v: zeros,
            });
        }
        update(s, &mut self.matrices[index], param, grad)
    }

    /// Updates the `index`-th vector parameter with its gradient; returns the new value.
    pub(crate) fn update_vector(
        &mut self,
        s: &StepScalars,
        index: usize,
        param: Tensor<1>,
        grad: Tensor<1>,
    ) -> Tensor<1> {
        if self.vectors.len() <= index {
            let zeros = grad.zeros_like();
            self.vectors.push(Moments {
                m: zeros.clone(),
                v: zeros,
            });
        }
        update(s, &mut self.vectors[index], param, grad)
    }
}

/// One PyTorch AdamW update of one tensor (see the module docs for the formulas).
fn update<const D: usize>(
    s: &StepScalars,
    moments: &mut Moments<D>,
    param: Tensor<D>,
    grad: Tensor<D>,
) -> Tensor<D> {
    let param = param.mul_scalar(s.decay);
    let m = moments.m.clone();
    moments.m = m.clone() + (grad.clone() - m).mul_scalar(s.one_minus_beta1);
    moments.v = moments.v.clone().mul_scalar(s.beta2)
        + grad.clone().mul_scalar(s.one_minus_beta2).mul(grad);
    let denom = moments
        .v
        .clone()
        .sqrt()
        .div_scalar(s.bias_correction2_sqrt)
        .add_scalar(s.epsilon);
    param - moments.m.clone().div(denom).mul_scalar(s.step_size)
}
