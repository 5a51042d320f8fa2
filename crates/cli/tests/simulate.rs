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

#[test]
fn a_filtering_capture_saves_each_recording_filtered_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let (plain, filtered) = (dir.path().join("plain"), dir.path().join("filtered"));
    let simulate = |out: &std::path::Path, filters: &[&str]| {
        let mut args = vec!["simulate", "--protocol", "exp1", "--scale", "tiny"];
        args.extend(["--limit", "1", "--out", out.to_str().unwrap()]);
        for f in filters {
            args.extend(["--filter", f]);
        }
        run_ok(&args);
    };
    simulate(&plain, &[]);
    simulate(&filtered, &["background-activity=10ms"]);
    for file in ["t0000.aedat4", "no_contact.aedat4"] {
        let by_hand = dir.path().join(format!("by-hand-{file}"));
        run_ok(&[
            "filter",
            plain.join(file).to_str().unwrap(),
            by_hand.to_str().unwrap(),
            "--filter",
            "background-activity=10ms",
        ]);
        let want = evtac_formats::read_recording(&by_hand).unwrap();
        let got = evtac_formats::read_recording(filtered.join(file)).unwrap();
        let original = evtac_formats::read_recording(plain.join(file)).unwrap();
        assert_eq!(got.events, want.events, "{file}");
        assert!(got.events.len() < original.events.len(), "{file}");
        assert_eq!(got.imu, original.imu, "{file}");
    }
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(filtered.join("simulator.json")).unwrap()).unwrap();
    assert_eq!(
        record["capture"],
        serde_json::json!(["background-activity=10ms"])
    );
    let plain_record = std::fs::read_to_string(plain.join("simulator.json")).unwrap();
    assert!(!plain_record.contains("capture"));

    let session = dir.path().join("session");
    let err = crate::common::run_err(&[
        "simulate",
        "--protocol",
        "exp1",
        "--scale",
        "tiny",
        "--session",
        "--out",
        session.to_str().unwrap(),
        "--filter",
        "polarity=on",
    ]);
    assert!(err.contains("a --session is one stream"), "{err}");
    assert!(!session.exists());
}
