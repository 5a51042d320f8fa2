//! `evtac reproduce --beyond`: Experiment 1 with the representations the paper did not choose,
//! at the tiny scale on the tiny run's datasets: each kind tuned on its grid, trained with every
//! seed on every dataset, timed, and reported with a verdict by the report's rule; Experiment 2
//! and the ablations keep to the binary kinds.

use crate::common::run_ok;
use crate::reproduce::tiny_run;
use evtac_experiments::results::Results;
use evtac_repr::ReprKind;

#[test]
fn beyond_rows_are_tuned_trained_timed_and_judged() {
    let data = tiny_run().join("data");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let args = [
        "reproduce",
        "--scale",
        "tiny",
        "--seed",
        "1",
        "--data",
        &s(&data),
        "--out",
        &s(&out),
        "--beyond",
        "--no-capture-filter",
        "--label-noise-deg",
        "0",
    ];
    run_ok(&args);
    let text = std::fs::read_to_string(out.join("results.json")).unwrap();
    let r: Results = serde_json::from_str(&text).unwrap();
    assert!(r.run.plan.beyond);
    let exp1: Vec<ReprKind> = r.exp1.iter().map(|e| e.name).collect();
    assert_eq!(exp1, ReprKind::ALL, "Experiment 1 compares every kind");
    let tuned: Vec<ReprKind> = r.tuning.iter().map(|t| t.repr).collect();
    let mut want = vec![ReprKind::Static, ReprKind::Dynamic];
    want.extend(ReprKind::BEYOND);
    assert_eq!(tuned, want);
    for kind in ReprKind::BEYOND {
        let t = r.tuning.iter().find(|t| t.repr == kind).unwrap();
        let e = r.exp1.iter().find(|e| e.name == kind).unwrap();
        assert_eq!(
            e.config, t.chosen_config,
            "{kind}: trained with its tuned settings"
        );
        assert_eq!(e.runs.len(), r.run.plan.seeds);
        assert!(
            e.test_truth.is_some(),
            "{kind}: error against the truth too"
        );
        assert!(r.latency.iter().any(|c| c.name == kind), "{kind}: latency");
        assert!(
            r.dataset_seeds.iter().any(|p| p.name == kind),
            "{kind}: on the other datasets"
        );
        assert!(r.noise.iter().all(|p| p.name != kind), "not at other noise");
        assert!(r.exp2.iter().all(|c| c.name != kind), "not in Experiment 2");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains(
            "## Beyond the paper's representations: time surfaces, histograms, voxel grids"
        ),
        "{report}"
    );
    for row in ["| Time surface |", "| Histogram |", "| Voxel grid |"] {
        assert!(report.contains(row), "no `{row}` row");
    }
    assert!(report.contains("against the paper's best here"), "{report}");
    assert!(
        report.contains("**In short:** on this simulator"),
        "{report}"
    );
    assert!(
        report.contains("| window (ms) | bins |"),
        "the voxel grid's tuning table"
    );
    // Each kind's sentence says what the one rule (`exp1_verdicts`, every pair) says of it.
    let verdicts = evtac_report::exp1_verdicts(&r);
    for kind in ReprKind::BEYOND {
        let start = format!("- {kind} against the paper's best here, ");
        let line = report
            .lines()
            .find(|l| l.starts_with(&start))
            .unwrap_or_else(|| panic!("no verdict line for {kind}"));
        let best = ReprKind::PAPER
            .into_iter()
            .find(|p| line[start.len()..].starts_with(&format!("{p} (")))
            .expect("the line names a paper representation");
        let (_, _, verdict) = verdicts
            .iter()
            .find(|(a, b, _)| (*a, *b) == (best, kind))
            .expect("every pair is judged");
        let said = match verdict {
            evtac_report::Verdict::FirstLower => "higher by",
            evtac_report::Verdict::SecondLower => "lower by",
            evtac_report::Verdict::Tied => "tied (",
        };
        assert!(line.contains(said), "{verdict:?} but: {line}");
    }
}
