//! Tests of `evtac train`.

use crate::common::{evtac, run_ok};
use crate::reproduce::tiny_run;

#[test]
fn trains_a_bundle_and_skips_a_finished_one() {
    let data = tiny_run().join("data").join("exp1");
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    let args = [
        "train",
        data.to_str().unwrap(),
        "--repr",
        "combined",
        "--window-ms",
        "320",
        "--epochs",
        "2",
        "--seed",
        "4",
        "--out",
        model.to_str().unwrap(),
    ];
    let out = run_ok(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("best validation MAE"), "{stderr}");
    for f in ["model.safetensors", "config.json", "history.csv", "done"] {
        assert!(model.join(f).is_file(), "no {f}");
    }
    let config = std::fs::read_to_string(model.join("config.json")).unwrap();
    assert!(config.contains("\"combined\""), "{config}");
    assert!(config.contains("320"), "{config}");
    let out = run_ok(&args);
    assert!(String::from_utf8_lossy(&out.stderr).contains("already holds a finished model"));
}

#[test]
fn bad_arguments_fail_with_a_message() {
    let dir = tempfile::tempdir().unwrap();
    let out = evtac()
        .args(["train", dir.path().to_str().unwrap(), "--repr", "static"])
        .args(["--out", dir.path().join("m").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("trials.csv"));
}
