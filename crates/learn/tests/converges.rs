//! Whole runs against PyTorch: 100 epochs on the same features from the same initial weights,
//! over 5 seeds, end with a best validation MAE within the seeds' spread of PyTorch's.
//!
//! The step-by-step test (`pytorch.rs`) holds the math to PyTorch's for 20 steps; over 6,300
//! steps rounding differences grow into different trajectories (PyTorch's own AdamW
//! implementations round differently from each other), so what must agree is the outcome: the
//! mean best validation MAE of the two over the same 5 seeds may differ by no more than the
//! larger of their spreads across seeds (sample SD). The shuffling is each tool's own, seeded.
//!
//! The data are synthetic but learnable: sparse features like the pooled representations
//! (20 % non-zero, in [0, 1)) and two labels in about +-20 degrees that are a smooth function of
//! them, from an integer hash both languages could compute, written to files for PyTorch.
//! Needs `torch` in the reference Python (`bash .ci/python-env`); skipped outside CI without it.

use std::path::Path;

use evtac_learn::model::{INPUTS, LAYERS, OUTPUTS};
use evtac_learn::{FeatureSet, Parameters, TrainConfig, train};

/// Samples in the training and validation sets: small, so that 5 x 100 epochs of both tools
/// take seconds (each run is 3,200 steps).
const TRAIN: usize = 1_000;
const VAL: usize = 250;
const EPOCHS: usize = 100;
const SEEDS: u64 = 5;

/// Knuth's multiplicative hash of `n`, in [0, 1).
fn u(n: u64) -> f64 {
    (n.wrapping_mul(2_654_435_761) % 4_294_967_296) as f64 / 4_294_967_296.0
}

/// `n` samples starting at sample `first`: features 20 % non-zero, and labels
/// `20 tanh(a . x / 4)`, `20 tanh(b . x / 4)` for fixed hashed directions `a`, `b` in [-1, 1).
fn samples(first: u64, n: usize) -> FeatureSet {
    let direction = |k: u64| -> Vec<f64> {
        (0..INPUTS as u64)
            .map(|i| 2.0 * u(90_000_000 + k * 10_000 + i) - 1.0)
            .collect()
    };
    let (a, b) = (direction(0), direction(1));
    let mut features = Vec::with_capacity(n * INPUTS);
    let mut labels = Vec::with_capacity(n * OUTPUTS);
    for s in first..first + n as u64 {
        let row: Vec<f32> = (0..INPUTS as u64)
            .map(|i| {
                let k = s * INPUTS as u64 + i;
                if u(k + 50_000_000) < 0.2 {
                    u(k) as f32
                } else {
                    0.0
                }
            })
            .collect();
        let dot = |d: &[f64]| -> f64 { row.iter().zip(d).map(|(&x, &w)| f64::from(x) * w).sum() };
        labels.push((20.0 * (dot(&a) / 4.0).tanh()) as f32);
        labels.push((20.0 * (dot(&b) / 4.0).tanh()) as f32);
        features.extend(row);
    }
    FeatureSet::with_width(features, labels, INPUTS).expect("valid set")
}

/// Writes `values` as little-endian f32 (numpy's `fromfile` reads them back).
fn write_f32(path: &Path, values: &[f32]) {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(path, bytes).expect("write");
}

/// PyTorch's side: per seed, the initial weights from `dir/init<seed>_<layer>_{w,b}.f32`,
/// the paper's recipe (AdamW lr 5e-3, weight decay 1e-4, SmoothL1 beta 1, batch 32, shuffled
/// with `torch.randperm` under `manual_seed(seed)`), the best validation MAE over the epochs
/// (the mean absolute error over pitch and roll, as `evtac_learn::mae`'s overall).
const SCRIPT: &str = r#"
import sys
import numpy as np
import torch
torch.set_num_threads(1)
torch.set_flush_denormal(True)
d, train_n, val_n, epochs, seeds = sys.argv[1], *map(int, sys.argv[2:6])
sizes = [900, 256, 128, 64, 2]
load = lambda name, shape: torch.from_numpy(np.fromfile(f"{d}/{name}", dtype="<f4").reshape(shape))
xt, yt = load("train_x.f32", (train_n, 900)), load("train_y.f32", (train_n, 2))
xv, yv = load("val_x.f32", (val_n, 900)), load("val_y.f32", (val_n, 2))
for seed in range(seeds):
    layers = []
    for k in range(4):
        lin = torch.nn.Linear(sizes[k], sizes[k + 1])
        with torch.no_grad():
            lin.weight.copy_(load(f"init{seed}_{k}_w.f32", (sizes[k + 1], sizes[k])))
            lin.bias.copy_(load(f"init{seed}_{k}_b.f32", (sizes[k + 1],)))
        layers.append(lin)
    model = torch.nn.Sequential(layers[0], torch.nn.ReLU(), layers[1], torch.nn.ReLU(),
                                layers[2], torch.nn.ReLU(), layers[3])
    opt = torch.optim.AdamW(model.parameters(), lr=5e-3, betas=(0.9, 0.999), eps=1e-8,
                            weight_decay=1e-4)
    loss_fn = torch.nn.SmoothL1Loss(beta=1.0)
    g = torch.Generator().manual_seed(seed)
    best = float("inf")
    for epoch in range(epochs):
        model.train()
        for batch in torch.randperm(train_n, generator=g).split(32):
            opt.zero_grad()
            loss_fn(model(xt[batch]), yt[batch]).backward()
            opt.step()
        with torch.no_grad():
            best = min(best, (model(xv) - yv).abs().mean().item())
    print(best)
"#;

/// Mean and sample SD.
fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

#[test]
fn a_hundred_epochs_end_within_the_seeds_spread_of_pytorch() {
    if evtac_testkit::python_with("torch").is_none() {
        return;
    }
    evtac_learn::flush_denormals();
    let dir = tempfile::tempdir().expect("tempdir");
    let (train_set, val_set) = (samples(0, TRAIN), samples(TRAIN as u64, VAL));
    for (name, set) in [("train", &train_set), ("val", &val_set)] {
        write_f32(&dir.path().join(format!("{name}_x.f32")), &set.features);
        write_f32(&dir.path().join(format!("{name}_y.f32")), &set.labels);
    }
    let started = std::time::Instant::now();
    let mut ours = Vec::new();
    for seed in 0..SEEDS {
        // `train` starts from `Parameters::init(seed)`: PyTorch starts from the same weights.
        let init = Parameters::init(seed);
        assert_eq!(init.layers.len(), LAYERS);
        for (k, layer) in init.layers.iter().enumerate() {
            write_f32(
                &dir.path().join(format!("init{seed}_{k}_w.f32")),
                &layer.weight,
            );
            write_f32(
                &dir.path().join(format!("init{seed}_{k}_b.f32")),
                &layer.bias,
            );
        }
        let cfg = TrainConfig {
            epochs: EPOCHS,
            seed,
            ..TrainConfig::default()
        };
        let trained = train(&train_set, &val_set, &cfg, |_| {}).expect("trains");
        ours.push(trained.best_val.overall);
    }
    let evtac_seconds = started.elapsed().as_secs_f64();
    let started = std::time::Instant::now();
    let args = [
        dir.path().to_str().expect("utf-8 temp path"),
        &TRAIN.to_string(),
        &VAL.to_string(),
        &EPOCHS.to_string(),
        &SEEDS.to_string(),
    ];
    let out = evtac_testkit::run_python(SCRIPT, &args).expect("python is available");
    let torch: Vec<f64> = out
        .lines()
        .map(|l| l.trim().parse().expect("a number per seed"))
        .collect();
    assert_eq!(torch.len(), SEEDS as usize, "{out}");
    let torch_seconds = started.elapsed().as_secs_f64();
    let ((m_ours, sd_ours), (m_torch, sd_torch)) = (mean_sd(&ours), mean_sd(&torch));
    eprintln!(
        "best validation MAE over {SEEDS} seeds: evtac {m_ours:.4} +- {sd_ours:.4} {ours:.4?}, \
         PyTorch {m_torch:.4} +- {sd_torch:.4} {torch:.4?} ({evtac_seconds:.1} s against \
         {torch_seconds:.1} s)"
    );
    // The data must be learnable, or the comparison says nothing: both far below the labels'
    // own mean absolute value (about 10 degrees).
    assert!(m_ours < 3.0 && m_torch < 3.0, "neither learned");
    assert!(
        (m_ours - m_torch).abs() <= sd_ours.max(sd_torch),
        "evtac {m_ours:.4} +- {sd_ours:.4} against PyTorch {m_torch:.4} +- {sd_torch:.4}"
    );
}
