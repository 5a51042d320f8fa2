//! The whole protocol at the tiny scale through the library: simulation, labels, splits,
//! tuning, Experiments 1-3, latency, and a report with every figure.

use crate::simulate;
use evtac_experiments::jobs::Quiet;
use evtac_experiments::pipeline::{Datasets, reproduce};
use evtac_experiments::plan::Plan;
use evtac_experiments::report::FIGURES;
use evtac_sim::Protocol;

#[test]
fn tiny_reproduction_writes_the_report_with_every_figure() {
    let tmp = tempfile::tempdir().unwrap();
    // EVTAC_REPORT_EXAMPLE=DIR keeps the output (how docs/report-example was made).
    let root = std::env::var_os("EVTAC_REPORT_EXAMPLE")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| tmp.path().to_path_buf());
    let data = root.join("data");
    for (p, name, n) in [
        (Protocol::Exp1, "exp1", 16),
        (Protocol::Exp2, "exp2", 16),
        (Protocol::Exp3Speed, "exp3-speed", 12),
        (Protocol::Exp3Depth, "exp3-depth", 12),
    ] {
        if !data.join(name).join("trials.csv").is_file() {
            simulate(&data.join(name), p, n);
        }
    }
    let plan = Plan::for_scale("tiny").unwrap();
    let out = root.join("out");
    let results = reproduce(&Datasets::in_dir(&data), &plan, 1, &out, &Quiet).unwrap();
    assert_eq!(results.exp1.len(), 3);
    assert_eq!(results.exp2.len(), 9);
    assert!(!results.exp3_speed.is_empty() && !results.exp3_depth.is_empty());
    assert!(results.exp3_speed.iter().any(|p| !p.seen));
    assert_eq!(results.latency.len(), 12);
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
        assert!(
            report.contains(&format!("(figures/{fig})")),
            "{fig} not referenced"
        );
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let mae = json["exp1"][0]["test"]["overall"]["mean"].as_f64().unwrap();
    assert!(mae.is_finite() && mae > 0.0);
    // A second run resumes: every job is done, the numbers are the same.
    let again = reproduce(&Datasets::in_dir(&data), &plan, 1, &out, &Quiet).unwrap();
    assert_eq!(again.exp1, results.exp1);
}
