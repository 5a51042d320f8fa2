//! Figures the docs quote from the committed reports are the reports' own: each quote below is
//! formatted from the committed `results.json` and must appear in the doc, so a report run again
//! with other numbers fails here until the prose is updated (as `committed_sensitivity.rs` does
//! for the sensitivity study).

use evtac_experiments::results::Results;
use std::path::{Path, PathBuf};

fn docs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs")
}

fn results(dir: &str) -> Results {
    let path = docs().join(dir).join("results.json");
    let text = std::fs::read_to_string(&path).unwrap();
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `doc` with its whitespace folded, so a quote may wrap.
fn doc(name: &str) -> String {
    std::fs::read_to_string(docs().join(name))
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn the_simulator_doc_quotes_the_reports_label_error_against_the_truth() {
    let doc = doc("simulator.md");
    for (dir, quote) in [
        (
            "report-example",
            "{rms} deg per trial on average in `docs/report-example` (Experiment 2, {n} trials)",
        ),
        (
            "report-paper",
            "{rms} deg in `docs/report-paper` ({n} trials)",
        ),
    ] {
        let rms = results(dir)
            .labels
            .and_then(|l| l.truth_rms_deg)
            .unwrap_or_else(|| panic!("docs/{dir} has no label error against the truth"));
        let quote = quote
            .replace("{rms}", &format!("{:.3}", rms.mean))
            .replace("{n}", &rms.n.to_string());
        assert!(
            doc.contains(&quote),
            "docs/simulator.md does not say {quote:?} (from docs/{dir}/results.json)"
        );
    }
}

/// The mean over datasets of `kind`'s per-dataset test MAE in `r`.
fn over_datasets(r: &Results, kind: evtac_repr::ReprKind) -> f64 {
    let means: Vec<f64> = r
        .dataset_seeds
        .iter()
        .filter(|p| p.name == kind)
        .map(|p| p.test.overall.mean)
        .collect();
    assert!(!means.is_empty(), "no datasets of {kind}");
    means.iter().sum::<f64>() / means.len() as f64
}

#[test]
fn the_guide_quotes_the_example_reports_choice_and_fusion_margins() {
    use evtac_repr::ReprKind::{Late, Stacked, Static};
    let doc = doc("guide.md");
    let r = results("report-example");
    let tuned = r
        .tuning
        .iter()
        .find(|t| t.repr == Static)
        .expect("static was tuned");
    let static_mean = over_datasets(&r, Static);
    let quotes = [
        format!("the static decay chosen is {} ms", tuned.chosen_time_ms),
        format!(
            "Static and Stacked differ by {:.3} deg",
            (over_datasets(&r, Stacked) - static_mean).abs()
        ),
        format!(
            "Static and Late by {:.3} deg",
            (over_datasets(&r, Late) - static_mean).abs()
        ),
    ];
    for quote in &quotes {
        assert!(
            doc.contains(quote.as_str()),
            "docs/guide.md does not say {quote:?} (from docs/report-example/results.json)"
        );
    }
    // Both quoted as not claimed: the report's rule must agree.
    for (a, b, v) in evtac_report::exp1_verdicts(&r) {
        if a == Static && matches!(b, Stacked | Late) {
            assert_eq!(v, evtac_report::Verdict::Tied, "{a} and {b}");
        }
    }
}
