//! Per-estimate latency at 1 ms intervals, for each representation (the paper's, the learned
//! fusions, and the time surface, histogram and voxel grid at their default settings), at a
//! realistic event rate (300k events/s, a NeuroTac in contact) and at 10x that.
//!
//! Two measurements per case:
//! - criterion, `estimate/<repr>/<rate>/<arrival>`: one iteration is one 1 ms interval of events
//!   handed to the [`Estimator`] (crop, representation update, advance, pool, MLP) in one
//!   packet or in ten 100 us packets: the processing cost of one interval on one core. The same
//!   iterations fill a latency histogram (from the arrival of the packet that made the estimate
//!   final, as `docs/online.md` defines it) whose median, P99 and max are printed, with the
//!   count of estimates over 1 ms.
//! - `pipeline/<repr>/<rate>`: 2 s of events replayed at recorded pace through the two-thread
//!   pipeline in 1 ms slices; prints the run's summary (latency as defined in docs/online.md).
//!   Printed first: how often, and for how long, the machine itself held up a busy thread over
//!   2 s (the floor under any latency tail measured on it).
//!
//! `EVTAC_BENCH_NO_PIPELINE=1` skips the pipeline runs (criterion's filter only selects among
//! the first kind).
//!
//! Run: `nice cargo bench -p evtac-online --bench latency -- --warm-up-time 1 --measurement-time 3`

#[path = "../tests/support/mod.rs"]
mod support;

use criterion::{Criterion, criterion_group, criterion_main};
use evtac_events::Event;
use evtac_learn::Model;
use evtac_online::input::{MemorySource, Paced};
use evtac_online::pipeline::{self, PipelineConfig};
use evtac_online::{Estimator, LatencyStats};
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

const RATES: [(&str, f64); 2] = [("300k", 300_000.0), ("3M", 3_000_000.0)];
const SPAN_US: i64 = 2_000_000;

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

/// How the events of each 1 ms interval arrive: all at once when the interval ends (the worst
/// case: every event of the interval is processed after the arrival that makes the estimate
/// final), or in 100 us packets as a live sensor streams them (only the last packet's events
/// are left to process when the estimate becomes final).
const ARRIVALS: [(&str, i64); 2] = [("1ms-packets", 1000), ("100us-packets", 100)];

fn estimate(c: &mut Criterion) {
    evtac_learn::flush_denormals();
    let mut group = c.benchmark_group("estimate");
    let kinds = support::representations()
        .into_iter()
        .chain(support::beyond_representations());
    for (name, repr) in kinds {
        let dir = tempfile::tempdir().expect("a temporary folder");
        support::seeded_bundle(dir.path(), 1, &repr, None);
        let model = Model::load(dir.path()).expect("the bundle loads");
        for (rate_name, rate) in RATES {
            let events = support::Synthetic::new(1, rate, 1000, SPAN_US).collect();
            for (arrival_name, packet_us) in ARRIVALS {
                // Packet `k` holds the events of `(k * packet_us, (k + 1) * packet_us]` (the
                // first one those at 0 too), so the packet ending at a multiple of 1 ms makes
                // that estimate final. Replayed in a loop with the clock moved on each lap.
                let bounds: Vec<usize> = (0..=SPAN_US / packet_us)
                    .map(|k| match k {
                        0 => 0,
                        k => events.partition_point(|e: &Event| e.t <= k * packet_us),
                    })
                    .collect();
                let per_interval = (1000 / packet_us) as usize;
                let mut estimator = Estimator::for_model(&model, support::SENSOR, 1000)
                    .expect("the estimator builds");
                let mut stats = LatencyStats::new(Duration::from_millis(1));
                let mut packet =
                    Vec::with_capacity(bounds.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0));
                let mut k = 0usize;
                let mut lap = 0i64;
                // One iteration is one interval: its packets handed to the estimator, each
                // vouching that every event up to its end has arrived (as a paced source
                // does), so the last one makes the interval's estimate final.
                let id = format!("{name}/{rate_name}/{arrival_name}");
                group.bench_function(&id, |b| {
                    b.iter_custom(|iters| {
                        let mut total = Duration::ZERO;
                        for _ in 0..iters {
                            for _ in 0..per_interval {
                                if k + 1 >= bounds.len() {
                                    k = 0;
                                    lap += 1;
                                }
                                packet.clear();
                                packet.extend(events[bounds[k]..bounds[k + 1]].iter().map(|e| {
                                    Event {
                                        t: e.t + lap * SPAN_US,
                                        ..*e
                                    }
                                }));
                                let horizon = (k as i64 + 1) * packet_us + lap * SPAN_US;
                                k += 1;
                                let arrival = Instant::now();
                                estimator
                                    .process(&packet, Some(horizon), arrival, &mut |e| {
                                        stats.record(e.latency)
                                    })
                                    .expect("the estimator accepts the packet");
                                total += arrival.elapsed();
                            }
                        }
                        total
                    });
                });
                eprintln!(
                    "estimate/{id}: {} estimates, median {:.1} us, P99 {:.1} us, \
                     max {:.1} us, over 1 ms: {}",
                    stats.count(),
                    us(stats.quantile(0.5)),
                    us(stats.quantile(0.99)),
                    us(stats.max()),
                    stats.late()
                );
            }
        }
    }
    group.finish();
}

/// The machine's own interruptions, for reading the pipeline's tail and late counts: a thread
/// that does nothing but read the clock for 2 s, and the longest gaps between two reads (time
/// the thread did not run: interrupts, other processes, on a VM the hypervisor).
fn machine_stalls() {
    let start = Instant::now();
    let mut last = start;
    let mut gaps = LatencyStats::new(Duration::from_millis(1));
    while last - start < Duration::from_secs(2) {
        let now = Instant::now();
        let gap = now - last;
        if gap > Duration::from_micros(20) {
            gaps.record(gap);
        }
        last = now;
    }
    eprintln!(
        "machine: a thread reading the clock for 2 s was held up {} times over 20 us, \
         {} over 1 ms, longest {:.1} us",
        gaps.count(),
        gaps.late(),
        us(gaps.max())
    );
}

fn paced_pipeline(_c: &mut Criterion) {
    if std::env::var_os("EVTAC_BENCH_NO_PIPELINE").is_some() {
        return;
    }
    machine_stalls();
    for (name, repr) in support::representations() {
        let dir = tempfile::tempdir().expect("a temporary folder");
        support::seeded_bundle(dir.path(), 1, &repr, None);
        let model = Model::load(dir.path()).expect("the bundle loads");
        for ((rate_name, rate), busy_poll) in
            RATES.into_iter().flat_map(|r| [(r, false), (r, true)])
        {
            let events = support::Synthetic::new(2, rate, 1000, SPAN_US).collect();
            let source = Paced::new(MemorySource::new(events, 1 << 16), 1000);
            let estimator =
                Estimator::for_model(&model, support::SENSOR, 1000).expect("the estimator builds");
            let config = PipelineConfig {
                busy_poll,
                ..PipelineConfig::default()
            };
            let summary = pipeline::run(source, estimator, &config, |_| ControlFlow::Continue(()))
                .expect("the replay runs");
            let mode = if busy_poll { "busy-poll" } else { "sleeping" };
            eprintln!(
                "pipeline/{name}/{rate_name}/{mode} (2 s at recorded pace): {} estimates, median {:.1} us, \
                 P99 {:.1} us, max {:.1} us, late {}, dropped {}",
                summary.estimates,
                us(summary.median),
                us(summary.p99),
                us(summary.max),
                summary.late,
                summary.events_dropped
            );
        }
    }
}

criterion_group!(benches, estimate, paced_pipeline);
criterion_main!(benches);
