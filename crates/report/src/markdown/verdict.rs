//! The one rule behind every sentence of a report that says one result is lower than another or
//! that the two are tied: [`judge`]. A difference counts only when it exceeds the training
//! seeds' spread and, where the run measured it, the spread across simulated datasets (each the
//! two sides' standard deviations added in quadrature, [`Spread`]); anything smaller is a tie.
//!
//! Every section that compares two numbers builds its two [`Side`]s and asks [`judge`], so no two
//! sections can apply different rules; and every section that compares two Experiment 1
//! representations takes their sides from [`exp1_side`], so no two sections can compare
//! different numbers for the same pair (the example report once called Static and Late different
//! over the datasets and tied on Experiment 1's own dataset). [`exp1_verdicts`] lists those
//! verdicts, for the test that checks every such sentence of the committed reports.
//!
//! The training seeds' spread says how much a result moves when the same data is trained on
//! again; the datasets' spread, how much it moves on another dataset of the same kind (other
//! trials, another camera, other noise; `evtac_experiments::dataset_seeds`). A difference
//! smaller than either could be an accident of the one dataset or of the few seeds.

use evtac_experiments::results::{MeanStd, Results};
use evtac_repr::ReprKind;

use super::dataset_seeds;

/// What a difference between two results must exceed to be claimed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Spread {
    /// The training seeds' spread: the two standard deviations added in quadrature.
    pub seeds: f64,
    /// The datasets' spread, the same over each dataset's mean, where measured.
    pub datasets: Option<f64>,
}

impl Spread {
    /// The spread of a difference between `a` and `b`: over training seeds, and over datasets
    /// when both sides measured theirs.
    pub fn between(a: &Side, b: &Side) -> Spread {
        Spread {
            seeds: a.seeds_sd.hypot(b.seeds_sd),
            datasets: a.datasets_sd.zip(b.datasets_sd).map(|(x, y)| x.hypot(y)),
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

/// One side of a comparison: a mean test MAE (lower is better) and its spreads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Side {
    /// The mean: over training seeds, or over datasets when `datasets_sd` is measured.
    pub mean: f64,
    /// The standard deviation over training seeds (pooled over datasets where there are several).
    pub seeds_sd: f64,
    /// The standard deviation across simulated datasets, where the run measured it.
    pub datasets_sd: Option<f64>,
}

impl Side {
    /// A result over training seeds on one dataset.
    pub fn of(stats: &MeanStd) -> Side {
        Side {
            mean: stats.mean,
            seeds_sd: stats.std,
            datasets_sd: None,
        }
    }

    /// How the side reads beside a name: "0.309 ± 0.010" over seeds, or "0.302 over 5
    /// datasets, SD 0.023 across them" where several were measured.
    pub fn display(&self, datasets: usize) -> String {
        match self.datasets_sd {
            None => format!("{:.3} ± {:.3}", self.mean, self.seeds_sd),
            Some(d) => format!(
                "{:.3} over {datasets} datasets, SD {d:.3} across them",
                self.mean
            ),
        }
    }
}

/// Which side is lower, if beyond the spread.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The first side is lower beyond the spread.
    FirstLower,
    /// The second side is lower beyond the spread.
    SecondLower,
    /// The difference is within the spread: nothing is claimed.
    Tied,
}

/// A comparison of two sides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Judged {
    /// The verdict.
    pub verdict: Verdict,
    /// The second side's mean minus the first's.
    pub diff: f64,
    /// The spread the difference was held against.
    pub spread: Spread,
}

/// The rule: `a` against `b`, lower is better, a difference claimed only beyond [`Spread::bound`].
pub(super) fn judge(a: &Side, b: &Side) -> Judged {
    let spread = Spread::between(a, b);
    let diff = b.mean - a.mean;
    let verdict = if diff.abs() <= spread.bound() {
        Verdict::Tied
    } else if diff > 0.0 {
        Verdict::FirstLower
    } else {
        Verdict::SecondLower
    };
    Judged {
        verdict,
        diff,
        spread,
    }
}

/// The numbers every section compares for `kind` in Experiment 1: over the run's datasets (mean
/// of each dataset's mean, seeds' SD pooled, SD across datasets) where it simulated several,
/// else over the training seeds on Experiment 1's own dataset. `None` when `kind` was not run.
pub(super) fn exp1_side(r: &Results, kind: ReprKind) -> Option<Side> {
    let across = dataset_seeds::across(r);
    if let Some(a) = across.iter().find(|a| a.kind == kind) {
        return Some(a.side());
    }
    r.exp1
        .iter()
        .find(|e| e.name == kind)
        .map(|e| Side::of(&e.test.overall))
}

/// How many datasets [`exp1_side`] pools (1 when the run simulated one).
pub(super) fn exp1_datasets(r: &Results) -> usize {
    dataset_seeds::across(r)
        .first()
        .map_or(1, |a| a.means.len())
}

/// The verdict on every pair of Experiment 1's representations, in report order (each pair once,
/// the earlier first): what every sentence on such a pair must say.
pub fn exp1_verdicts(r: &Results) -> Vec<(ReprKind, ReprKind, Verdict)> {
    let kinds = ReprKind::in_order(r.exp1.iter().map(|e| e.name));
    let mut out = Vec::new();
    for (i, &a) in kinds.iter().enumerate() {
        for &b in &kinds[i + 1..] {
            if let (Some(x), Some(y)) = (exp1_side(r, a), exp1_side(r, b)) {
                out.push((a, b, judge(&x, &y).verdict));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn side(mean: f64, seeds_sd: f64, datasets_sd: Option<f64>) -> Side {
        Side {
            mean,
            seeds_sd,
            datasets_sd,
        }
    }

    #[test]
    fn the_bound_is_the_larger_spread() {
        let (a, b) = (side(0.2, 0.03, None), side(0.3, 0.04, None));
        let seeds_only = Spread::between(&a, &b);
        assert!((seeds_only.bound() - 0.05).abs() < 1e-12);
        assert!(
            seeds_only
                .describe()
                .starts_with("the seeds' spread of 0.050")
        );
        let both = Spread::between(&side(0.2, 0.03, Some(0.06)), &side(0.3, 0.04, Some(0.08)));
        assert!((both.bound() - 0.1).abs() < 1e-12);
        assert!(both.describe().contains("the datasets' (0.100)"));
        let small = Spread::between(&side(0.2, 0.03, Some(0.0)), &side(0.3, 0.04, Some(0.0)));
        assert_eq!(small.bound(), seeds_only.bound());
        // Only one side measured across datasets: the datasets' term is not made up.
        assert_eq!(
            Spread::between(&side(0.2, 0.03, Some(0.5)), &b).datasets,
            None
        );
    }

    #[test]
    fn a_difference_counts_only_beyond_the_bound_and_says_which_side_is_lower() {
        let low = side(0.10, 0.01, None);
        let high = side(0.20, 0.01, None);
        assert_eq!(judge(&low, &high).verdict, Verdict::FirstLower);
        assert_eq!(judge(&high, &low).verdict, Verdict::SecondLower);
        assert!((judge(&low, &high).diff - 0.1).abs() < 1e-12);
        let near = side(0.11, 0.01, None);
        assert_eq!(judge(&low, &near).verdict, Verdict::Tied);
        // Beyond the seeds' spread but within the datasets': a tie.
        let (a, b) = (side(0.10, 0.01, Some(0.1)), side(0.20, 0.01, Some(0.1)));
        assert_eq!(judge(&a, &b).verdict, Verdict::Tied);
        // Exactly at the bound: not beyond it.
        let (a, b) = (side(0.0, 0.0, None), side(0.0, 0.0, None));
        assert_eq!(judge(&a, &b).verdict, Verdict::Tied);
    }

    #[test]
    fn experiment_1_sides_pool_the_datasets_where_the_run_measured_them() {
        let r: Results =
            serde_json::from_str(include_str!("../../../../docs/report-example/results.json"))
                .expect("the example report's results");
        let s = exp1_side(&r, ReprKind::Static).expect("static ran");
        assert!(s.datasets_sd.is_some());
        let mean: f64 = r
            .dataset_seeds
            .iter()
            .filter(|p| p.name == ReprKind::Static)
            .map(|p| p.test.overall.mean)
            .sum::<f64>()
            / exp1_datasets(&r) as f64;
        assert!((s.mean - mean).abs() < 1e-12);
        let mut one = r.clone();
        one.dataset_seeds.clear();
        let s = exp1_side(&one, ReprKind::Static).expect("static ran");
        assert_eq!(s.datasets_sd, None);
        assert_eq!(exp1_datasets(&one), 1);
        let n = ReprKind::in_order(r.exp1.iter().map(|e| e.name)).len();
        assert_eq!(exp1_verdicts(&r).len(), n * (n - 1) / 2);
    }
}
