//! Tests of `evtac tune`.

use crate::common::run_ok;
use crate::reproduce::tiny_run;

#[test]
fn tunes_the_dynamic_window_and_writes_the_choice() {
    let data = tiny_run().join("data").join("exp1");
    let dir = tempfile::tempdir().unwrap();
    let out = run_ok(&[
        "tune",
        data.to_str().unwrap(),
        "--repr",
        "dynamic",
        "--scale",
        "tiny",
        "--epochs",
        "1",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("chosen: window_ms"), "{text}");
    let t: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("tuning-dynamic.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(t["runs"].as_array().map(Vec::len), Some(3));
}
