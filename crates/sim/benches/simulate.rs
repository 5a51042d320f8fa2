//! Simulator throughput: simulated time per wall time for single trials (no files) and for a
//! small dataset written to disk (AEDAT4 with LZ4, truth CSVs, manifest).
//!
//! Throughput is reported in elements per second where one element is one simulated
//! millisecond: `1 Kelem/s` = 1 simulated second per wall second.
//!
//! `nice cargo bench -p evtac-sim --bench simulate -- --warm-up-time 1 --measurement-time 3`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use evtac_sim::{DatasetConfig, Protocol, Scale, SimParams, Simulator, plan, simulate_dataset};

fn trials(c: &mut Criterion) {
    let params = SimParams::default();
    let sim = Simulator::new(params.clone(), 1);
    let base = plan(Protocol::Exp1, Scale::Tiny, 1, &params.timeline).remove(0);
    let mut group = c.benchmark_group("trial");
    group.sample_size(10);
    for (speed, depth) in [(2.0, 1.0), (6.0, 2.0), (10.0, 3.0)] {
        let mut spec = base.clone();
        spec.speed_deg_s = speed;
        spec.depth_mm = depth;
        let duration_ms = sim.simulate(&spec).duration_us / 1000;
        group.throughput(Throughput::Elements(duration_ms as u64));
        group.bench_function(format!("speed{speed}_depth{depth}"), |b| {
            b.iter(|| sim.simulate(&spec))
        });
    }
    group.finish();
}

fn dataset(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let config = DatasetConfig {
        limit: Some(4),
        ..DatasetConfig::new(Protocol::Exp1, Scale::Tiny, 1)
    };
    let manifest = simulate_dataset(&config, dir.path(), |_| {}).expect("dataset");
    let simulated_ms: i64 = manifest
        .trials
        .iter()
        .map(|t| (t.motion_end_us + 300_000) / 1000)
        .sum();
    let mut group = c.benchmark_group("dataset");
    group.sample_size(10);
    group.throughput(Throughput::Elements(simulated_ms as u64));
    group.bench_function("exp1_tiny_4_trials_to_disk", |b| {
        b.iter(|| simulate_dataset(&config, dir.path(), |_| {}).expect("dataset"))
    });
    group.finish();
}

criterion_group!(benches, trials, dataset);
criterion_main!(benches);
