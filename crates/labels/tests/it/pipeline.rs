//! The whole pipeline on synthetic IMU streams whose tilt is known exactly.

use evtac_labels::geometry::Calibration;
use evtac_labels::{LabelConfig, ScaleMethod, Summary, TruthError, label_imu};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::synthetic::{Gyro, Profile, rotated_calibration};

#[test]
fn an_ideal_gyroscope_gives_the_exact_tilt() {
    // Without sensor errors only the low-pass near the ramps separates labels from truth.
    for calibration in [Calibration::default(), rotated_calibration()] {
        for phi in [0.0, 72.0, 162.0, 270.0, 342.0] {
            let profile = Profile::new(phi, 6.0, 200.0, 20.0, Some((8.5, 500_000)), 600_000);
            let imu = Gyro::ideal().record(&profile, &calibration, 1);
            let labels =
                label_imu(&imu, &profile.motion, &calibration, &LabelConfig::default()).unwrap();
            let err = TruthError::compare(&labels.labels, &profile.truth(1_000)).unwrap();
            assert!(err.rms_deg < 2e-3, "phi {phi}: {err:?}");
            assert!(err.max_abs_deg < 1e-2, "phi {phi}: {err:?}");
            assert!((labels.scale_factor - 1.0).abs() < 1e-4);
            let stop = labels.stop.unwrap();
            assert!(stop.error_deg.abs() < 1e-3, "{stop:?}");
        }
    }
}

/// Labels a set of realistic trials (the paper's five speeds, its 20 directions, a stop at a
/// random angle in each) and returns the per-trial truth errors and stop errors.
fn realistic_trials(config: &LabelConfig, seed: u64) -> (Vec<TruthError>, Vec<f64>) {
    let calibration = rotated_calibration();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut truth, mut stops) = (Vec::new(), Vec::new());
    for k in 0..20 {
        let phi = 18.0 * k as f64;
        let speed = 2.0 * (1 + k % 5) as f64;
        let stop_deg = rng.random_range(3.0..17.0);
        let profile = Profile::new(phi, speed, 100.0, 20.0, Some((stop_deg, 500_000)), 600_000);
        let mut gyro = Gyro::realistic();
        gyro.scale_error = rng.random_range(-0.04..0.04);
        gyro.bias = std::array::from_fn(|_| rng.random_range(-0.5..0.5));
        let imu = gyro.record(&profile, &calibration, seed * 100 + k);
        let labels = label_imu(&imu, &profile.motion, &calibration, config).unwrap();
        truth.push(TruthError::compare(&labels.labels, &profile.truth(1_000)).unwrap());
        stops.push(labels.stop_error_deg().unwrap());
    }
    (truth, stops)
}

#[test]
fn a_realistic_gyroscope_meets_the_papers_figures() {
    let (truth, stops) = realistic_trials(&LabelConfig::default(), 7);
    let rms: Vec<f64> = truth.iter().map(|e| e.rms_deg).collect();
    let rms_summary = Summary::of(&rms).unwrap();
    let stop_summary = Summary::of(&stops).unwrap();
    eprintln!("label RMS vs truth (deg): {rms_summary}");
    eprintln!("stop error (deg): {stop_summary}");
    assert!(rms_summary.max <= 0.05, "{rms:?}");
    assert!(stop_summary.mean.abs() <= 0.02, "{stops:?}");
    assert!(stop_summary.std <= 0.05, "{stops:?}");
}

#[test]
fn the_speed_prior_leaves_the_final_angle_to_check() {
    let calibration = Calibration::default();
    let profile = Profile::new(45.0, 4.0, 100.0, 20.0, None, 600_000);
    let mut gyro = Gyro::realistic();
    gyro.scale_error = -0.035;
    let imu = gyro.record(&profile, &calibration, 3);
    let config = LabelConfig {
        scale: ScaleMethod::CommandedSpeed,
        ..LabelConfig::default()
    };
    let labels = label_imu(&imu, &profile.motion, &calibration, &config).unwrap();
    assert!((labels.scale_factor * (1.0 - 0.035) - 1.0).abs() < 2e-3);
    assert!(
        labels.final_error_deg.abs() < 0.05,
        "{}",
        labels.final_error_deg
    );
    assert!(labels.stop.is_none());
    // Without calibration the 3.5 % scale error shows in full at the end.
    let config = LabelConfig {
        scale: ScaleMethod::None,
        ..LabelConfig::default()
    };
    let labels = label_imu(&imu, &profile.motion, &calibration, &config).unwrap();
    assert!(
        (labels.final_error_deg + 0.7).abs() < 0.05,
        "{}",
        labels.final_error_deg
    );
}

#[test]
fn theta_is_held_where_the_robot_is_still() {
    let calibration = Calibration::default();
    let profile = Profile::new(200.0, 10.0, 100.0, 20.0, Some((12.0, 500_000)), 600_000);
    let imu = Gyro::realistic().record(&profile, &calibration, 11);
    let labels = label_imu(&imu, &profile.motion, &calibration, &LabelConfig::default()).unwrap();
    let m = profile.motion;
    let stop = m.stop.unwrap();
    let series = &labels.labels;
    let mut stop_values = Vec::new();
    for (&t, &theta) in series.t_us.iter().zip(&series.theta_deg) {
        if t <= m.motion_start_us {
            assert_eq!(theta, 0.0);
        } else if t >= m.motion_end_us {
            assert!((theta - 20.0).abs() < 1e-12);
        } else if t >= stop.start_us && t <= stop.end_us {
            stop_values.push(theta);
        }
    }
    assert!(stop_values.len() > 300);
    assert!(stop_values.iter().all(|&v| v == stop_values[0]));
    // Labels are on the IMU's time base.
    assert_eq!(series.t_us, imu.iter().map(|s| s.t).collect::<Vec<_>>());
}
