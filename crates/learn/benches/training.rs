//! Training speed: one AdamW step on a batch of 32, one full epoch over 35,000 x 900 samples
//! (the paper-sized Experiment 1 training set), and one epoch each of two runs side by side on
//! two threads (how `evtac reproduce` and `tune` use a 2-core machine: one run per core). The
//! last one is the machine's throughput to set against PyTorch on 2 threads.
//!
//! The learned fusions (`stacked`, `late`) train on 1800 features per sample, a static frame
//! then a dynamic one at their own densities: `epoch_35000x1800/{stacked,late}` times one epoch
//! of each network, to set against the 900-feature epochs above.
//!
//! The PyTorch CPU reference for the same model is `benches/pytorch_baseline.py`; run both in
//! the same session and compare:
//!
//! ```text
//! nice cargo bench -p evtac-learn --bench training -- --warm-up-time 1 --measurement-time 3
//! .venv/bin/python crates/learn/benches/pytorch_baseline.py
//! ```

use std::hint::black_box;

/// The allocator the `evtac` binary uses, so the figures are the binary's (a training step
/// allocates nothing now, but the 126 MB data set and the epoch's order do).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use evtac_learn::data::Shuffler;
use evtac_learn::{Architecture, FeatureSet, Parameters, TrainConfig, Trainer};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Samples in the benchmark epoch (the paper's Experiment 1 training set is about this size).
const SAMPLES: usize = 35_000;

/// Validation samples an epoch predicts (the paper-sized Experiment 1's validation set).
const VALIDATION: usize = 7_500;

/// Fractions of non-zero features, measured on the pooled features of a simulated Experiment 1
/// trial (`evtac simulate --protocol exp1 --scale tiny --seed 0`, trial t0000, every 2 ms of the
/// motion, default settings): static 0.138; dynamic and combined 0.752 (a 640 ms window at
/// count threshold 0 keeps the background noise of most cells). The paper's tuning grid is
/// denser still at count threshold 0: every static tau gives 95.6-95.8 % non-zero on the
/// paper-scale Experiment 1 (`docs/performance.md`), a fifth of the static grid. Training skips
/// zero inputs, so its speed depends on them; PyTorch's does not.
const DENSITIES: [(&str, f32); 3] = [
    ("static", 0.138),
    ("dynamic_combined", 0.752),
    ("threshold0", 0.958),
];

/// Features of one frame per entry of `densities` side by side, each frame's a fraction
/// `density` non-zero, uniform in [0, 1), and labels in +-20 degrees.
fn dataset(n: usize, densities: &[f32]) -> FeatureSet {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let width = 900 * densities.len();
    let mut features = Vec::with_capacity(n * width);
    for _ in 0..n {
        for &density in densities {
            features.extend((0..900).map(|_| {
                if rng.random_range(0.0..1.0_f32) < density {
                    rng.random_range(0.0..1.0_f32)
                } else {
                    0.0
                }
            }));
        }
    }
    let labels = (0..n * 2)
        .map(|_| rng.random_range(-20.0..20.0_f32))
        .collect();
    FeatureSet::with_width(features, labels, width).expect("valid")
}

fn bench(c: &mut Criterion) {
    evtac_learn::flush_denormals();
    let cfg = TrainConfig::default();
    for (name, density) in DENSITIES {
        let data = dataset(SAMPLES, &[density]);
        let mut trainer = Trainer::new(&Parameters::init(0), &cfg).expect("trainer");
        let mut shuffler = Shuffler::new(data.len(), 0);
        let (mut x, mut y) = (Vec::new(), Vec::new());

        let order = shuffler.next_epoch().to_vec();
        let mut batches = order.chunks(32).cycle();
        c.bench_function(&format!("train_step_batch32/{name}"), |b| {
            b.iter(|| {
                let batch = batches.next().unwrap_or(&[0]);
                data.gather(batch, &mut x, &mut y);
                black_box(trainer.step(&x, &y).expect("step"))
            })
        });

        let mut group = c.benchmark_group(format!("epoch_35000x900/{name}"));
        group.sample_size(10);
        group.measurement_time(Duration::from_secs(10));
        group.bench_function("one_run", |b| {
            b.iter(|| black_box(epoch(&mut trainer, &mut shuffler, &data)))
        });

        // Two runs of a sweep side by side, one per core: each iteration is one epoch of each
        // run (70,000 sample-passes), the way the experiments fill a 2-core machine.
        let mut pair: Vec<_> = (0..2_u64)
            .map(|seed| {
                let cfg = TrainConfig {
                    seed,
                    ..TrainConfig::default()
                };
                let trainer = Trainer::new(&Parameters::init(seed), &cfg).expect("trainer");
                (trainer, Shuffler::new(data.len(), seed))
            })
            .collect();
        // Validation's forward pass over an epoch's 7,500 validation samples (the paper-sized
        // Experiment 1's), the first layer a group of samples at a time.
        let (mut validation, mut validation_labels) = (Vec::new(), Vec::new());
        let rows: Vec<usize> = (0..VALIDATION).collect();
        data.gather(&rows, &mut validation, &mut validation_labels);
        group.bench_function("validation_7500", |b| {
            b.iter(|| black_box(trainer.predict(&validation).expect("predict")))
        });

        group.bench_function("two_runs_on_two_threads", |b| {
            b.iter(|| {
                std::thread::scope(|scope| {
                    for (trainer, shuffler) in &mut pair {
                        let data = &data;
                        scope.spawn(move || {
                            evtac_learn::flush_denormals();
                            black_box(epoch(trainer, shuffler, data))
                        });
                    }
                })
            })
        });
        group.finish();
    }

    // The learned fusions: a static frame and a dynamic frame per sample.
    let data = dataset(SAMPLES, &[DENSITIES[0].1, DENSITIES[1].1]);
    let mut group = c.benchmark_group("epoch_35000x1800");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    for architecture in [Architecture::Stacked, Architecture::Late] {
        let cfg = TrainConfig {
            architecture,
            ..TrainConfig::default()
        };
        let params = Parameters::init_for(architecture, 0);
        let mut trainer = Trainer::new(&params, &cfg).expect("trainer");
        let mut shuffler = Shuffler::new(data.len(), 0);
        group.bench_function(architecture.name(), |b| {
            b.iter(|| black_box(epoch(&mut trainer, &mut shuffler, &data)))
        });
    }
    group.finish();
}

/// One epoch of `trainer` over `data`; returns the summed batch losses.
fn epoch(trainer: &mut Trainer, shuffler: &mut Shuffler, data: &FeatureSet) -> f32 {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    let mut loss = 0.0;
    for batch in shuffler.next_epoch().chunks(32) {
        data.gather(batch, &mut x, &mut y);
        loss += trainer.step(&x, &y).expect("step");
    }
    loss
}

criterion_group!(benches, bench);
criterion_main!(benches);
