//! Per-sample cost of the time surface, the polarity histogram and the voxel grid at a 1 ms
//! sampling interval on the benches' synthetic stream (~300k events/s over 240x240, seeded),
//! against tonic 1.7's functional transforms on the same events in the same run
//! (`benches/dense_reference.py`).
//!
//! `nice cargo bench -p evtac-repr --bench dense -- --warm-up-time 1 --measurement-time 3`
//! prints criterion's throughput, then a table of per-sample latency (median, P99) and
//! throughput for evtac and tonic, with ratios. evtac's sample is what an estimator does: push
//! the millisecond's events, advance, copy the pooled features out. tonic's is its frame at the
//! sample and numpy's 8x8 mean over it (how each is asked of tonic: the reference's docs).

use criterion::{BenchmarkId, Criterion, Throughput};
use evtac_events::Event;
use evtac_repr::{
    DenseConfig, DenseExtractor, HistogramConfig, TimeSurfaceConfig, VoxelGridConfig,
};
use std::hint::black_box;
use std::time::Instant;

#[path = "common/stream.rs"]
mod stream;
use stream::{DURATION_US, FRAME, STEP_US, samples, synthetic_stream};

/// The settings timed: the paper's dynamic window's order of magnitude for the windows, and a
/// tau a tenth of the paper's static one.
fn configs() -> [(&'static str, DenseConfig); 4] {
    [
        (
            "time-surface",
            DenseConfig::TimeSurface(TimeSurfaceConfig {
                tau_ms: 100.0,
                threshold: None,
            }),
        ),
        (
            "time-surface-binary",
            DenseConfig::TimeSurface(TimeSurfaceConfig {
                tau_ms: 100.0,
                threshold: Some(0.5),
            }),
        ),
        (
            "histogram",
            DenseConfig::Histogram(HistogramConfig { window_ms: 100.0 }),
        ),
        (
            "voxel-grid",
            DenseConfig::VoxelGrid(VoxelGridConfig {
                window_ms: 100.0,
                bins: 5,
            }),
        ),
    ]
}

/// One pass: per sample, push the events before it, advance, copy the features out. Returns
/// per-sample nanoseconds in `lat`.
fn pass(config: DenseConfig, events: &[Event], samples: &[i64], lat: &mut Vec<u64>) -> f32 {
    let mut fx = DenseExtractor::new(config, FRAME).expect("valid config");
    let mut features = vec![0.0f32; fx.feature_len()];
    let (mut start, mut sum) = (0, 0.0);
    lat.clear();
    for &t_k in samples {
        let end = start + events[start..].partition_point(|e| e.t < t_k);
        let t0 = Instant::now();
        fx.push(&events[start..end]).expect("events in order");
        fx.advance_to(t_k).expect("samples in order");
        features.copy_from_slice(fx.features());
        lat.push(t0.elapsed().as_nanos() as u64);
        sum += features[465];
        start = end;
    }
    sum
}

fn throughput(c: &mut Criterion, events: &[Event], samples: &[i64]) {
    let mut group = c.benchmark_group("dense_1ms");
    group.throughput(Throughput::Elements(events.len() as u64));
    group.sample_size(10);
    let mut lat = Vec::with_capacity(samples.len());
    for (name, config) in configs() {
        group.bench_with_input(BenchmarkId::from_parameter(name), &config, |b, config| {
            b.iter(|| black_box(pass(*config, events, samples, &mut lat)))
        });
    }
    group.finish();
}

/// Median and P99 per sample in microseconds, and events per second over the summed samples.
fn stats(lat_ns: &mut [u64], events: usize) -> (f64, f64, f64) {
    lat_ns.sort_unstable();
    let n = lat_ns.len();
    let total_s = lat_ns.iter().sum::<u64>() as f64 / 1e9;
    (
        lat_ns[n / 2] as f64 / 1e3,
        lat_ns[(n * 99).div_ceil(100) - 1] as f64 / 1e3,
        events as f64 / total_s,
    )
}

/// tonic's rows from `dense_reference.py`: name -> (median us, P99 us, events/s).
fn tonic(events: &[Event], samples: &[i64]) -> Vec<(String, (f64, f64, f64))> {
    let Some(python) = evtac_testkit::python_with("tonic") else {
        return Vec::new();
    };
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/dense_reference.py");
    let Some(stdout) = stream::run_reference(&python, script, events, samples) else {
        return Vec::new();
    };
    stdout
        .lines()
        .filter_map(|line| {
            let mut it = line.split_whitespace();
            let name = it.next()?.to_string();
            let mut f = || it.next()?.parse::<f64>().ok();
            Some((name, (f()?, f()?, f()?)))
        })
        .collect()
}

fn table(events: &[Event], samples: &[i64]) {
    let reference = tonic(events, samples);
    let secs = DURATION_US as f64 / 1e6;
    println!(
        "\n{} events over {secs} s, 240x240, sampled every {} ms ({} samples)\n",
        events.len(),
        STEP_US / 1000,
        samples.len()
    );
    println!(
        "| kind | evtac median / P99 (us) | evtac Mev/s | tonic median / P99 (us) | tonic Mev/s | ratio (median) | ratio (throughput) |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    let mut lat = Vec::with_capacity(samples.len());
    for (name, config) in configs() {
        let mut all = Vec::with_capacity(samples.len() * 3);
        for _ in 0..3 {
            black_box(pass(config, events, samples, &mut lat));
            all.extend_from_slice(&lat);
        }
        let (median, p99, rate) = stats(&mut all, events.len() * 3);
        let theirs = reference.iter().find(|(n, _)| n == name).map(|(_, r)| *r);
        let cell = |r: Option<(f64, f64, f64)>, f: &dyn Fn((f64, f64, f64)) -> String| {
            r.map_or("-".to_string(), f)
        };
        println!(
            "| {name} | {median:.1} / {p99:.1} | {:.1} | {} | {} | {} | {} |",
            rate / 1e6,
            cell(theirs, &|t| format!("{:.1} / {:.1}", t.0, t.1)),
            cell(theirs, &|t| format!("{:.2}", t.2 / 1e6)),
            cell(theirs, &|t| format!("{:.0}x", t.0 / median)),
            cell(theirs, &|t| format!("{:.0}x", rate / t.2)),
        );
    }
    if reference.is_empty() {
        println!("(tonic skipped: no reference Python environment with tonic)");
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
        table(&events, &samples);
    }
}
