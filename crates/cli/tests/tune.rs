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

/// A kind the paper did not choose through every command a lab runs: `tune` over its grid,
/// `evaluate` of the chosen run, `represent --model` and `predict` on a trial's events, and the
/// same estimates as `evaluate`'s library path would give.
#[test]
fn tunes_a_histogram_and_its_model_evaluates_represents_and_predicts() {
    let data = tiny_run().join("data").join("exp1");
    let dir = tempfile::tempdir().unwrap();
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let out = run_ok(&[
        "tune",
        &s(&data),
        "--repr",
        "histogram",
        "--scale",
        "tiny",
        "--epochs",
        "1",
        "--out",
        &s(dir.path()),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("chosen: window_ms"), "{text}");
    let t: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("tuning-histogram.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(t["runs"].as_array().map(Vec::len), Some(2));
    assert_eq!(t["chosen_config"]["kind"], "histogram");
    let config: evtac_repr::ReprConfig =
        serde_json::from_value(t["chosen_config"].clone()).unwrap();
    let model = dir
        .path()
        .join("tuning")
        .join("histogram")
        .join(config.cache_key());
    let bundle = evtac_learn::ModelBundle::load(&model).unwrap();
    assert_eq!(
        bundle.parameters.architecture,
        evtac_learn::Architecture::Channels(2)
    );
    let out = run_ok(&["evaluate", "--model", &s(&model), &s(&data), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let overall = v["mae"][0]["overall"].as_f64().unwrap();
    assert!(overall.is_finite() && overall > 0.0, "{v}");

    // One trial's events through `represent --model`, then `predict`.
    let manifest = evtac_events::manifest::Manifest::read(&data).unwrap();
    let events = data.join(&manifest.trials[0].file);
    let samples = dir.path().join("samples.txt");
    let recording = evtac_formats::read_recording(&events).unwrap();
    let (t0, t1) = (recording.events[0].t, recording.events.last().unwrap().t);
    let times: String = (1..=5)
        .map(|k| format!("{}\n", t0 + k * (t1 - t0) / 5))
        .collect();
    std::fs::write(&samples, times).unwrap();
    let features = dir.path().join("x.npy");
    run_ok(&[
        "represent",
        &s(&events),
        "--samples",
        &s(&samples),
        "--model",
        &s(&model),
        "-o",
        &s(&features),
    ]);
    let x: ndarray::Array2<f32> = ndarray_npy::read_npy(&features).unwrap();
    assert_eq!(x.dim(), (5, 1800));
    let y_path = dir.path().join("y.npy");
    run_ok(&[
        "predict",
        "--model",
        &s(&model),
        "--features",
        &s(&features),
        "--output",
        &s(&y_path),
    ]);
    let y: ndarray::Array2<f32> = ndarray_npy::read_npy(&y_path).unwrap();
    let flat: Vec<f32> = x.iter().copied().collect();
    let want = evtac_learn::Predictor::new(&bundle.parameters)
        .unwrap()
        .predict(&flat)
        .unwrap();
    for (row, w) in y.rows().into_iter().zip(&want) {
        assert_eq!([row[0], row[1]], *w);
    }
}
