//! Training speed: one AdamW step on a batch of 32 and one full epoch over 35,000 x 900 samples
//! (the paper-sized Experiment 1 training set), on burn's flex backend.
//!
//! The PyTorch CPU reference for the same model is `benches/pytorch_baseline.py`; run both in
//! the same session and compare:
//!
//! ```text
//! nice cargo bench -p evtac-learn --bench training -- --warm-up-time 1 --measurement-time 3
//! .venv/bin/python crates/learn/benches/pytorch_baseline.py
//! ```

use std::hint::black_box;

/// The allocator the `evtac` binary uses: burn allocates and frees megabyte tensors every step,
/// and glibc's malloc returns them to the kernel each time (2.5x slower steps, page faults).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use evtac_learn::data::Shuffler;
use evtac_learn::{FeatureSet, Parameters, TrainConfig, Trainer};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Samples in the benchmark epoch (the paper's Experiment 1 training set is about this size).
const SAMPLES: usize = 35_000;

/// Sparse features like the binarised, pooled representations (about a quarter non-zero).
fn dataset(n: usize) -> FeatureSet {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let features = (0..n * 900)
        .map(|_| {
            if rng.random_range(0.0..1.0_f32) < 0.25 {
                rng.random_range(0.0..1.0_f32)
            } else {
                0.0
            }
        })
        .collect();
    let labels = (0..n * 2)
        .map(|_| rng.random_range(-20.0..20.0_f32))
        .collect();
    FeatureSet::new(features, labels).expect("valid")
}

fn bench(c: &mut Criterion) {
    evtac_learn::flush_denormals();
    let data = dataset(SAMPLES);
    let cfg = TrainConfig::default();
    let mut trainer = Trainer::new(&Parameters::init(0), &cfg).expect("trainer");
    let mut shuffler = Shuffler::new(data.len(), 0);
    let (mut x, mut y) = (Vec::new(), Vec::new());

    let order = shuffler.next_epoch().to_vec();
    let mut batches = order.chunks(32).cycle();
    c.bench_function("train_step_batch32", |b| {
        b.iter(|| {
            let batch = batches.next().unwrap_or(&[0]);
            data.gather(batch, &mut x, &mut y);
            black_box(trainer.step(&x, &y).expect("step"))
        })
    });

    let mut group = c.benchmark_group("epoch");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    group.bench_function("35000x900", |b| {
        b.iter(|| {
            let mut loss = 0.0;
            for batch in shuffler.next_epoch().chunks(32) {
                data.gather(batch, &mut x, &mut y);
                loss += trainer.step(&x, &y).expect("step");
            }
            black_box(loss)
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
