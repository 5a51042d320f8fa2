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

#[test]
fn a_dataset_opened_with_filters_trains_a_model_that_records_them() {
    let data = tiny_run().join("data").join("exp1");
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    let (d, m) = (data.to_str().unwrap(), model.to_str().unwrap());
    let spec = "background-activity=10ms";
    run_ok(&[
        "train", d, "--repr", "static", "--epochs", "1", "--seed", "4", "--out", m, "--filter",
        spec,
    ]);
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(model.join("config.json")).unwrap()).unwrap();
    assert_eq!(
        config["representation"]["filters"],
        serde_json::json!([spec]),
        "{config}"
    );
    // The filtered features are cached apart from the unfiltered ones, and say so.
    let cached: Vec<std::path::PathBuf> =
        std::fs::read_dir(data.join(evtac_events::layout::CACHE_DIR))
            .unwrap()
            .flat_map(|s| std::fs::read_dir(s.unwrap().path()).unwrap())
            .map(|e| e.unwrap().path())
            .filter(|p| p.join("config.json").is_file())
            .filter(|p| {
                std::fs::read_to_string(p.join("config.json"))
                    .unwrap()
                    .contains(spec)
            })
            .collect();
    assert!(!cached.is_empty());
    for dir in &cached {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.rsplit('-').next().unwrap().starts_with('f'), "{name}");
    }

    // Evaluating it on the dataset without the filters is refused, with them it runs.
    let refused = crate::common::run_err(&["evaluate", "--model", m, d]);
    assert!(
        refused.contains(&format!(
            "filters: the features' events went through no filter, the model's through {spec}"
        )),
        "{refused}"
    );
    let out = run_ok(&["evaluate", "--model", m, d, "--json", "--filter", spec]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["mae"][0]["overall"].as_f64().unwrap().is_finite());
}
