//! The committed sensitivity study (`docs/sensitivity/`) is current and quoted right: its
//! `README.md` is what this code makes of its `sensitivity.json`, it covers every parameter the
//! code varies (a parameter added to `PARAMETERS` shows up here until the study is run again),
//! and `docs/simulator.md` quotes its shares and its gap's range, so the prose never outlives the
//! run it describes.

use evtac_experiments::sensitivity::{PARAMETERS, Study, Varied};
use std::path::{Path, PathBuf};

fn docs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs")
}

fn study() -> Study {
    let path = docs().join("sensitivity/sensitivity.json");
    let text = std::fs::read_to_string(&path).unwrap();
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_committed_readme_is_what_the_code_makes_of_the_study() {
    let path = docs().join("sensitivity/README.md");
    let committed = std::fs::read_to_string(&path).unwrap();
    assert!(
        committed == evtac_report::sensitivity::markdown(&study()),
        "{} is not what evtac_report::sensitivity::markdown makes of sensitivity.json beside it",
        path.display()
    );
}

#[test]
fn the_committed_study_varies_every_parameter_the_code_does_at_each_factor() {
    let study = study();
    assert!(study.baseline().is_some(), "the study has no baseline");
    for parameter in PARAMETERS.iter().map(|p| p.name) {
        for &factor in &study.factors {
            assert!(
                study
                    .points
                    .iter()
                    .any(|p| p.parameter.name() == parameter && p.factor == factor),
                "docs/sensitivity has no point {parameter} x{factor}: run the study again"
            );
        }
    }
    let perturbed = study
        .points
        .iter()
        .filter(|p| p.parameter != Varied::Baseline)
        .count();
    assert_eq!(perturbed, PARAMETERS.len() * study.factors.len());
}

#[test]
fn the_simulator_doc_quotes_the_committed_study() {
    let study = study();
    let doc = std::fs::read_to_string(docs().join("simulator.md"))
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let shares = study.shares();
    let gaps = || study.points.iter().map(|p| p.gap_deg);
    let quotes = [
        format!("{} points", study.points.len()),
        format!("hold at all {} perturbed points", shares[0].1),
        format!("shallowest depth at {}", shares[3].0),
        format!("{:+.3}", gaps().fold(f64::INFINITY, f64::min)),
        format!("{:+.3}", gaps().fold(f64::NEG_INFINITY, f64::max)),
        format!("the baseline's {:+.3}", study.baseline().unwrap().gap_deg),
    ];
    for quote in &quotes {
        assert!(
            doc.contains(quote.as_str()),
            "docs/simulator.md does not say {quote:?}"
        );
    }
    // The first three conclusions are quoted as holding everywhere.
    assert!(shares[..3].iter().all(|&(holds, decided)| holds == decided));
}
