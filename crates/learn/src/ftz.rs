//! Flushing subnormal floats to zero (FTZ/DAZ) on the calling thread.
//!
//! AdamW's second moments decay geometrically towards zero and, in f32, end up subnormal for
//! parameters whose gradients vanish (dead ReLU units, masked-out pixels). x86 cores take a
//! microcode assist of ~100 cycles for every subnormal operand or result, which made every engine
//! measured for this model 2-14x slower late in training. Setting FTZ (results flushed) and DAZ
//! (inputs treated as zero) in MXCSR removes the assists; the numerical effect is below f32
//! resolution for this model (values under 1.2e-38 become 0).
//!
//! MXCSR is per thread: call [`flush_denormals`] at the start of every thread that trains or
//! infers. [`crate::train`] and [`crate::Predictor::new`] call it themselves for the calling
//! thread, and training also sets it on every thread of rayon's global pool (where the
//! experiments run their training jobs, and where burn's flex backend would run its matrix
//! products if its `rayon` feature were on).

/// MXCSR bit 15: flush-to-zero (subnormal results become zero).
#[cfg(target_arch = "x86_64")]
const MXCSR_FTZ: u32 = 1 << 15;
/// MXCSR bit 6: denormals-are-zero (subnormal inputs are read as zero).
#[cfg(target_arch = "x86_64")]
const MXCSR_DAZ: u32 = 1 << 6;

/// Sets flush-to-zero and denormals-are-zero for SSE/AVX arithmetic on the calling thread
/// (x86_64); does nothing on other architectures. Idempotent and cheap (two instructions).
///
/// ```
/// evtac_learn::flush_denormals();
/// let tiny = std::hint::black_box(1e-38_f32);
/// # #[cfg(target_arch = "x86_64")]
/// assert_eq!(tiny / 1e3, 0.0); // a subnormal result, flushed
/// ```
pub fn flush_denormals() {
    #[cfg(target_arch = "x86_64")]
    write_mxcsr(read_mxcsr() | MXCSR_FTZ | MXCSR_DAZ);
}

/// Runs [`flush_denormals`] on every thread of rayon's global pool (where burn's flex backend and
/// `gemm` run their parallel kernels), creating the pool if needed. Rayon's pool threads live as
/// long as the process, so once is enough; calling again is harmless.
pub fn flush_denormals_in_rayon_pool() {
    rayon::broadcast(|_| flush_denormals());
}

/// Whether FTZ and DAZ are both set on the calling thread (always `false` off x86_64).
pub fn denormals_flushed() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        read_mxcsr() & (MXCSR_FTZ | MXCSR_DAZ) == MXCSR_FTZ | MXCSR_DAZ
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The calling thread's MXCSR. Inline assembly because `_mm_getcsr` is deprecated.
#[cfg(target_arch = "x86_64")]
fn read_mxcsr() -> u32 {
    let mut csr: u32 = 0;
    // SAFETY: `stmxcsr` stores the 4-byte MXCSR to the given address, which is a live, aligned,
    // writable `u32` on this stack frame; SSE is part of the x86_64 baseline.
    unsafe {
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack, preserves_flags));
    }
    csr
}

/// Loads `csr` into the calling thread's MXCSR.
#[cfg(target_arch = "x86_64")]
fn write_mxcsr(csr: u32) {
    // SAFETY: `ldmxcsr` reads 4 bytes from a live, aligned `u32`. The value written is the current
    // MXCSR with only FTZ/DAZ added (callers above), so exception masks and rounding mode are
    // unchanged and no floating-point exception can be unmasked; flushing subnormals changes
    // results below 1.2e-38 only and no Rust invariant depends on them.
    unsafe {
        core::arch::asm!("ldmxcsr [{}]", in(reg) &csr, options(nostack, preserves_flags, readonly));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_the_flags_on_the_calling_thread_only() {
        std::thread::spawn(|| {
            flush_denormals();
            assert_eq!(denormals_flushed(), cfg!(target_arch = "x86_64"));
            let tiny = std::hint::black_box(1e-38_f32);
            if cfg!(target_arch = "x86_64") {
                assert_eq!(tiny / 1e3, 0.0);
            }
        })
        .join()
        .expect("thread ran");
        std::thread::spawn(|| {
            // The flags belong to the thread that set them (new threads copy their parent's MXCSR,
            // and this test's thread never set them): subnormals are kept here.
            let tiny = std::hint::black_box(1e-38_f32);
            assert!(tiny / 1e3 > 0.0);
        })
        .join()
        .expect("thread ran");
    }
}
