//! Broken input gives errors that say what is wrong.

use evtac_labels::geometry::Calibration;
use evtac_labels::{LabelConfig, TrialError, TrialMotion, label_imu};

use crate::synthetic::{Gyro, Profile};

fn trial() -> (Profile, Vec<evtac_events::ImuSample>) {
    let profile = Profile::new(30.0, 8.0, 100.0, 20.0, None, 600_000);
    let imu = Gyro::realistic().record(&profile, &Calibration::default(), 5);
    (profile, imu)
}

fn label(imu: &[evtac_events::ImuSample], motion: &TrialMotion) -> String {
    label_imu(
        imu,
        motion,
        &Calibration::default(),
        &LabelConfig::default(),
    )
    .unwrap_err()
    .to_string()
}

#[test]
fn missing_imu() {
    let (profile, _) = trial();
    assert_eq!(
        label(&[], &profile.motion),
        "the recording has no IMU stream (0 IMU samples)"
    );
}

#[test]
fn nan_sample() {
    let (profile, mut imu) = trial();
    imu[1234].gyroscope[2] = f32::NAN;
    let t = imu[1234].t;
    assert_eq!(
        label(&imu, &profile.motion),
        format!("IMU sample 1234 (t = {t} us): gyroscope axis 2 is not finite (NaN)")
    );
}

#[test]
fn timestamp_gap() {
    let (profile, mut imu) = trial();
    let after = imu[999].t;
    imu.drain(1000..1040);
    let err = label(&imu, &profile.motion);
    assert!(
        err.starts_with("gap of ") && err.contains(&format!("after t = {after} us")),
        "{err}"
    );
}

#[test]
fn out_of_order_timestamps() {
    let (profile, mut imu) = trial();
    imu.swap(500, 501);
    assert!(label(&imu, &profile.motion).contains("IMU sample 501 has t ="));
}

#[test]
fn no_stationary_segment() {
    let (profile, imu) = trial();
    // The recording starts 20 ms before motion onset: too little to estimate the bias.
    let start = profile.motion.motion_start_us - 20_000;
    let late: Vec<_> = imu.into_iter().filter(|s| s.t >= start).collect();
    let err = label(&late, &profile.motion);
    assert!(
        err.starts_with("no stationary segment before motion onset"),
        "{err}"
    );
}

#[test]
fn motion_past_the_recording() {
    let (profile, imu) = trial();
    let cut = profile.motion.motion_end_us - 300_000;
    let short: Vec<_> = imu.into_iter().filter(|s| s.t < cut).collect();
    let err = label_imu(
        &short,
        &profile.motion,
        &Calibration::default(),
        &LabelConfig::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, TrialError::MotionOutsideRecording { .. }),
        "{err}"
    );
}

#[test]
fn wrong_direction_is_caught_by_the_scale_prior() {
    let (profile, imu) = trial();
    let mut motion = profile.motion;
    motion.direction_deg += 180.0;
    let err = label(&imu, &motion);
    assert!(err.contains("check the tilt direction"), "{err}");
}

#[test]
fn inconsistent_motion() {
    let (profile, imu) = trial();
    let mut motion = profile.motion;
    motion.motion_end_us = motion.motion_start_us;
    assert!(label(&imu, &motion).contains("motion_end_us"));
}
