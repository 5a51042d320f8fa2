//! Tests of `evtac labels`: a simulated Experiment 2 dataset labelled end to end, and the errors
//! that name the broken trial.

use std::path::Path;

use evtac_events::manifest::Manifest;

use crate::common::{evtac, run_ok};

/// Simulates two Experiment 2 trials (each with a stop) into `out`, with the sensor seated
/// without a turn: the labels keep the commanded rolling axis, so a seating's turn would show
/// in their comparison with the truth (sensor frame) as the rig's error, not the labeller's.
fn simulate(out: &Path) {
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    let params = out.with_extension("params.json");
    std::fs::write(&params, r#"{"rig": {"reseat_rotation_sd_deg": 0.0}}"#).unwrap();
    run_ok(&[
        "simulate",
        "--params",
        params.to_str().unwrap(),
        "--protocol",
        "exp2",
        "--scale",
        "tiny",
        "--seed",
        "11",
        "--out",
        out.to_str().unwrap(),
        "--jobs",
        "2",
        "--limit",
        "2",
    ]);
}

#[test]
fn labels_a_simulated_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("ds");
    simulate(&ds);
    let ds_s = ds.to_str().unwrap();

    let out = run_ok(&["labels", ds_s]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("labelled 2 trials"), "{text}");
    assert!(text.contains("stop check"), "{text}");
    assert!(text.contains("labels vs ground truth"), "{text}");

    let out = run_ok(&["labels", ds_s, "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let trials = json["trials"].as_array().unwrap();
    assert_eq!(trials.len(), 2);
    for t in trials {
        let name = t["trial"].as_str().unwrap();
        let rms = t["truth"]["rms_deg"].as_f64().unwrap();
        assert!(
            rms <= 0.05,
            "{name}: RMS {rms} deg against the simulator's truth"
        );
        // Against the command: the robot's repeatability (0.0013 deg) and the labels' own error
        // (up to 0.05 deg RMS against the truth) with room to spare.
        let stop = t["stop"]["error_deg"].as_f64().unwrap();
        assert!(stop.abs() <= 0.175, "{name}: stop error {stop} deg");
        let csv = std::fs::read_to_string(ds.join("labels").join(format!("{name}.csv"))).unwrap();
        assert!(csv.starts_with("t_us,theta_deg,pitch_deg,roll_deg\n"));
    }
    let stop = &json["stop_error_deg"];
    assert_eq!(stop["n"], 2);
    assert!(stop["mean"].as_f64().unwrap().abs() <= 0.125, "{stop}");
}

#[test]
fn errors_name_the_trial_and_what_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("ds");
    simulate(&ds);
    // Move the second trial's onset to the very start: no stationary segment is left.
    let mut manifest = Manifest::read(&ds).unwrap();
    manifest.trials[1].motion_start_us = 30_000;
    manifest.write(&ds).unwrap();
    let out = evtac()
        .args(["labels", ds.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("trial `t0001`: no stationary segment before motion onset"),
        "{err}"
    );

    let out = evtac()
        .args(["labels", dir.path().join("nowhere").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("trials.csv"), "{err}");
}

#[test]
fn a_missing_calibration_is_refused_unless_the_identity_is_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("ds");
    simulate(&ds);
    std::fs::remove_file(ds.join("calibration.json")).unwrap();
    let ds_s = ds.to_str().unwrap();
    let out = evtac().args(["labels", ds_s]).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("calibration.json is missing"), "{err}");
    assert!(err.contains("--identity-calibration"), "{err}");

    // Without the gyroscope scale check, which the wrong rotation would fail.
    let out = run_ok(&[
        "labels",
        ds_s,
        "--identity-calibration",
        "--scale",
        "none",
        "--json",
    ]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // The simulator turns its IMU against the sensor, so the identity gives wrong labels: the
    // flag really replaced the calibration.
    let rms = json["truth_rms_deg"]["mean"].as_f64().unwrap();
    assert!(rms > 1.0, "identity-calibrated labels RMS {rms} deg");
}
