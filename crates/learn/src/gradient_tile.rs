//! The first layer's weight gradient on a dense batch, AVX-512: a tile of four input rows by
//! one block of 64 units, held in sixteen registers while the batch's samples stream past.
//!
//! Why: training's column path ([`crate::backprop`]'s `first_layer_rows`) forms a row's
//! gradient from the samples that have that input non-zero, one sample after another into four
//! accumulators. That skips zeros, which is what sparse batches need, but on a dense batch
//! (the static grid at count threshold 0 is 96 % non-zero) every accumulator waits for its
//! previous multiply-add: four chains of 32 dependent fused multiply-adds per row, a quarter of
//! what the multiply-add ports can do. perf on a 96 %-dense epoch put 25 % of it there. Four
//! rows at a time give sixteen independent chains, and each sample's block of output gradients
//! is loaded once for four rows instead of once per row. The zeros of a dense batch are
//! multiplied like any other value (they add nothing).
//!
//! The sums run over the samples in order with fused multiply-adds. The column path adds only
//! the non-zero terms, with a multiply then an add: the two differ in the last bits (training
//! is held to PyTorch's math, not to one rounding: see [`crate::adamw`]). Used only where a
//! batch is dense ([`crate::panels::GROUPED_DENSITY`]), so a given binary on a given CPU
//! always takes the same path for the same batch. CPUs without AVX-512F run [`tile_portable`]:
//! the same sums in the same order, so the same bits, a [`CHUNK`] of units at a time (the
//! sixteen-register tile does not fit AVX2's sixteen registers with room for the operands).

use std::arch::x86_64::{
    _mm512_fmadd_ps, _mm512_loadu_ps, _mm512_set1_ps, _mm512_setzero_ps, _mm512_storeu_ps,
};

use crate::panels::BLOCK;

/// Input rows per tile.
pub(crate) const ROWS: usize = 4;

/// Floats in one AVX-512 register.
const LANES: usize = 16;

/// Registers per row of a block.
const VECTORS: usize = BLOCK / LANES;

/// Units of a block that [`tile_portable`] sums at once: four rows by sixteen units are 8 AVX2
/// registers.
const CHUNK: usize = 16;

/// Whether this CPU can run [`tile`].
pub(crate) fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
}

/// [`tile`] where the CPU has it ([`available`]), else [`tile_portable`]: the same bits.
pub(crate) fn gradient(
    x: (&[f32], usize),
    first: usize,
    d: (&[f32], usize),
    out: &mut [f32; ROWS * BLOCK],
) {
    if available() {
        // SAFETY: the CPU has AVX-512F (checked).
        unsafe { tile(x, first, d, out) }
    } else {
        tile_portable(x, first, d, out);
    }
}

/// The batch's samples, once it is checked that `x` and `d` hold what a tile of rows `first..`
/// reads (the tiles' bounds, asserted once rather than at every load).
fn samples((x, inputs): (&[f32], usize), first: usize, (d, stride): (&[f32], usize)) -> usize {
    let n = x.len() / inputs;
    assert!(first + ROWS <= inputs && x.len() == n * inputs);
    assert!(n == 0 || d.len() >= (n - 1) * stride + BLOCK);
    n
}

/// [`tile`] in portable code, compiled for AVX2 with FMA besides the baseline: each sum is the
/// same fused multiply-adds in sample order, a [`CHUNK`] of the block's units at a time.
/// On an AVX2-only CPU (AMD Zen 3) it replaces, on dense batches, the column path, which forms
/// each product and sum separately: a dense epoch on one thread went 0.92-0.94 -> 0.70 s at 75 %
/// non-zero and 1.02-1.08 -> 0.68-0.73 s at 96 % (`docs/performance.md`).
#[multiversion::multiversion(targets("x86_64+avx2+fma"))]
pub(crate) fn tile_portable(
    (x, inputs): (&[f32], usize),
    first: usize,
    (d, stride): (&[f32], usize),
    out: &mut [f32; ROWS * BLOCK],
) {
    let n = samples((x, inputs), first, (d, stride));
    for chunk in (0..BLOCK).step_by(CHUNK) {
        let mut acc = [[0.0_f32; CHUNK]; ROWS];
        for s in 0..n {
            let dv = &d[s * stride + chunk..][..CHUNK];
            let xs = &x[s * inputs + first..][..ROWS];
            for (acc, &xr) in acc.iter_mut().zip(xs) {
                for (a, &dd) in acc.iter_mut().zip(dv) {
                    *a = xr.mul_add(dd, *a);
                }
            }
        }
        for (r, acc) in acc.iter().enumerate() {
            out[r * BLOCK + chunk..][..CHUNK].copy_from_slice(acc);
        }
    }
}

/// The gradient of the weights from inputs `first..first + ROWS` to the units of one block:
/// `out[r][j] = sum over samples s of x[s][first + r] * d[s][j]`, samples in order. `x` is the
/// batch (`n x inputs`, dense rows), `d` the gradient at the block's units for each sample
/// (`d[s * stride..][..BLOCK]`).
///
/// # Safety
/// The CPU must support AVX-512F ([`available`]).
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn tile(
    (x, inputs): (&[f32], usize),
    first: usize,
    (d, stride): (&[f32], usize),
    out: &mut [f32; ROWS * BLOCK],
) {
    let n = samples((x, inputs), first, (d, stride));
    let mut acc = [[_mm512_setzero_ps(); VECTORS]; ROWS];
    for s in 0..n {
        let row = &d[s * stride..][..BLOCK];
        let mut dv = [_mm512_setzero_ps(); VECTORS];
        for (v, dv) in dv.iter_mut().enumerate() {
            // SAFETY: `row` holds BLOCK floats, so lanes v*16.. are in bounds.
            *dv = unsafe { _mm512_loadu_ps(row.as_ptr().add(v * LANES)) };
        }
        let xs = &x[s * inputs + first..][..ROWS];
        for (acc, &xr) in acc.iter_mut().zip(xs) {
            let xr = _mm512_set1_ps(xr);
            for (a, &dv) in acc.iter_mut().zip(&dv) {
                *a = _mm512_fmadd_ps(xr, dv, *a);
            }
        }
    }
    for (r, acc) in acc.iter().enumerate() {
        for (v, &a) in acc.iter().enumerate() {
            // SAFETY: `out` holds ROWS * BLOCK floats; r < ROWS, v < VECTORS.
            unsafe { _mm512_storeu_ps(out.as_mut_ptr().add(r * BLOCK + v * LANES), a) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grouped_tile::tests::floats;

    /// A tile's signature: the batch and its width, the first row, the block's output gradients
    /// and their stride, the tile's sums.
    type Tile = fn((&[f32], usize), usize, (&[f32], usize), &mut [f32; ROWS * BLOCK]);

    /// Both tiles (the AVX-512 one where the CPU has it, the portable one on every CPU) give
    /// the fused sums of the non-zero terms in sample order to the bit (a zero term adds
    /// nothing), for full and short batches and rows at both ends.
    #[test]
    fn the_tiles_give_the_column_sums() {
        if !available() {
            eprintln!("no AVX-512F on this CPU: only the portable tile is checked");
        }
        let hand: Tile = |x, first, d, out| {
            // SAFETY: only called where the CPU has AVX-512F (filtered below).
            unsafe { tile(x, first, d, out) }
        };
        let tiles = [(hand, available()), (tile_portable as Tile, true)];
        for (tile, _) in tiles.into_iter().filter(|(_, runs)| *runs) {
            check_column_sums(tile);
        }
    }

    fn check_column_sums(tile: Tile) {
        let (inputs, stride) = (900, 256);
        for (n, seed, zeros) in [(32, 1, 0.04), (32, 2, 0.5), (7, 3, 0.2), (1, 4, 0.0)] {
            let x = floats(n * inputs, seed, zeros);
            let d = floats(n * stride, seed + 10, 0.5);
            for (first, block) in [(0, 0), (4, 1), (896, 3), (448, 2)] {
                let mut got = [0.0; ROWS * BLOCK];
                let d_block = &d[block * BLOCK..];
                tile((&x, inputs), first, (d_block, stride), &mut got);
                for r in 0..ROWS {
                    for j in 0..BLOCK {
                        let mut want = 0.0_f32;
                        for s in 0..n {
                            let xi = x[s * inputs + first + r];
                            if xi != 0.0 {
                                want = xi.mul_add(d_block[s * stride + j], want);
                            }
                        }
                        let g = got[r * BLOCK + j];
                        assert!(
                            g == want,
                            "n {n}, rows {first}+{r}, block {block}, unit {j}: {g} vs {want}"
                        );
                    }
                }
            }
        }
    }
}
