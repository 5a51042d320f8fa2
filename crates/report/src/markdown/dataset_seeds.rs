//! The report's "Experiment 1 on other simulated datasets" section, and the rule every claim of a
//! difference in Experiment 1 follows: it must exceed both the training seeds' spread and, where
//! the run measured it, the spread across simulated datasets ([`Spread`]).
//!
//! The training seeds' spread says how much a result moves when the same data is trained on
//! again; the datasets' spread, how much it moves on another dataset of the same kind (other
//! trials, another camera, other noise; `evtac_experiments::dataset_seeds`). A difference
//! smaller than either could be an accident of the one dataset or of the few seeds.

use std::fmt::Write as _;

use evtac_experiments::results::{MeanStd, Results};
use evtac_repr::ReprKind;

/// What a difference between two representations' MAEs must exceed to be claimed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Spread {
    /// The training seeds' spread: the two standard deviations added in quadrature.
    pub seeds: f64,
    /// The datasets' spread, the same over each dataset's mean, where measured.
    pub datasets: Option<f64>,
}

impl Spread {
    /// The spread of a difference between `a` and `b` over training seeds, and over datasets
    /// when both their standard deviations across datasets are given.
    pub fn of(a: &MeanStd, b: &MeanStd, datasets: Option<(f64, f64)>) -> Spread {
        Spread {
            seeds: a.std.hypot(b.std),
            datasets: datasets.map(|(x, y)| x.hypot(y)),
        }
    }

    /// The larger of the two: a difference counts only beyond it.
    pub fn bound(&self) -> f64 {
        self.datasets.map_or(self.seeds, |d| d.max(self.seeds))
    }

    /// How the bound reads in a sentence ("the seeds' spread of 0.012", or both).
    pub fn describe(&self) -> String {
        match self.datasets {
            None => format!("the seeds' spread of {:.3}", self.seeds),
            Some(d) => format!(
                "the larger of the seeds' spread ({:.3}) and the datasets' ({d:.3})",
                self.seeds
            ),
        }
    }
}

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
            Across {
                kind,
                means,
                over_datasets: MeanStd::of(&values),
                seeds_sd: var.sqrt(),
            }
        })
        .collect();
    if out.iter().all(|a| a.means.len() < 2) {
        return Vec::new();
    }
    out
}

/// `kind`'s standard deviation across datasets, or `None` when not measured.
pub(super) fn datasets_sd(all: &[Across], kind: ReprKind) -> Option<f64> {
    all.iter()
        .find(|a| a.kind == kind)
        .map(|a| a.over_datasets.std)
}

/// In how many datasets `a`'s mean is below `b`'s.
fn lower_in(a: &Across, b: &Across) -> usize {
    a.means
        .iter()
        .filter(|(seed, m)| b.means.iter().any(|(s, n)| s == seed && m < n))
        .count()
}

/// One sentence on `a` against `b` (MAE over datasets, lower is better): claimed only beyond
/// both spreads.
fn claim(a: &Across, b: &Across) -> (String, bool) {
    let diff = b.over_datasets.mean - a.over_datasets.mean;
    let spread = Spread {
        seeds: a.seeds_sd.hypot(b.seeds_sd),
        datasets: Some(a.over_datasets.std.hypot(b.over_datasets.std)),
    };
    let n = a.means.len().min(b.means.len());
    let (lower, higher) = if diff >= 0.0 { (a, b) } else { (b, a) };
    let count = lower_in(lower, higher);
    if diff.abs() > spread.bound() {
        (
            format!(
                "**{} is lower than {}** by {:.3} deg, beyond {}; lower in {count} of {n} \
                 datasets.",
                lower.kind,
                higher.kind,
                diff.abs(),
                spread.describe()
            ),
            true,
        )
    } else {
        (
            format!(
                "{} and {}: not claimed; {} is lower by {:.3} deg, within {}; lower in {count} \
                 of {n} datasets.",
                a.kind,
                b.kind,
                lower.kind,
                diff.abs(),
                spread.describe()
            ),
            false,
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
         seeds' spread and the datasets' (each pair's two standard deviations in quadrature).\n",
        seeds.len(),
        seeds.join(", "),
        r.dataset_seeds.first().map_or(0, |p| p.runs.len()),
    );
    let header: Vec<String> = seeds.iter().map(|s| format!("seed {s}")).collect();
    let _ = writeln!(
        md,
        "| Representation | {} | Mean over datasets | SD across datasets | SD across training \
         seeds |",
        header.join(" | ")
    );
    let _ = writeln!(
        md,
        "| --- |{} ---: | ---: | ---: |",
        " ---: |".repeat(header.len())
    );
    for a in &all {
        let cells: Vec<String> = a.means.iter().map(|m| format!("{:.3}", m.1)).collect();
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {:.3} |",
            a.kind,
            cells.join(" | "),
            a.over_datasets.mean,
            a.over_datasets.std,
            a.seeds_sd
        );
    }
    let _ = writeln!(
        md,
        "\nSD across training seeds: the root mean square of each dataset's standard deviation \
         over seeds.\n"
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
        }
    }

    #[test]
    fn the_bound_is_the_larger_spread() {
        let a = MeanStd {
            mean: 0.2,
            std: 0.03,
            n: 5,
        };
        let b = MeanStd {
            mean: 0.3,
            std: 0.04,
            n: 5,
        };
        let seeds_only = Spread::of(&a, &b, None);
        assert!((seeds_only.bound() - 0.05).abs() < 1e-12);
        assert!(
            seeds_only
                .describe()
                .starts_with("the seeds' spread of 0.050")
        );
        let both = Spread::of(&a, &b, Some((0.06, 0.08)));
        assert!((both.bound() - 0.1).abs() < 1e-12);
        assert!(both.describe().contains("the datasets' (0.100)"));
        let small = Spread::of(&a, &b, Some((0.0, 0.0)));
        assert_eq!(small.bound(), seeds_only.bound());
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
        assert_eq!(datasets_sd(&all, ReprKind::Late), None);
        // One dataset: no section.
        r.dataset_seeds.retain(|p| p.dataset_seed == 0);
        assert!(across(&r).is_empty());
    }
}
