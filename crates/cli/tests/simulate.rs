//! Tests of `evtac simulate`.

use crate::common::{evtac, run_ok};

#[test]
fn simulates_a_dataset_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    let out_s = out.to_str().unwrap();
    run_ok(&[
        "simulate",
        "--protocol",
        "exp3-depth",
        "--scale",
        "tiny",
        "--seed",
        "4",
        "--out",
        out_s,
        "--jobs",
        "2",
        "--limit",
        "2",
    ]);
    let manifest = std::fs::read_to_string(out.join("trials.csv")).unwrap();
    let lines: Vec<&str> = manifest.lines().collect();
    assert_eq!(lines.len(), 3, "{manifest}");
    assert!(lines[0].starts_with("trial,file,truth,direction_deg,speed_deg_s,depth_mm,"));
    assert!(lines[1].starts_with("t0000,t0000.aedat4,truth/t0000.csv,"));
    assert!(lines[1].ends_with(",seen"), "{}", lines[1]);
    for f in [
        "t0000.aedat4",
        "t0001.aedat4",
        "truth/t0001.csv",
        "no_contact.aedat4",
        "calibration.json",
        "simulator.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let sim: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("simulator.json")).unwrap()).unwrap();
    assert_eq!(sim["protocol"], "exp3-depth");
    assert_eq!(sim["params"]["dvs"]["pos_thres"], 0.2);
}

#[test]
fn rejects_unknown_protocol() {
    let out = evtac()
        .args(["simulate", "--protocol", "exp9", "--out", "x"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown protocol `exp9`"), "{err}");
}
