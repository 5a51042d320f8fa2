//! A cache prefetch hint for the per-pixel state of upcoming events.
//!
//! Events hit pixels at random, so each one misses the cache on the accumulator's potential and
//! time and on the window's count (profiled: those loads were the largest cost of
//! `advance_to`). The pending queue tells which pixels come next, so the extractor asks for
//! them a few events ahead. No crate offers a stable, safe prefetch; this is the one `unsafe`
//! line of the crate.

/// Hints the CPU to bring `slice[index]` into the cache; does nothing off x86_64 or when `index`
/// is out of bounds.
#[inline(always)]
pub(crate) fn prefetch<T>(slice: &[T], index: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(item) = slice.get(index) {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: `_mm_prefetch` is SSE (baseline on x86_64) and only hints the cache: it never
        // dereferences the pointer architecturally and cannot fault; the pointer is in bounds
        // anyway.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(item).cast::<i8>()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (slice, index);
}
