//! Soak test: a long stream through the whole pipeline with flat memory and no allocation per
//! estimate, measured with a counting global allocator (this binary's only test, so nothing
//! else allocates meanwhile).
//!
//! Event time covered: `EVTAC_SOAK_SECS` seconds (default 20), replayed as fast as possible
//! (an hour of events: `EVTAC_SOAK_SECS=3600`, several minutes).

mod support;

use evtac_learn::Model;
use evtac_online::Estimator;
use evtac_online::pipeline::{self, Output, PipelineConfig};
use std::alloc::{GlobalAlloc, Layout, System};
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering::Relaxed};

/// Counts allocations and live bytes, then defers to the system allocator.
struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);
static LIVE_BYTES: AtomicI64 = AtomicI64::new(0);

// SAFETY: every method forwards to `System` with the caller's arguments unchanged; the counters
// are plain atomics that never allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Relaxed);
        LIVE_BYTES.fetch_add(layout.size() as i64, Relaxed);
        // SAFETY: forwarded as received.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE_BYTES.fetch_sub(layout.size() as i64, Relaxed);
        // SAFETY: forwarded as received.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Relaxed);
        LIVE_BYTES.fetch_add(new_size as i64 - layout.size() as i64, Relaxed);
        // SAFETY: forwarded as received.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Resident set size in bytes from `/proc/self/statm` (Linux), for the log.
fn rss_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096)
}

#[test]
fn memory_stays_flat_and_estimates_do_not_allocate() {
    let seconds: i64 = std::env::var("EVTAC_SOAK_SECS")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|&s| s > 2)
        .unwrap_or(20);
    let dir = tempfile::tempdir().unwrap();
    // The combined representation exercises both the accumulator and the window.
    let (_, repr) = support::representations()[2];
    support::seeded_bundle(dir.path(), 17, &repr, None);
    let model = Model::load(dir.path()).unwrap();
    // 100k events/s in 1 ms packets keeps the default run to a few seconds in the dev profile.
    let source = support::Synthetic::new(5, 100_000.0, 1000, seconds * 1_000_000);
    let estimator = Estimator::for_model(&model, support::SENSOR, 1000).unwrap();

    // Samples of (estimates so far, allocations so far, live bytes), taken on the calling
    // thread at fixed estimate counts into a preallocated buffer.
    let warm_up = 2000u64;
    let every = 1000u64;
    let mut samples: Vec<(u64, u64, i64)> = Vec::with_capacity((seconds as usize) + 16);
    let mut estimates = 0u64;
    let summary = pipeline::run(source, estimator, &PipelineConfig::default(), |out| {
        if let Output::Estimate(_) = out {
            estimates += 1;
            if estimates >= warm_up
                && estimates.is_multiple_of(every)
                && samples.len() < samples.capacity()
            {
                samples.push((
                    estimates,
                    ALLOCATIONS.load(Relaxed),
                    LIVE_BYTES.load(Relaxed),
                ));
            }
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    let (first, last) = (samples[0], samples[samples.len() - 1]);
    let steady_estimates = last.0 - first.0;
    let steady_allocations = last.1 - first.1;
    let growth = last.2 - first.2;
    eprintln!(
        "soak: {} s of events, {} estimates; after warm-up {} allocations over {} estimates, \
         live bytes {} -> {} ({:+}); RSS {:?} bytes\n{summary}",
        seconds,
        summary.estimates,
        steady_allocations,
        steady_estimates,
        first.2,
        last.2,
        growth,
        rss_bytes()
    );
    assert_eq!(summary.estimates, estimates);
    assert!(steady_estimates >= (seconds as u64 - 3) * 1000);
    // No allocation per estimate: a handful at most over the whole steady phase (a channel
    // registering a waiting thread, a chunk larger than any before).
    assert!(
        steady_allocations * 100 < steady_estimates,
        "{steady_allocations} allocations over {steady_estimates} estimates"
    );
    // Flat memory: live bytes after warm-up grow by less than 1 MiB however long the run.
    assert!(growth < 1 << 20, "live bytes grew by {growth}");
}
