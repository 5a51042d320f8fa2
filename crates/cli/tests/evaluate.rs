//! Tests of `evtac evaluate`.

use crate::common::run_ok;
use crate::reproduce::tiny_run;

#[test]
fn evaluates_overall_and_per_phase_as_json() {
    let run = tiny_run();
    let model = run.join("models").join("exp1").join("static").join("seed1");
    let exp1 = run.join("data").join("exp1");
    let out = run_ok(&[
        "evaluate",
        "--model",
        model.to_str().unwrap(),
        exp1.to_str().unwrap(),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v["mae"].as_array().unwrap();
    assert_eq!(rows.len(), 1, "no stop phases in exp1");
    let overall = rows[0]["overall"].as_f64().unwrap();
    assert!(overall.is_finite() && overall > 0.0);
    // The same number the report has for this model (test split, seed 1).
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("results.json")).unwrap()).unwrap();
    let reported = results["exp1"][0]["runs"][0]["overall"].as_f64().unwrap();
    assert!((reported - overall).abs() < 1e-9, "{reported} vs {overall}");
    // On the pause dataset: motion and stop rows.
    let exp2 = run.join("data").join("exp2");
    let out = run_ok(&[
        "evaluate",
        "--model",
        model.to_str().unwrap(),
        exp2.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("motion") && text.contains("stop"), "{text}");
}
