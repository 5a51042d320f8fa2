//! Throughput and per-sample latency of the static, dynamic and combined representations at a
//! 1 ms sampling interval on a realistic synthetic stream (~300k events/s over 240x240, seeded),
//! and the same measured in the same run for the paper's implementation style
//! (`benches/baseline.py`: dv-processing's Accumulator, a numpy sliding window).
//!
//! `nice cargo bench -p evtac-repr --bench represent -- --warm-up-time 1 --measurement-time 3`
//! prints criterion's throughput, then a table of latency (median, P99, max) and throughput for
//! evtac and the Python baseline, with ratios.

use criterion::{BenchmarkId, Criterion, Throughput};
use evtac_events::Event;
use evtac_repr::{FeatureExtractor, ReprConfig};
use std::hint::black_box;
use std::time::Instant;

#[path = "common/stream.rs"]
mod stream;
use stream::{DURATION_US, FRAME, STEP_US, samples, synthetic_stream};

fn configs() -> [(&'static str, ReprConfig); 3] {
    let ReprConfig::Combined {
        static_part,
        dynamic_part,
    } = ReprConfig::default()
    else {
        unreachable!("the default is combined")
    };
    [
        ("static", ReprConfig::Static(static_part)),
        ("dynamic", ReprConfig::Dynamic(dynamic_part)),
        ("combined", ReprConfig::default()),
    ]
}

/// One pass at 1 ms sampling: per sample, push that millisecond's events, advance, and copy the
/// features out (what an online estimator hands to the model). Returns per-sample nanoseconds.
fn pass(config: &ReprConfig, events: &[Event], samples: &[i64], lat: &mut Vec<u64>) -> f32 {
    let mut fx =
        FeatureExtractor::new(std::slice::from_ref(config), FRAME, None).expect("valid config");
    let mut features = vec![0.0f32; fx.feature_len(0)];
    let mut start = 0;
    let mut sum = 0.0;
    lat.clear();
    for &t_k in samples {
        let end = start + events[start..].partition_point(|e| e.t <= t_k);
        let t0 = Instant::now();
        fx.push(&events[start..end]).expect("events in order");
        fx.advance_to(t_k).expect("samples in order");
        features.copy_from_slice(fx.features(0));
        lat.push(t0.elapsed().as_nanos() as u64);
        sum += features[465];
        start = end;
    }
    sum
}

fn throughput(c: &mut Criterion, events: &[Event], samples: &[i64]) {
    let mut group = c.benchmark_group("represent_1ms");
    group.throughput(Throughput::Elements(events.len() as u64));
    group.sample_size(10);
    let mut lat = Vec::with_capacity(samples.len());
    for (name, config) in configs() {
        group.bench_with_input(BenchmarkId::from_parameter(name), &config, |b, config| {
            b.iter(|| black_box(pass(config, events, samples, &mut lat)))
        });
    }
    group.finish();
}

struct Row {
    median_us: f64,
    p99_us: f64,
    max_us: f64,
    events_per_s: f64,
}

fn stats(lat_ns: &mut [u64], events: usize) -> Row {
    lat_ns.sort_unstable();
    let us = |ns: u64| ns as f64 / 1e3;
    let n = lat_ns.len();
    let total_s = lat_ns.iter().sum::<u64>() as f64 / 1e9;
    Row {
        median_us: us(lat_ns[n / 2]),
        p99_us: us(lat_ns[(n * 99).div_ceil(100) - 1]),
        max_us: us(lat_ns[n - 1]),
        events_per_s: events as f64 / total_s,
    }
}

fn python_baseline(events: &[Event], samples: &[i64]) -> Option<Vec<(String, Row)>> {
    let python = evtac_testkit::python()?;
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/baseline.py");
    let stdout = stream::run_reference(&python, script, events, samples)?;
    let rows = stdout
        .lines()
        .filter_map(|line| serde_json::from_str::<serde_json::Value>(line).ok())
        .filter_map(|v| {
            let f = |k: &str| v[k].as_f64();
            Some((
                v["repr"].as_str()?.to_string(),
                Row {
                    median_us: f("median_us")?,
                    p99_us: f("p99_us")?,
                    max_us: f("max_us")?,
                    events_per_s: f("events_per_s")?,
                },
            ))
        })
        .collect();
    Some(rows)
}

fn latency_table(events: &[Event], samples: &[i64]) {
    let mut lat = Vec::with_capacity(samples.len() * 3);
    let mut rows = Vec::new();
    for (name, config) in configs() {
        // Three fresh passes (window filling up included), latencies pooled.
        let mut all = Vec::with_capacity(samples.len() * 3);
        for _ in 0..3 {
            black_box(pass(&config, events, samples, &mut lat));
            all.extend_from_slice(&lat);
        }
        rows.push((name, stats(&mut all, events.len() * 3)));
    }
    let baseline = python_baseline(events, samples).unwrap_or_default();
    let secs = DURATION_US as f64 / 1e6;
    println!(
        "\n{} events over {secs} s ({:.0} events/s), 240x240, sampled every {} ms ({} samples)\n",
        events.len(),
        events.len() as f64 / secs,
        STEP_US / 1000,
        samples.len()
    );
    println!(
        "| repr | impl | median (us) | P99 (us) | max (us) | throughput (Mevents/s) | speed-up (throughput) | speed-up (median) |"
    );
    println!("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (name, row) in &rows {
        let base = baseline.iter().find(|(n, _)| n == name).map(|(_, r)| r);
        let ratio = base.map_or("-".into(), |b| {
            format!("{:.0}x", row.events_per_s / b.events_per_s)
        });
        let median_ratio = base.map_or("-".into(), |b| {
            format!("{:.0}x", b.median_us / row.median_us)
        });
        println!(
            "| {name} | evtac | {:.1} | {:.1} | {:.1} | {:.1} | {ratio} | {median_ratio} |",
            row.median_us,
            row.p99_us,
            row.max_us,
            row.events_per_s / 1e6
        );
        if let Some(b) = base {
            println!(
                "| {name} | Python (dv-processing / numpy) | {:.1} | {:.1} | {:.1} | {:.2} | 1x | 1x |",
                b.median_us,
                b.p99_us,
                b.max_us,
                b.events_per_s / 1e6
            );
        }
    }
    if baseline.is_empty() {
        println!("(Python baseline skipped: no reference Python environment)");
    }
}

fn main() {
    let events = synthetic_stream(42);
    let samples = samples();
    let mut c = Criterion::default().configure_from_args();
    throughput(&mut c, &events, &samples);
    c.final_summary();
    // Only under `cargo bench` (which passes `--bench`), not when `cargo test` smoke-runs benches.
    if std::env::args().any(|a| a == "--bench") {
        latency_table(&events, &samples);
    }
}
