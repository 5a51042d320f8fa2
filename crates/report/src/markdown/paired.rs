//! Experiment 1's representations trained again with one thing changed (noisy labels, filtered
//! events), beside Experiment 1, paired by seed: the same initial weights and batches, so the
//! change is the mean of each seed's difference, judged by the one verdict rule
//! ([`super::verdict`]). The label-noise and capture-filter sections share it.

use evtac_experiments::results::{Exp1Repr, MeanStd};

use super::verdict::{self, Side, Verdict};

/// A cell: the test MAE against the labels, and against the simulator's exact truth where
/// measured ("0.309 ± 0.010 / 0.301").
fn with_truth(r: &Exp1Repr) -> String {
    match r.test_truth {
        Some(t) => format!("{} / {:.3}", r.test.overall.display(), t.overall.mean),
        None => r.test.overall.display(),
    }
}

/// One row per representation of `changed` that `before` has too (`| name | before | changed
/// | change |`), then the truth note and a sentence of verdicts, appended to `md`.
pub fn rows(md: &mut String, before: &[Exp1Repr], changed: &[Exp1Repr]) {
    let mut verdicts = Vec::new();
    for after in changed {
        let Some(base) = before.iter().find(|c| c.name == after.name) else {
            continue;
        };
        let diffs: Vec<f64> = after
            .seeds
            .iter()
            .zip(&after.runs)
            .filter_map(|(seed, n)| {
                let k = base.seeds.iter().position(|s| s == seed)?;
                Some(n.overall - base.runs.get(k)?.overall)
            })
            .collect();
        let change = MeanStd::of(&diffs);
        md.push_str(&format!(
            "| {} | {} | {} | {:+.3} ± {:.3} |\n",
            after.name.title(),
            with_truth(base),
            with_truth(after),
            change.mean,
            change.std
        ));
        let judged = verdict::judge(
            &Side::of(&base.test.overall),
            &Side::of(&after.test.overall),
        );
        verdicts.push(format!(
            "{} changes by {:+.3} deg, {} {}",
            after.name.title(),
            change.mean,
            if judged.verdict == Verdict::Tied {
                "within"
            } else {
                "beyond"
            },
            judged.spread.describe()
        ));
    }
    if before.iter().chain(changed).any(|r| r.test_truth.is_some()) {
        md.push_str(
            "\nEach cell: mean ± std over seeds against the clean test labels / the mean against \
             the simulator's exact truth.\n",
        );
    }
    if !verdicts.is_empty() {
        md.push_str(&format!("\n{}.\n\n", verdicts.join("; ")));
    }
}
