//! Labelling one long trial (the paper's slowest speed, 2 deg/s, with a stop: 11.7 s of IMU at
//! 800 Hz, 9,360 samples), and the zero-phase filter alone on the same length.
//!
//! Reference: `label_reference.py` beside this file runs the same steps with numpy and SciPy
//! (`sosfiltfilt`, `cumulative_trapezoid`) on the same number of samples.

use criterion::{Criterion, criterion_group, criterion_main};
use evtac_labels::filter::LowPass;
use evtac_labels::{LabelConfig, label_imu};
use std::hint::black_box;

#[allow(dead_code)]
#[path = "../tests/it/synthetic.rs"]
mod synthetic;

fn bench(c: &mut Criterion) {
    let calibration = synthetic::rotated_calibration();
    let profile = synthetic::Profile::new(54.0, 2.0, 100.0, 20.0, Some((9.0, 500_000)), 600_000);
    let imu = synthetic::Gyro::realistic().record(&profile, &calibration, 1);
    let config = LabelConfig::default();
    c.bench_function(&format!("label_imu {} samples", imu.len()), |b| {
        b.iter(|| label_imu(black_box(&imu), &profile.motion, &calibration, &config))
    });
    let filter = LowPass::new(4, 20.0, 800.0).expect("valid design");
    let x: Vec<f64> = (0..imu.len()).map(|i| (i as f64 * 0.01).sin()).collect();
    c.bench_function(&format!("filtfilt {} samples", x.len()), |b| {
        b.iter(|| filter.filtfilt(black_box(&x)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
