//! The report's "Experiment 1 on other simulated datasets" section: each representation's test
//! MAE on every simulated dataset, and every pair of representations judged by the report's one
//! rule ([`super::verdict`]) on the numbers every section compares for Experiment 1.

use std::fmt::Write as _;

use evtac_experiments::results::{MeanStd, Results};
use evtac_repr::ReprKind;

use super::verdict::{self, Side, Verdict};

/// One representation across the run's datasets.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Across {
    /// The representation.
    pub kind: ReprKind,
    /// Each dataset's (seed, mean test MAE over training seeds), Experiment 1's first.
    pub means: Vec<(u64, f64)>,
    /// Mean and sample standard deviation of those means.
    pub over_datasets: MeanStd,
    /// The training seeds' standard deviation, pooled over datasets (root mean square).
    pub seeds_sd: f64,
    /// The mean over datasets of each one's mean test MAE against the simulator's exact truth,
    /// where every dataset measured it.
    pub truth_mean: Option<f64>,
}

/// Every representation across datasets, in report order; empty when the run simulated fewer
/// than two datasets.
pub(super) fn across(r: &Results) -> Vec<Across> {
    let kinds = ReprKind::in_order(r.dataset_seeds.iter().map(|p| p.name));
    let out: Vec<Across> = kinds
        .into_iter()
        .map(|kind| {
            let points: Vec<_> = r.dataset_seeds.iter().filter(|p| p.name == kind).collect();
            let means: Vec<(u64, f64)> = points
                .iter()
                .map(|p| (p.dataset_seed, p.test.overall.mean))
                .collect();
            let values: Vec<f64> = means.iter().map(|m| m.1).collect();
            let var = points
                .iter()
                .map(|p| p.test.overall.std.powi(2))
                .sum::<f64>()
                / points.len().max(1) as f64;
            let truth: Option<Vec<f64>> = points
                .iter()
                .map(|p| p.test_truth.map(|t| t.overall.mean))
                .collect();
            Across {
                kind,
                means,
                over_datasets: MeanStd::of(&values),
                seeds_sd: var.sqrt(),
                truth_mean: truth
                    .filter(|t| !t.is_empty())
                    .map(|t| t.iter().sum::<f64>() / t.len() as f64),
            }
        })
        .collect();
    if out.iter().all(|a| a.means.len() < 2) {
        return Vec::new();
    }
    out
}

/// In how many datasets `a`'s mean is below `b`'s.
fn lower_in(a: &Across, b: &Across) -> usize {
    a.means
        .iter()
        .filter(|(seed, m)| b.means.iter().any(|(s, n)| s == seed && m < n))
        .count()
}

impl Across {
    /// The side every Experiment 1 comparison takes for this representation.
    pub fn side(&self) -> Side {
        Side {
            mean: self.over_datasets.mean,
            seeds_sd: self.seeds_sd,
            datasets_sd: Some(self.over_datasets.std),
        }
    }
}

/// One sentence on `a` against `b` (MAE over datasets, lower is better), judged by the report's
/// one rule; whether a difference is claimed.
fn claim(a: &Across, b: &Across) -> (String, bool) {
    let judged = verdict::judge(&a.side(), &b.side());
    let n = a.means.len().min(b.means.len());
    let (lower, higher) = if judged.diff >= 0.0 { (a, b) } else { (b, a) };
    let count = lower_in(lower, higher);
    if judged.verdict == Verdict::Tied {
        (
            format!(
                "{} and {}: not claimed; {} is lower by {:.3} deg, within {}; lower in {count} \
                 of {n} datasets.",
                a.kind,
                b.kind,
                lower.kind,
                judged.diff.abs(),
                judged.spread.describe()
            ),
            false,
        )
    } else {
        (
            format!(
                "**{} is lower than {}** by {:.3} deg, beyond {}; lower in {count} of {n} \
                 datasets.",
                lower.kind,
                higher.kind,
                judged.diff.abs(),
                judged.spread.describe()
            ),
            true,
        )
    }
}

/// The section, or nothing when the run simulated one dataset.
pub(super) fn section(md: &mut String, r: &Results) {
    let all = across(r);
    let Some(first) = all.first() else {
        return;
    };
    let seeds: Vec<String> = first.means.iter().map(|m| m.0.to_string()).collect();
    let _ = writeln!(
        md,
        "## Experiment 1 on other simulated datasets (test MAE, degrees)\n"
    );
    let _ = writeln!(
        md,
        "Experiment 1 on {} datasets simulated with the same parameters and the seeds {} (the \
         first is Experiment 1's own), each trained with the settings tuned on the first and \
         the same {} training seeds. Each cell is a dataset's mean over training seeds. A \
         difference between two representations is claimed only beyond both the training \
         seeds' spread and the datasets' (each pair's two standard deviations in quadrature); \
         every comparison of Experiment 1's representations in this report is this one, on \
         these numbers.\n",
        seeds.len(),
        seeds.join(", "),
        r.dataset_seeds.first().map_or(0, |p| p.runs.len()),
    );
    let header: Vec<String> = seeds.iter().map(|s| format!("seed {s}")).collect();
    let truth = all.iter().all(|a| a.truth_mean.is_some());
    let _ = writeln!(
        md,
        "| Representation | {} | Mean over datasets | SD across datasets | SD across training \
         seeds |{}",
        header.join(" | "),
        if truth { " Mean vs truth |" } else { "" }
    );
    let _ = writeln!(
        md,
        "| --- |{} ---: | ---: | ---: |{}",
        " ---: |".repeat(header.len()),
        if truth { " ---: |" } else { "" }
    );
    for a in &all {
        let cells: Vec<String> = a.means.iter().map(|m| format!("{:.3}", m.1)).collect();
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {:.3} |{}",
            a.kind,
            cells.join(" | "),
            a.over_datasets.mean,
            a.over_datasets.std,
            a.seeds_sd,
            a.truth_mean
                .filter(|_| truth)
                .map_or(String::new(), |t| format!(" {t:.3} |"))
        );
    }
    let _ = writeln!(
        md,
        "\nSD across training seeds: the root mean square of each dataset's standard deviation \
         over seeds.{}\n",
        if truth {
            " Mean vs truth: the same mean against the simulator's exact truth instead of the \
             labels."
        } else {
            ""
        }
    );
    let mut claimed = 0;
    let mut lines = String::new();
    for (i, a) in all.iter().enumerate() {
        for b in &all[i + 1..] {
            let (text, yes) = claim(a, b);
            claimed += usize::from(yes);
            let _ = writeln!(lines, "- {text}");
        }
    }
    let _ = writeln!(
        md,
        "**In short:** {claimed} of {} pairs differ beyond both spreads.\n",
        all.len() * (all.len() - 1) / 2
    );
    md.push_str(&lines);
    let ratio: Vec<String> = all
        .iter()
        .filter(|a| a.seeds_sd > 0.0)
        .map(|a| format!("{} {:.1}x", a.kind, a.over_datasets.std / a.seeds_sd))
        .collect();
    if !ratio.is_empty() {
        let _ = writeln!(
            md,
            "\nThe spread across datasets against the training seeds': {}. On evtac's simulator: \
             datasets differ here in their trials' noise, the rig's errors, the sensor's \
             seatings and the camera's fixed pattern, not in the sensor's build.\n",
            ratio.join(", ")
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_experiments::results::{DatasetSeedPoint, MaeStats};

    fn point(seed: u64, name: ReprKind, maes: &[f64]) -> DatasetSeedPoint {
        let runs = super::super::runs_of(maes);
        DatasetSeedPoint {
            dataset_seed: seed,
            name,
            test: MaeStats::of(&runs),
            runs,
            test_truth: None,
        }
    }

    #[test]
    fn a_difference_within_the_datasets_spread_is_not_claimed() {
        // Static below dynamic in every dataset by far more than the seeds' spread: claimed.
        // Static and Combined: Combined lower by 0.010 over datasets, beyond the seeds' spread on each,
        // but the datasets disagree by far more: not claimed.
        let mut r: Results =
            serde_json::from_str(include_str!("../../../../docs/report-example/results.json"))
                .expect("the example report's results");
        r.dataset_seeds = vec![
            point(0, ReprKind::Static, &[0.30, 0.31]),
            point(0, ReprKind::Dynamic, &[0.60, 0.61]),
            point(0, ReprKind::Combined, &[0.20, 0.21]),
            point(1, ReprKind::Static, &[0.35, 0.36]),
            point(1, ReprKind::Dynamic, &[0.62, 0.63]),
            point(1, ReprKind::Combined, &[0.43, 0.44]),
        ];
        let all = across(&r);
        assert_eq!(all.len(), 3);
        assert_eq!(all[0].means, [(0, 0.305), (1, 0.355)]);
        let (text, yes) = claim(&all[0], &all[1]);
        assert!(yes, "{text}");
        assert!(text.contains("lower in 2 of 2 datasets"), "{text}");
        let (text, yes) = claim(&all[0], &all[2]);
        assert!(!yes, "{text}");
        assert!(text.contains("not claimed"), "{text}");
        let mut md = String::new();
        section(&mut md, &r);
        assert!(md.contains("| Static | 0.305 | 0.355 |"), "{md}");
        assert!(
            md.contains("2 of 3 pairs differ beyond both spreads"),
            "{md}"
        );
        // One dataset: no section.
        r.dataset_seeds.retain(|p| p.dataset_seed == 0);
        assert!(across(&r).is_empty());
    }
}
