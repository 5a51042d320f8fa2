//! Every sentence of the committed reports that compares two of Experiment 1's representations
//! says what the report's one verdict rule (`evtac_report::exp1_verdicts`) says of that pair on
//! the committed `results.json`: no section may call a pair different that another calls tied.
//!
//! The sentences are found by the forms the report writes them in: "**A is lower than B**" and
//! "A and B: not claimed" (the datasets section), and "Experiment 1: A (...) against the best
//! single representation, B (...): beats it / is worse / ties" (the fusion section).

use evtac_experiments::results::Results;
use evtac_report::Verdict;
use evtac_repr::ReprKind;
use std::path::Path;

/// What one sentence says of `a` against `b`.
fn said(line: &str, a: ReprKind, b: ReprKind) -> Option<Verdict> {
    let (a, b) = (a.to_string(), b.to_string());
    if line.contains(&format!("**{a} is lower than {b}**")) {
        return Some(Verdict::FirstLower);
    }
    if line.contains(&format!("**{b} is lower than {a}**")) {
        return Some(Verdict::SecondLower);
    }
    if line.contains(&format!("{a} and {b}: not claimed"))
        || line.contains(&format!("{b} and {a}: not claimed"))
    {
        return Some(Verdict::Tied);
    }
    // "- Experiment 1: F (...) against the best single representation, S (...): <verdict>".
    let rest = line.strip_prefix("- Experiment 1: ")?;
    let (fusion, rest) = rest.split_once(" (")?;
    let (_, rest) = rest.split_once("against the best single representation, ")?;
    let (single, rest) = rest.split_once(" (")?;
    let (_, verdict) = rest.rsplit_once("): ")?;
    let fusion_lower = if verdict.starts_with("beats it") {
        Verdict::FirstLower
    } else if verdict.starts_with("is worse") {
        Verdict::SecondLower
    } else if verdict.starts_with("ties") {
        Verdict::Tied
    } else {
        panic!("an Experiment 1 comparison without a verdict: {line}");
    };
    let flip = |v| match v {
        Verdict::FirstLower => Verdict::SecondLower,
        Verdict::SecondLower => Verdict::FirstLower,
        Verdict::Tied => Verdict::Tied,
    };
    if fusion == a && single == b {
        Some(fusion_lower)
    } else if fusion == b && single == a {
        Some(flip(fusion_lower))
    } else {
        None
    }
}

fn check(dir: &str) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs")
        .join(dir);
    let results: Results =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let mut checked = 0;
    for (a, b, verdict) in evtac_report::exp1_verdicts(&results) {
        for line in report.lines() {
            if let Some(v) = said(line, a, b) {
                assert_eq!(
                    v,
                    verdict,
                    "{}: {a} against {b} is {verdict:?} by the rule, but the report says: {line}",
                    dir.display()
                );
                checked += 1;
            }
        }
    }
    checked
}

#[test]
fn the_example_reports_comparisons_of_experiment_1_follow_the_one_rule() {
    // Ten pairs in the datasets section and two fusions against the best single one.
    assert_eq!(check("report-example"), 12);
}

#[test]
fn the_paper_scale_reports_comparisons_of_experiment_1_follow_the_one_rule() {
    // One dataset and no fusions: no sentence compares two representations of Experiment 1
    // (the plan is the paper's own); the rule is still the one every section would use.
    check("report-paper");
}

#[test]
fn a_sentence_that_disagrees_with_the_rule_is_found() {
    let (s, l) = (ReprKind::Static, ReprKind::Late);
    assert_eq!(
        said("- **Static is lower than Late** by 0.029 deg", s, l),
        Some(Verdict::FirstLower)
    );
    assert_eq!(
        said(
            "- Experiment 1: Late (0.317 ± 0.014) against the best single representation, \
             Static (0.309 ± 0.010): ties (+0.008 deg, within the larger of ...).",
            s,
            l
        ),
        Some(Verdict::Tied)
    );
    assert_eq!(
        said("- Stacked and Late: not claimed; Late is lower", s, l),
        None
    );
}
