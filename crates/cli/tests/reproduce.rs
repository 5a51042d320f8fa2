//! Tests of `evtac reproduce`: the whole protocol at the tiny scale, the report with every
//! figure, resuming, and the exported job list.

use crate::common::run_ok;
use evtac_experiments::choices;
use evtac_experiments::plan::Plan;
use evtac_experiments::report::{CHOICES_TITLE, FIGURES};
use evtac_sim::{Scale, SimParams};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// One tiny reproduction shared by the tests of `train`, `evaluate`, `tune` and `reproduce`
/// (simulated once per test binary, and the only end-to-end reproduction in the test suite):
/// its output folder. It runs twice: the second run resumes the finished one, and must find
/// every job done and give the same Experiment 1 results.
pub fn tiny_run() -> &'static Path {
    static RUN: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, out) = RUN.get_or_init(|| {
        let dir = tempfile::tempdir().expect("temp dir");
        let out = dir.path().join("out");
        let args = [
            "reproduce",
            "--scale",
            "tiny",
            "--seed",
            "1",
            "--out",
            out.to_str().expect("utf-8 path"),
        ];
        run_ok(&args);
        let exp1 = |out: &Path| results(out)["exp1"].clone();
        let noise = |out: &Path| results(out)["noise"].clone();
        let (first, first_noise) = (exp1(&out), noise(&out));
        run_ok(&args);
        assert_eq!(exp1(&out), first, "a resumed run changed Experiment 1");
        assert_eq!(
            noise(&out),
            first_noise,
            "a resumed run changed the noise study"
        );
        (dir, out)
    });
    out
}

/// `results.json` of a finished run.
fn results(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap()
}

#[test]
fn tiny_reproduction_writes_the_report_with_every_figure() {
    let out = tiny_run();
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for row in ["| Static |", "| Dynamic |", "| Combined |"] {
        assert!(report.contains(row), "no `{row}` row in:\n{report}");
    }
    assert!(
        report.contains("0.160 ± 0.004"),
        "the paper's numbers are quoted"
    );
    for (fig, _) in FIGURES {
        let bytes = std::fs::read(out.join("figures").join(fig)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG"), "{fig} is not a PNG");
        assert!(bytes.len() > 5_000, "{fig} is nearly empty");
        assert!(
            report.contains(&format!("(figures/{fig})")),
            "{fig} not referenced"
        );
    }
    // Every value the paper leaves open, as this run used it: simulated with the defaults.
    assert!(report.contains(&format!("## {CHOICES_TITLE}")));
    let sim = SimParams::default();
    let expected = choices::of_run(&Plan::for_scale(Scale::Tiny), 1, Some(&sim), Some(&sim));
    for c in &expected {
        let row = format!("| {} | {} | {} | {} |", c.what, c.value, c.why, c.change);
        assert!(report.contains(&row), "no choice row `{row}` in:\n{report}");
    }
    let results = results(out);
    assert_eq!(
        results["choices"].as_array().map(Vec::len),
        Some(expected.len())
    );
    assert_eq!(results["exp1"].as_array().map(Vec::len), Some(3));
    // Experiment 1 at every noise level of the plan, for the three representations; x1 is
    // Experiment 1 itself, and no noise means no background events.
    let levels = Plan::for_scale(Scale::Tiny).noise_levels;
    let noise = results["noise"].as_array().unwrap();
    assert_eq!(noise.len(), 3 * levels.len());
    for p in noise {
        let level = p["level"].as_f64().unwrap();
        assert!(levels.contains(&level), "{p}");
        let rate = p["no_contact_events_per_s"].as_f64().unwrap();
        assert_eq!(
            rate == 0.0,
            level == 0.0,
            "background rate {rate} at x{level}"
        );
        if level == 1.0 {
            let e1 = results["exp1"].as_array().unwrap();
            let same = e1.iter().find(|e| e["name"] == p["name"]).unwrap();
            assert_eq!(same["test"], p["test"], "x1 is not Experiment 1");
        }
        assert!(p["test"]["overall"]["mean"].as_f64().unwrap() > 0.0);
    }
    for level in levels {
        assert!(
            report.contains(&format!("| x{level} | ")),
            "no x{level} row"
        );
    }
    assert!(report.contains("Dynamic minus static test MAE: "));
    assert_eq!(results["exp2"].as_array().map(Vec::len), Some(9));
    let speeds = results["exp3_speed"].as_array().unwrap();
    assert!(
        speeds.iter().any(|p| p["seen"] == false),
        "Experiment 3 has no unseen speed"
    );
    assert!(!results["exp3_depth"].as_array().unwrap().is_empty());
    assert_eq!(results["latency"].as_array().map(Vec::len), Some(12));
    let mae = results["exp1"][0]["test"]["overall"]["mean"]
        .as_f64()
        .unwrap();
    assert!(mae.is_finite() && mae > 0.0);
}

#[test]
fn finished_run_exports_no_jobs_and_a_fresh_one_exports_the_tuning_grid() {
    let out = tiny_run();
    let data = out.join("data");
    let dir = tempfile::tempdir().unwrap();
    let list = dir.path().join("jobs.txt");
    let args = |o: &Path| {
        vec![
            "reproduce".to_string(),
            "--scale".into(),
            "tiny".into(),
            "--seed".into(),
            "1".into(),
            "--data".into(),
            data.display().to_string(),
            "--out".into(),
            o.display().to_string(),
            "--export-jobs".into(),
            list.display().to_string(),
        ]
    };
    let a = args(out);
    run_ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(std::fs::read_to_string(&list).unwrap(), "");
    let fresh = dir.path().join("fresh");
    let a = args(&fresh);
    run_ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let text = std::fs::read_to_string(&list).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    // The tiny cross: 3 static and 3 dynamic settings.
    assert_eq!(lines.len(), 6, "{text}");
    assert!(
        lines
            .iter()
            .all(|l| l.contains(" train ") && l.contains("--out"))
    );
    assert!(lines.iter().any(|l| l.contains("--repr static")));
    assert!(lines.iter().any(|l| l.contains("--repr dynamic")));
}
