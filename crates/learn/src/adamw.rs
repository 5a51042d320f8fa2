//! AdamW with PyTorch's update (`torch.optim.AdamW`, its math; not its rounding), on the
//! host copies of the parameters.
//!
//! burn's own `AdamW` differs from PyTorch in details that change the numbers: it computes the
//! bias corrections `1 - beta^t` in f32 (PyTorch in f64 on the host), divides by the corrected
//! second moment before the square root (PyTorch divides `sqrt(v)` by `sqrt(1 - beta2^t)`),
//! updates the first moment as `beta1*m + (1-beta1)*g` (PyTorch uses `lerp`), and defaults to
//! `eps = 1e-5`. This module computes PyTorch's update, so that the per-step losses match a
//! PyTorch run to 1e-5 relative (see `tests/pytorch.rs`). The update is one fused loop per
//! parameter tensor rather than a dozen whole-tensor burn operations: written with burn ops it
//! allocated and wrote ten 1 MB temporaries per step for the first layer alone and took about
//! a third of each training step.
//!
//! The math is PyTorch's, the rounding is not (PyTorch's own for-each and fused AdamW round
//! differently from each other too): the division by `sqrt(1 - beta2^t)` is a multiplication
//! by its reciprocal, and on CPUs with AVX-512F (`update`) the square root and the division
//! by the denominator are the hardware's 14-bit estimates (`vrsqrt14ps`, `vrcp14ps`) refined by
//! one Newton step each, about 1 ulp from the correctly rounded results. Why: the exact
//! `sqrt` and two divisions per weight were most of a training step's optimiser pass (every
//! first-layer weight, every step); the estimates run on the multiply-add ports instead.
//! Every element goes through the same instructions whatever its neighbours, so a binary gives
//! the same bits on a given CPU; the portable path (other CPUs, and the tails of slices not a
//! multiple of 16) rounds differently in the last bit.
//!
//! ```text
//! p  <- p * (1 - lr * wd)                      decoupled weight decay, before the Adam step
//! m  <- m + (1 - b1) * (g - m)                 exp_avg.lerp_(grad, 1 - beta1)
//! v  <- v * b2 + (1 - b2) * g * g              exp_avg_sq.mul_(beta2).addcmul_(grad, grad, 1 - beta2)
//! p  <- p - lr / (1 - b1^t) * m / (sqrt(v) / sqrt(1 - b2^t) + eps)
//! ```

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
struct Moments {
    m: Vec<f32>,
    v: Vec<f32>,
}

/// The optimiser: its settings, the step count and one pair of moments per parameter tensor.
#[derive(Debug, Clone)]
pub struct AdamW {
    config: AdamWConfig,
    step: u64,
    moments: Vec<Moments>,
}

/// The per-step scalars, from the step count (bias corrections in f64, as PyTorch computes them
/// on the host) and rounded once to f32, the precision of PyTorch's CPU kernels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepScalars {
    decay: f32,
    one_minus_beta1: f32,
    beta2: f32,
    one_minus_beta2: f32,
    step_size: f32,
    /// `1 / sqrt(1 - beta2^t)`, so that the update multiplies rather than divides.
    inv_bias_correction2_sqrt: f32,
    epsilon: f32,
}

impl AdamW {
    /// A fresh optimiser (moments are created, zeroed, on each tensor's first update).
    pub fn new(config: AdamWConfig) -> Self {
        Self {
            config,
            step: 0,
            moments: Vec::new(),
        }
    }

    /// Number of steps begun.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// Starts a step: advances the count and computes its scalars.
    pub(crate) fn begin_step(&mut self) -> StepScalars {
        self.step += 1;
        let c = &self.config;
        let t = self.step as f64;
        let bias_correction1 = 1.0 - c.beta1.powf(t);
        let bias_correction2 = 1.0 - c.beta2.powf(t);
        StepScalars {
            decay: (1.0 - c.learning_rate * c.weight_decay) as f32,
            one_minus_beta1: (1.0 - c.beta1) as f32,
            beta2: c.beta2 as f32,
            one_minus_beta2: (1.0 - c.beta2) as f32,
            step_size: (c.learning_rate / bias_correction1) as f32,
            inv_bias_correction2_sqrt: (1.0 / bias_correction2.sqrt()) as f32,
            epsilon: c.epsilon as f32,
        }
    }

    /// The moments of parameter tensor `index` (any fixed numbering) of `len` values, created
    /// zeroed on first use.
    pub(crate) fn moments(&mut self, index: usize, len: usize) -> (&mut [f32], &mut [f32]) {
        while self.moments.len() <= index {
            self.moments.push(Moments {
                m: Vec::new(),
                v: Vec::new(),
            });
        }
        let moments = &mut self.moments[index];
        if moments.m.len() != len {
            moments.m = vec![0.0; len];
            moments.v = vec![0.0; len];
        }
        (&mut moments.m, &mut moments.v)
    }

    /// Updates parameter tensor `index` (any fixed numbering) in place from its gradient.
    ///
    /// `param` and `grad` have the same length, the same for every step of one tensor.
    pub(crate) fn update(
        &mut self,
        s: &StepScalars,
        index: usize,
        param: &mut [f32],
        grad: &[f32],
    ) {
        debug_assert_eq!(param.len(), grad.len());
        let (m, v) = self.moments(index, param.len());
        update(s, param, grad, m, v);
    }
}

/// One element's update, portably: the operations of PyTorch's single-tensor path (weight
/// decay, lerp of the first moment, addcmul of the second, then the corrected step), with the
/// bias correction multiplied by its reciprocal.
#[inline(always)]
pub(crate) fn update_one(s: &StepScalars, p: &mut f32, g: f32, m: &mut f32, v: &mut f32) {
    let decayed = *p * s.decay;
    *m += (g - *m) * s.one_minus_beta1;
    *v = *v * s.beta2 + g * s.one_minus_beta2 * g;
    let denom = v.sqrt() * s.inv_bias_correction2_sqrt + s.epsilon;
    *p = decayed - s.step_size * *m / denom;
}

/// Updates `param` from `grad` with the moments `m`, `v` (all the same length): sixteen
/// elements at a time on AVX-512F where the CPU has it ([`avx512`]), the rest by
/// [`update_one`].
#[inline]
pub(crate) fn update(
    s: &StepScalars,
    param: &mut [f32],
    grad: &[f32],
    m: &mut [f32],
    v: &mut [f32],
) {
    let n = param.len();
    assert!(grad.len() == n && m.len() == n && v.len() == n);
    let mut done = 0;
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        done = n - n % avx512::LANES;
        // SAFETY: the CPU has AVX-512F (checked) and the four slices hold `n >= done` floats.
        unsafe { avx512::update(s, param, grad, m, v, done) };
    }
    update_portable(
        s,
        &mut param[done..],
        &grad[done..],
        &mut m[done..],
        &mut v[done..],
    );
}

/// [`update_one`] over whole slices, compiled for AVX2 besides the baseline: the same exact
/// square root and division eight elements per instruction (correctly rounded either way, so
/// the same bits as one element at a time). On the baseline alone, this pass was 20 % of a
/// dense training run on an AVX2-only CPU (AMD Zen 3), four elements per instruction.
#[multiversion::multiversion(targets("x86_64+avx2+fma"))]
fn update_portable(s: &StepScalars, param: &mut [f32], grad: &[f32], m: &mut [f32], v: &mut [f32]) {
    for (((p, &g), m), v) in param
        .iter_mut()
        .zip(grad)
        .zip(m.iter_mut())
        .zip(v.iter_mut())
    {
        update_one(s, p, g, m, v);
    }
}

/// The AVX-512F form of [`update_one`], sixteen elements per instruction.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::StepScalars;
    use std::arch::x86_64::{
        __m512, _CMP_GT_OQ, _mm512_cmp_ps_mask, _mm512_fmadd_ps, _mm512_fnmadd_ps, _mm512_loadu_ps,
        _mm512_maskz_fmadd_ps, _mm512_maskz_mul_ps, _mm512_mul_ps, _mm512_rcp14_ps,
        _mm512_rsqrt14_ps, _mm512_set1_ps, _mm512_setzero_ps, _mm512_storeu_ps, _mm512_sub_ps,
    };

    /// Floats in one AVX-512 register.
    pub(super) const LANES: usize = 16;

    /// [`super::update_one`] on the first `len` elements (a multiple of [`LANES`]).
    ///
    /// `sqrt(v)` is `v * rsqrt14(v)` plus one Newton step (`v = 0` gives 0: the estimate is
    /// infinite there, so those lanes are masked to zero); `1 / denom` is `rcp14(denom)` plus
    /// one Newton step (`denom >= eps > 0`). Each step squares the estimate's relative error:
    /// 2^-14 becomes about 2^-28, under f32's rounding.
    ///
    /// # Safety
    /// The CPU must support AVX-512F, and every slice must hold at least `len` floats.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn update(
        s: &StepScalars,
        param: &mut [f32],
        grad: &[f32],
        m: &mut [f32],
        v: &mut [f32],
        len: usize,
    ) {
        debug_assert!(len.is_multiple_of(LANES));
        debug_assert!(param.len() >= len && grad.len() >= len && m.len() >= len);
        debug_assert!(v.len() >= len);
        let decay = _mm512_set1_ps(s.decay);
        let one_minus_beta1 = _mm512_set1_ps(s.one_minus_beta1);
        let beta2 = _mm512_set1_ps(s.beta2);
        let one_minus_beta2 = _mm512_set1_ps(s.one_minus_beta2);
        let step_size = _mm512_set1_ps(s.step_size);
        let inv_correction = _mm512_set1_ps(s.inv_bias_correction2_sqrt);
        let epsilon = _mm512_set1_ps(s.epsilon);
        let (half, one) = (_mm512_set1_ps(0.5), _mm512_set1_ps(1.0));
        for k in (0..len).step_by(LANES) {
            // SAFETY: `k + LANES <= len <= every slice's length` (the caller's contract).
            unsafe {
                let (pp, gp) = (param.as_mut_ptr().add(k), grad.as_ptr().add(k));
                let (mp, vp) = (m.as_mut_ptr().add(k), v.as_mut_ptr().add(k));
                let (p, g) = (_mm512_loadu_ps(pp), _mm512_loadu_ps(gp));
                let (m, v) = (_mm512_loadu_ps(mp), _mm512_loadu_ps(vp));
                let decayed = _mm512_mul_ps(p, decay);
                let m = _mm512_fmadd_ps(_mm512_sub_ps(g, m), one_minus_beta1, m);
                let v = _mm512_fmadd_ps(
                    _mm512_mul_ps(g, one_minus_beta2),
                    g,
                    _mm512_mul_ps(v, beta2),
                );
                let root = sqrt(v, half);
                let denom = _mm512_fmadd_ps(root, inv_correction, epsilon);
                let inv = reciprocal(denom, one);
                let p = _mm512_fnmadd_ps(_mm512_mul_ps(step_size, m), inv, decayed);
                _mm512_storeu_ps(pp, p);
                _mm512_storeu_ps(mp, m);
                _mm512_storeu_ps(vp, v);
            }
        }
    }

    /// `sqrt(v)` for `v >= 0`: `v * r` with `r = rsqrt14(v)`, refined once
    /// (`s + s * (0.5 - s * r / 2)`); 0 where `v` is 0.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn sqrt(v: __m512, half: __m512) -> __m512 {
        let positive = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(v, _mm512_setzero_ps());
        let r = _mm512_rsqrt14_ps(v);
        let s = _mm512_maskz_mul_ps(positive, v, r);
        let h = _mm512_mul_ps(half, r);
        let e = _mm512_fnmadd_ps(s, h, half);
        // Where v = 0, r is infinite and e NaN: keep those lanes at 0.
        _mm512_maskz_fmadd_ps(positive, s, e, s)
    }

    /// `1 / d` for `d > 0`: `q = rcp14(d)`, refined once (`q + q * (1 - d * q)`).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn reciprocal(d: __m512, one: __m512) -> __m512 {
        let q = _mm512_rcp14_ps(d);
        _mm512_fmadd_ps(q, _mm512_fnmadd_ps(d, q, one), q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// PyTorch's moments of one element in f64: the updated `(m, v)`.
    fn reference_moments(c: &AdamWConfig, g: f32, m: f32, v: f32) -> (f64, f64) {
        let (g, m, v) = (f64::from(g), f64::from(m), f64::from(v));
        let m = m + (g - m) * (1.0 - c.beta1);
        let v = v * c.beta2 + (1.0 - c.beta2) * g * g;
        (m, v)
    }

    /// PyTorch's step of one element in f64 at step `t`, from its weight and its *updated*
    /// moments.
    fn reference_step(c: &AdamWConfig, t: u64, p: f32, m: f32, v: f32) -> f64 {
        let (p, m, v) = (f64::from(p), f64::from(m), f64::from(v));
        let bias_correction1 = 1.0 - c.beta1.powf(t as f64);
        let bias_correction2 = 1.0 - c.beta2.powf(t as f64);
        let decayed = p * (1.0 - c.learning_rate * c.weight_decay);
        let denom = v.sqrt() / bias_correction2.sqrt() + c.epsilon;
        decayed - c.learning_rate / bias_correction1 * m / denom
    }

    /// Whether `got` is within `ulps` f32 ulps of `want`, measured at `scale` (the largest
    /// term the result was formed from: a difference of large terms is exact only to theirs).
    fn close(got: f32, want: f64, scale: f64, ulps: f64) -> bool {
        (f64::from(got) - want).abs() <= ulps * f64::from(f32::EPSILON) * scale.abs().max(1e-30)
    }

    proptest! {
        /// Both paths (sixteen lanes where the CPU has AVX-512F, and the portable tail: 37
        /// elements are two registers and five more) compute PyTorch's update to within a few
        /// ulps, zero second moments (a weight no sample has reached yet) included.
        #[test]
        fn update_is_pytorchs_to_a_few_ulps(
            step in 1_u64..20_000,
            values in proptest::collection::vec(
                (-1.0_f32..1.0, -10.0_f32..10.0, -1.0_f32..1.0, 0.0_f32..10.0, any::<bool>()),
                37,
            ),
        ) {
            let c = AdamWConfig::default();
            let mut optimizer = AdamW::new(c);
            optimizer.step = step - 1;
            let s = optimizer.begin_step();
            let (mut p, mut g, mut m, mut v) = (vec![], vec![], vec![], vec![]);
            for &(pi, gi, mi, vi, zero) in &values {
                // A zero gradient with zero moments: the weight only decays.
                let (gi, mi, vi) = if zero { (0.0, 0.0, 0.0) } else { (gi, mi, vi) };
                p.push(pi);
                g.push(gi);
                m.push(mi);
                v.push(vi);
            }
            let (p0, m0, v0) = (p.clone(), m.clone(), v.clone());
            update(&s, &mut p, &g, &mut m, &mut v);
            for k in 0..p.len() {
                let (want_m, want_v) = reference_moments(&c, g[k], m0[k], v0[k]);
                // The step from the moments as computed (each checked against PyTorch's just
                // below): where `g - m` cancels, the new first moment keeps only a few of its
                // digits (to 2 ulps of the larger term, as PyTorch's own f32 kernels), and the
                // step carries that error whatever its own rounding.
                let want_p = reference_step(&c, step, p0[k], m[k], v[k]);
                let decayed = f64::from(p0[k]) * (1.0 - c.learning_rate * c.weight_decay);
                let scale = decayed.abs().max((want_p - decayed).abs());
                prop_assert!(close(m[k], want_m, f64::from(m0[k].abs().max(g[k].abs())), 2.0));
                prop_assert!(close(v[k], want_v, f64::from(v0[k]).max(f64::from(g[k]).powi(2)), 2.0));
                prop_assert!(
                    close(p[k], want_p, scale, 8.0),
                    "element {k}: {} against PyTorch's {want_p}", p[k]
                );
            }
        }

        /// The portable pass, vectorised or not, gives each element the bits [`update_one`]
        /// gives it alone.
        #[test]
        fn the_portable_pass_is_update_one_per_element(
            step in 1_u64..20_000,
            values in proptest::collection::vec(
                (-1.0_f32..1.0, -10.0_f32..10.0, -1.0_f32..1.0, 0.0_f32..10.0),
                0..80,
            ),
        ) {
            let mut optimizer = AdamW::new(AdamWConfig::default());
            optimizer.step = step - 1;
            let s = optimizer.begin_step();
            let mut p: Vec<f32> = values.iter().map(|t| t.0).collect();
            let g: Vec<f32> = values.iter().map(|t| t.1).collect();
            let mut m: Vec<f32> = values.iter().map(|t| t.2).collect();
            let mut v: Vec<f32> = values.iter().map(|t| t.3).collect();
            let mut want = values.clone();
            update_portable(&s, &mut p, &g, &mut m, &mut v);
            for (k, (pk, gk, mk, vk)) in want.iter_mut().enumerate() {
                update_one(&s, pk, *gk, mk, vk);
                prop_assert_eq!(
                    (p[k].to_bits(), m[k].to_bits(), v[k].to_bits()),
                    (pk.to_bits(), mk.to_bits(), vk.to_bits()),
                    "element {}", k
                );
            }
        }
    }
}
