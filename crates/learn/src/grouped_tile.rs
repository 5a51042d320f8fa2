//! The AVX-512 kernel of [`crate::panels::grouped_forward`]: a tile of four samples by one
//! block of 64 outputs, held in sixteen registers while the block's weight panel streams past.
//!
//! Why by hand: written portably (a `[[f32; 64]; 4]` accumulator), LLVM keeps the tile in
//! memory on the stack, so every fused multiply-add loads its accumulator and stores it back.
//! perf on a real dynamic-density `evtac train` (tau 640 ms, count threshold 0) put 34.5 % of
//! the epoch in that kernel, its hottest instructions `vfmadd213ps 0x3c0(%rsp),...` and
//! `vmovups %zmm,0x380(%rsp)`. No crate offers a GEMM that skips the rows every sample of a
//! group has at zero, and a dense GEMM would change the order of the sums.
//!
//! The tile does the same operations in the same order as the portable kernels (input by
//! input): fused multiply-adds `acc = x * w + acc` for training's forward pass
//! (`FUSED = true`, as [`crate::panels::grouped_forward_portable`]), or a multiply then an add
//! for validation (`FUSED = false`, as [`crate::panels::dense_forward`], whose bits inference
//! has), so it gives the same bits (tested below). It runs only on whole groups, on CPUs with
//! AVX-512F; the portable kernels do the rest.

use std::arch::x86_64::{
    _mm512_add_ps, _mm512_fmadd_ps, _mm512_loadu_ps, _mm512_mul_ps, _mm512_set1_ps,
    _mm512_setzero_ps, _mm512_storeu_ps,
};
use std::ops::Range;

use crate::panels::{BLOCK, GROUP};

/// Floats in one AVX-512 register.
const LANES: usize = 16;

/// Registers per sample's row of a block.
const VECTORS: usize = BLOCK / LANES;

/// Whether this CPU can run [`tile`].
pub(crate) fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
}

/// `bias + x W` for [`GROUP`] samples (`x`: their dense rows, `GROUP x fan_in`) over one
/// block's `panel` (`[fan_in][BLOCK]`), from the inputs `inputs` only; rows that every sample
/// has at zero are skipped. Fused multiply-adds when `FUSED`, else a multiply then an add.
/// Returns the tile, sample by sample.
///
/// # Safety
/// The CPU must support AVX-512F ([`available`]).
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn tile<const FUSED: bool>(
    panel: &[f32],
    bias: &[f32],
    x: &[f32],
    inputs: Range<usize>,
) -> [[f32; BLOCK]; GROUP] {
    let fan_in = x.len() / GROUP;
    assert!(bias.len() == BLOCK && panel.len() >= inputs.end * BLOCK && inputs.end <= fan_in);
    let mut acc = [[_mm512_setzero_ps(); VECTORS]; GROUP];
    for sample in acc.iter_mut() {
        for (v, a) in sample.iter_mut().enumerate() {
            // SAFETY: `bias` holds BLOCK floats (asserted), so lanes v*16.. are in bounds.
            *a = unsafe { _mm512_loadu_ps(bias.as_ptr().add(v * LANES)) };
        }
    }
    for i in inputs {
        let xs: [f32; GROUP] = std::array::from_fn(|k| x[k * fan_in + i]);
        if xs.iter().all(|&v| v == 0.0) {
            continue;
        }
        let row = &panel[i * BLOCK..][..BLOCK];
        let mut w = [_mm512_setzero_ps(); VECTORS];
        for (v, w) in w.iter_mut().enumerate() {
            // SAFETY: `row` holds BLOCK floats, so lanes v*16.. are in bounds.
            *w = unsafe { _mm512_loadu_ps(row.as_ptr().add(v * LANES)) };
        }
        for (sample, &xk) in acc.iter_mut().zip(&xs) {
            let xk = _mm512_set1_ps(xk);
            for (a, &w) in sample.iter_mut().zip(&w) {
                *a = if FUSED {
                    _mm512_fmadd_ps(xk, w, *a)
                } else {
                    _mm512_add_ps(*a, _mm512_mul_ps(xk, w))
                };
            }
        }
    }
    let mut out = [[0.0_f32; BLOCK]; GROUP];
    for (o, sample) in out.iter_mut().zip(&acc) {
        for (v, &a) in sample.iter().enumerate() {
            // SAFETY: `o` holds BLOCK floats, so lanes v*16.. are in bounds.
            unsafe { _mm512_storeu_ps(o.as_mut_ptr().add(v * LANES), a) };
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::panels::{Sums, grouped_forward_portable};

    /// A deterministic stream of floats in [-1, 1), a fraction of them zero.
    pub(crate) fn floats(n: usize, seed: u64, zeros: f32) -> Vec<f32> {
        let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|_| {
                if next() < zeros {
                    0.0
                } else {
                    2.0 * next() - 1.0
                }
            })
            .collect()
    }

    #[test]
    fn the_tile_gives_the_portable_kernels_bits() {
        if !available() {
            eprintln!("no AVX-512F on this CPU: the tile never runs here");
            return;
        }
        let (fan_in, fan_out) = (900, 256);
        let weights = floats(fan_in * fan_out, 1, 0.0);
        let bias = floats(fan_out, 2, 0.0);
        // Dense-ish, sparse (rows every sample has at zero are skipped), and exactly zero.
        for (seed, zeros) in [(3, 0.25), (4, 0.9), (5, 1.0)] {
            let x = floats(GROUP * fan_in, seed, zeros);
            for inputs in [0..fan_in, 0..450, 450..900] {
                let mut want = vec![0.0; GROUP * fan_out];
                let units = 0..fan_out;
                let shape = (units.clone(), inputs.clone());
                grouped_forward_portable(
                    &weights,
                    &bias,
                    (&x, GROUP),
                    &mut want,
                    shape,
                    (false, Sums::Fused),
                );
                for b in 0..fan_out / BLOCK {
                    let panel = &weights[b * fan_in * BLOCK..][..fan_in * BLOCK];
                    let bias = &bias[b * BLOCK..][..BLOCK];
                    // SAFETY: AVX-512F is available (checked above).
                    let got = unsafe { tile::<true>(panel, bias, &x, inputs.clone()) };
                    for (k, got) in got.iter().enumerate() {
                        let want = &want[k * fan_out + b * BLOCK..][..BLOCK];
                        let (got, want): (Vec<u32>, Vec<u32>) = (
                            got.iter().map(|v| v.to_bits()).collect(),
                            want.iter().map(|v| v.to_bits()).collect(),
                        );
                        assert_eq!(got, want, "zeros {zeros}, inputs {inputs:?}, block {b}");
                    }
                }
            }
        }
    }
}
