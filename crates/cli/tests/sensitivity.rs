//! Tests of `evtac sensitivity` (its Slurm executor's in `slurm.rs`).

use crate::common::{evtac, run_ok};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The arguments of the tiny study the tests share: one parameter at the default factors.
pub fn tiny_study_args(out: &Path) -> Vec<String> {
    let out = out.to_str().expect("utf-8 path");
    [
        "sensitivity",
        "--scale",
        "tiny",
        "--parameters",
        "on_threshold",
        "--out",
        out,
    ]
    .map(String::from)
    .to_vec()
}

/// One tiny study, run once per test binary, and what it printed: its output folder and stdout.
pub fn tiny_study() -> &'static (PathBuf, String) {
    static STUDY: OnceLock<(tempfile::TempDir, (PathBuf, String))> = OnceLock::new();
    let (_, study) = STUDY.get_or_init(|| {
        let dir = tempfile::tempdir().expect("temp dir");
        let out = dir.path().join("study");
        let args = tiny_study_args(&out);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let stdout = String::from_utf8_lossy(&run_ok(&args).stdout).into_owned();
        (dir, (out, stdout))
    });
    study
}

/// `dvs.pos_thres` of the dataset of one point (its copy of the dataset's `simulator.json`).
fn on_threshold(point: &std::path::Path) -> f64 {
    let text = std::fs::read_to_string(point.join("simulator.json")).unwrap();
    let sim: serde_json::Value = serde_json::from_str(&text).unwrap();
    sim["params"]["dvs"]["pos_thres"]
        .as_f64()
        .unwrap_or_else(|| panic!("no dvs.pos_thres in {text}"))
}

#[test]
fn a_tiny_study_varies_the_simulator_writes_its_summary_and_resumes_to_the_same_bytes() {
    let (out, stdout) = tiny_study();
    assert!(
        stdout.contains("static best: holds at ") && stdout.contains(" of 2 perturbed points"),
        "{stdout}"
    );
    // The parameter reached the simulator, and nothing else differs in it.
    let points = out.join("points");
    let base = on_threshold(&points.join("baseline/x1"));
    assert_eq!(on_threshold(&points.join("on_threshold/x0.5")), base * 0.5);
    assert_eq!(on_threshold(&points.join("on_threshold/x1.5")), base * 1.5);
    // A finished point keeps its results and models; its dataset and feature cache are gone.
    for point in ["baseline/x1", "on_threshold/x0.5", "on_threshold/x1.5"] {
        let dir = points.join(point);
        assert!(dir.join("point.json").is_file(), "{point}");
        assert!(
            dir.join("models/exp1/static/seed0/done").is_file(),
            "{point}"
        );
        assert!(!dir.join("data").exists(), "{point} kept its dataset");
    }

    let json = std::fs::read(out.join("sensitivity.json")).unwrap();
    let study: serde_json::Value = serde_json::from_slice(&json).unwrap();
    let names: Vec<(String, f64)> = study["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["parameter"].as_str().unwrap().to_string(),
                p["factor"].as_f64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        names,
        [
            ("baseline".to_string(), 1.0),
            ("on_threshold".to_string(), 0.5),
            ("on_threshold".to_string(), 1.5)
        ]
    );
    for p in study["points"].as_array().unwrap() {
        let st = p["test"][0]["overall"]["mean"].as_f64().unwrap();
        let dy = p["test"][1]["overall"]["mean"].as_f64().unwrap();
        let gap = p["gap_deg"].as_f64().unwrap();
        assert!((gap - (dy - st)).abs() < 1e-12, "{p}");
        assert_eq!(
            p["conclusions"]["static_best"].as_bool(),
            Some(st < dy && st < p["test"][2]["overall"]["mean"].as_f64().unwrap()),
            "{p}"
        );
    }
    let readme = std::fs::read_to_string(out.join("README.md")).unwrap();
    for row in [
        "| baseline | x1 |",
        "| on_threshold | x0.5 |",
        "| on_threshold | x1.5 |",
    ] {
        assert!(readme.contains(row), "{row} missing:\n{readme}");
    }
    assert!(
        readme.contains("perturbed points where it holds"),
        "{readme}"
    );
    let png = std::fs::read(out.join("gap-tornado.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 1000);
    // No partial file is left beside the outputs.
    let leftovers: Vec<_> = std::fs::read_dir(out)
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    // Run again: every point resumes from its finished runs, and the study is the same bytes.
    let args = tiny_study_args(out);
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(std::fs::read(out.join("sensitivity.json")).unwrap(), json);
}

#[test]
fn unknown_parameters_and_factors_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    for (flag, value, says) in [
        ("--parameters", "on_threshold,grip", "\"grip\""),
        ("--factors", "0.5,1", "1 is not a factor"),
        ("--factors", "-2", "-2 is not a factor"),
    ] {
        let run = evtac()
            .args(["sensitivity", "--scale", "tiny", &format!("{flag}={value}")])
            .args(["--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{flag} {value}: {stderr}");
        assert!(stderr.contains(says), "{flag} {value}: {stderr}");
        assert!(!out.exists(), "{flag} {value} wrote {}", out.display());
    }
    let run = evtac()
        .args(["sensitivity", "--scale", "tiny", "--parameters", "grip"])
        .args(["--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("on_threshold, off_threshold"), "{stderr}");
}
