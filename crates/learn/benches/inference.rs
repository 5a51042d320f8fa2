//! Single-sample inference latency of the hand-written [`Predictor`], plus a tail-latency table
//! (median, P99, P99.9) printed before criterion's runs. Three inputs for the hand-written pass:
//! sparse off-grid features (float32 first layer), dense pooled features (every value a multiple
//! of 1/64: the exact first layer from scratch), and a stream of pooled samples each differing
//! from the previous one in 50 cells, run through a [`StreamingPredictor`] (what the online
//! estimator does at 3 M events/s).
//!
//! The PyTorch CPU reference is `benches/pytorch_baseline.py` (run in the same session). burn's
//! forward pass on the same weights (20 us median, the measurement behind the predictor's design,
//! `docs/performance.md`) is no longer benchmarked: burn is only the training's test reference.

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use evtac_learn::{Parameters, Predictor, StreamingPredictor};

/// A sparse feature vector like a pooled binarised representation.
fn sample(k: usize) -> Vec<f32> {
    (0..900)
        .map(|j| {
            if (j * 7 + k).is_multiple_of(4) {
                ((j + k) % 10) as f32 / 10.0
            } else {
                0.0
            }
        })
        .collect()
}

/// Dense pooled features (a multiple of 1/64 in every cell), like a combined representation.
fn pooled(k: usize) -> Vec<f32> {
    (0..900)
        .map(|j| ((j * 13 + k) % 64 + 1) as f32 / 64.0)
        .collect()
}

/// 32 pooled samples, each differing from the one before in 50 cells by one count, then the
/// same back: played in a loop, every step changes 50 cells.
fn pooled_stream() -> Vec<Vec<f32>> {
    let mut x = pooled(0);
    let mut forth = vec![x.clone()];
    for k in 0..31 {
        for c in 0..50 {
            let cell = (k * 389 + c * 17) % 900;
            let count = (x[cell] * 64.0) as u8;
            x[cell] = f32::from(if count == 64 { 63 } else { count + 1 }) / 64.0;
        }
        forth.push(x.clone());
    }
    let back = forth[1..forth.len() - 1].iter().rev().cloned();
    forth.clone().into_iter().chain(back).collect()
}

/// Median, P99 and P99.9 in microseconds of `f` over `n` timed calls.
fn percentiles(n: usize, mut f: impl FnMut(usize)) -> [f64; 3] {
    let mut times: Vec<f64> = (0..n)
        .map(|i| {
            let t = Instant::now();
            f(i);
            t.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    times.sort_by(f64::total_cmp);
    let at = |q: f64| times[((n as f64 - 1.0) * q).round() as usize];
    [at(0.5), at(0.99), at(0.999)]
}

fn bench(c: &mut Criterion) {
    evtac_learn::flush_denormals();
    let params = Parameters::init(0);
    let predictor = Predictor::new(&params).expect("predictor");
    let samples: Vec<Vec<f32>> = (0..64).map(sample).collect();

    let dense: Vec<Vec<f32>> = (0..64).map(pooled).collect();
    let stream = pooled_stream();
    let mut streaming = StreamingPredictor::new(predictor.clone());
    for (name, stats) in [
        (
            "hand-written, pooled (exact first layer)",
            percentiles(100_000, |i| {
                black_box(predictor.predict_one(&dense[i % 64]));
            }),
        ),
        (
            "hand-written, streaming (50 cells changed)",
            percentiles(100_000, |i| {
                black_box(streaming.predict(&stream[i % stream.len()]));
            }),
        ),
        (
            "hand-written, off-grid (float32 first layer)",
            percentiles(100_000, |i| {
                black_box(predictor.predict_one(&samples[i % 64]));
            }),
        ),
    ] {
        println!(
            "single-sample latency, {name}: median {:.1} us, P99 {:.1} us, P99.9 {:.1} us",
            stats[0], stats[1], stats[2]
        );
    }

    let mut i = 0;
    c.bench_function("predict_one/hand-written", |b| {
        b.iter(|| {
            i = (i + 1) % 64;
            black_box(predictor.predict_one(black_box(&samples[i])))
        })
    });
    c.bench_function("predict_one/hand-written-pooled", |b| {
        b.iter(|| {
            i = (i + 1) % 64;
            black_box(predictor.predict_one(black_box(&dense[i])))
        })
    });
    c.bench_function("predict/streaming-50-cells", |b| {
        b.iter(|| {
            i = (i + 1) % stream.len();
            black_box(streaming.predict(black_box(&stream[i])))
        })
    });
    let batch: Vec<f32> = samples.concat();
    c.bench_function("predict/batch64/hand-written", |b| {
        b.iter(|| black_box(predictor.predict(black_box(&batch)).expect("rows")))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
