//! glibc's `expf`, reproduced bit for bit, so the static accumulator can inline and vectorize it.
//!
//! dv-processing decays a pixel with `expf(-dt / tau)`, which on Linux is glibc's `expf`
//! (glibc 2.27 and later: the algorithm of Arm's optimized-routines). Calling it per event was
//! about a quarter of the static representation's cost at high event rates (an opaque call that
//! the compiler can neither inline nor vectorize). This module computes the same function with the
//! same double-precision operations in the same order, so the results are the same bits:
//!
//! ```text
//! z = x * 32 / ln 2;  k = round(z);  r = z - k            (r in [-1/2, 1/2])
//! exp(x) = 2^(k/32) * 2^(r/32) ~= s * (C0 r^3 + C1 r^2 + C2 r + 1),   s = 2^(k/32) from a table
//! ```
//!
//! glibc has two builds of it and picks one at load time: with FMA (CPUs with FMA and AVX2) the
//! compiler fused four multiply-adds, without FMA every operation rounds on its own. The two can
//! differ in the last bit, so [`Flavor`] mirrors that choice, and each build here spells out its
//! operations exactly as the disassembly of glibc 2.36's `__expf_fma` and `__expf_sse2` shows.
//! Why written by hand: no crate reproduces glibc's `expf` bit for bit (the `libm` crate differs
//! by one ulp on some inputs, see the design notes); `tests/expf.rs` compares every input this
//! crate can produce with the platform's `expf` on linux-gnu.
//!
//! Special inputs (`|x| >= 88`, infinities, NaN) take glibc's slow path, reproduced too; off
//! x86_64 the platform's `f32::exp` is used as before.

/// `32 / ln 2`.
const INV_LN2_N: f64 = f64::from_bits(0x4047_1547_652b_82fe);
/// `1.5 * 2^52`: adding it rounds to an integer (ties to even) kept in the low mantissa bits.
const SHIFT: f64 = f64::from_bits(0x4338_0000_0000_0000);
/// The polynomial for `2^(r/32)`, highest degree first.
const C0: f64 = f64::from_bits(0x3ebc_6af8_4b91_2394);
const C1: f64 = f64::from_bits(0x3f2e_bfce_50fa_c4f3);
const C2: f64 = f64::from_bits(0x3f96_2e42_ff0c_52d6);
/// `bits(2^(i/32)) - (i << 47)`: adding `k << 47` to entry `k % 32` gives `2^(k/32)`.
const TABLE: [u64; 32] = [
    0x3ff0000000000000,
    0x3fefd9b0d3158574,
    0x3fefb5586cf9890f,
    0x3fef9301d0125b51,
    0x3fef72b83c7d517b,
    0x3fef54873168b9aa,
    0x3fef387a6e756238,
    0x3fef1e9df51fdee1,
    0x3fef06fe0a31b715,
    0x3feef1a7373aa9cb,
    0x3feedea64c123422,
    0x3feece086061892d,
    0x3feebfdad5362a27,
    0x3feeb42b569d4f82,
    0x3feeab07dd485429,
    0x3feea47eb03a5585,
    0x3feea09e667f3bcd,
    0x3fee9f75e8ec5f74,
    0x3feea11473eb0187,
    0x3feea589994cce13,
    0x3feeace5422aa0db,
    0x3feeb737b0cdc5e5,
    0x3feec49182a3f090,
    0x3feed503b23e255d,
    0x3feee89f995ad3ad,
    0x3feeff76f2fb5e47,
    0x3fef199bdd85529c,
    0x3fef3720dcef9069,
    0x3fef5818dcfba487,
    0x3fef7c97337b9b5f,
    0x3fefa4afa2a490da,
    0x3fefd0765b6e4540,
];
/// The top 12 bits of `88.0f32`: inputs at or above it in magnitude take the slow path.
const TOP12_88: u32 = 0x42a;

/// Which build of glibc's `expf` to reproduce: the one glibc picks on this CPU
/// ([`Flavor::detect`]), or the one without FMA ([`Flavor::PLAIN`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Flavor(Build);

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Build {
    /// `__expf_fma`, what glibc runs on a CPU with FMA and AVX2. Only [`Flavor::detect`] makes
    /// it, after checking the CPU: the functions compiled with FMA rely on that.
    Fma,
    /// `__expf_sse2`, every operation rounded on its own.
    Plain,
    /// Not x86_64: the platform's `f32::exp`.
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    Platform,
}

impl Flavor {
    /// glibc's build without FMA (any CPU).
    pub const PLAIN: Flavor = Flavor(Build::Plain);

    /// The build glibc picks on this CPU (the platform's own `expf` off x86_64).
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("fma")
                && std::arch::is_x86_feature_detected!("avx2")
            {
                Flavor(Build::Fma)
            } else {
                Flavor(Build::Plain)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        Flavor(Build::Platform)
    }

    /// Whether this is the FMA build.
    pub fn is_fma(self) -> bool {
        self.0 == Build::Fma
    }
}

/// Whether `x` needs glibc's slow path (`|x| >= 88`, infinite or NaN).
#[inline(always)]
fn is_special(x: f32) -> bool {
    (x.to_bits() >> 20) & 0x7ff >= TOP12_88
}

/// `2^(k/32)` for the integer `k` in the low bits of `ki`.
#[inline(always)]
fn scale(ki: u64) -> f64 {
    f64::from_bits(TABLE[(ki % 32) as usize].wrapping_add(ki << 47))
}

/// The main path of `__expf_fma` (valid for `|x| < 88`).
#[inline(always)]
fn core_fma(x: f32) -> f32 {
    let xd = f64::from(x);
    let kd = INV_LN2_N.mul_add(xd, SHIFT);
    let ki = kd.to_bits();
    let kd = kd - SHIFT;
    let r = INV_LN2_N.mul_add(xd, -kd);
    let s = scale(ki);
    let z = C0.mul_add(r, C1);
    let r2 = r * r;
    let y = C2.mul_add(r, 1.0);
    let y = z.mul_add(r2, y);
    (y * s) as f32
}

/// The main path of `__expf_sse2` (valid for `|x| < 88`).
#[inline(always)]
fn core_plain(x: f32) -> f32 {
    let z = INV_LN2_N * f64::from(x);
    let kd = z + SHIFT;
    let ki = kd.to_bits();
    let kd = kd - SHIFT;
    let r = z - kd;
    let s = scale(ki);
    let y = (C0 * r + C1) * (r * r) + (C2 * r + 1.0);
    (y * s) as f32
}

/// glibc's slow path for `|x| >= 88`, infinities and NaN (`core` is the main path, which it
/// falls back to between the overflow and underflow bounds).
#[inline(never)]
fn special(x: f32, core: impl Fn(f32) -> f32) -> f32 {
    if x == f32::NEG_INFINITY {
        return 0.0;
    }
    if (x.to_bits() >> 20) & 0x7ff >= 0x7f8 {
        return x + x;
    }
    // `__math_oflowf`, `__math_uflowf`, `__math_may_uflowf`: a square that over- or underflows
    // at run time (so flush-to-zero mode applies to it as it does in glibc).
    let square = |bits: u32| {
        let y = std::hint::black_box(f32::from_bits(bits));
        y * y
    };
    if x > f32::from_bits(0x42b1_7217) {
        return square(0x7000_0000); // 2^97
    }
    if x < f32::from_bits(0xc2cf_f1b4) {
        return square(0x1000_0000); // 2^-95
    }
    if x < f32::from_bits(0xc2ce_8ecf) {
        return square(0x1a20_0000); // 1.25 * 2^-75
    }
    core(x)
}

/// `expf(x)` as glibc computes it with `flavor`.
#[inline]
pub fn expf(x: f32, flavor: Flavor) -> f32 {
    match flavor.0 {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `Build::Fma` is only made on a CPU with FMA and AVX2.
        Build::Fma => unsafe { one_fma(x) },
        #[cfg(not(target_arch = "x86_64"))]
        Build::Fma => unreachable!("the FMA build is only detected on x86_64"),
        Build::Plain if is_special(x) => special(x, core_plain),
        Build::Plain => core_plain(x),
        Build::Platform => x.exp(),
    }
}

/// Writes `expf(x)`, as glibc computes it with `flavor`, for every `x` of `xs` into `out`
/// (of the same length): the main path for all of them in one vectorized loop, then the rare
/// special inputs again one by one.
///
/// # Panics
/// When `out` is shorter than `xs`.
pub fn expf_slice(xs: &[f32], out: &mut [f32], flavor: Flavor) {
    let out = &mut out[..xs.len()];
    match flavor.0 {
        #[cfg(target_arch = "x86_64")]
        Build::Fma => {
            if std::arch::is_x86_feature_detected!("avx512f") {
                // SAFETY: the CPU has AVX-512F, and FMA and AVX2 (`Build::Fma` is only made
                // on a CPU with them).
                unsafe { slice_fma_avx512(xs, out) }
            } else {
                // SAFETY: `Build::Fma` is only made on a CPU with FMA and AVX2.
                unsafe { slice_fma_avx2(xs, out) }
            }
        }
        Build::Plain => main_then_special(xs, out, core_plain),
        _ => {
            for (o, &x) in out.iter_mut().zip(xs) {
                *o = expf(x, flavor);
            }
        }
    }
}

/// [`expf`] for [`Flavor::Fma`], compiled with FMA so `mul_add` is one instruction.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn one_fma(x: f32) -> f32 {
    if is_special(x) {
        special(x, core_fma)
    } else {
        core_fma(x)
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
fn slice_fma_avx512(xs: &[f32], out: &mut [f32]) {
    main_then_special(xs, out, core_fma);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn slice_fma_avx2(xs: &[f32], out: &mut [f32]) {
    main_then_special(xs, out, core_fma);
}

/// The main path over the whole slice (branch-free, so the compiler vectorizes it, table
/// lookups included), then glibc's slow path for the special inputs.
#[inline(always)]
fn main_then_special(xs: &[f32], out: &mut [f32], core: impl Fn(f32) -> f32 + Copy) {
    let mut any_special = false;
    for (o, &x) in out.iter_mut().zip(xs) {
        any_special |= is_special(x);
        *o = core(x);
    }
    if any_special {
        for (o, &x) in out.iter_mut().zip(xs) {
            if is_special(x) {
                *o = special(x, core);
            }
        }
    }
}
