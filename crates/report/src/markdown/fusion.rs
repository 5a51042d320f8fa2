//! The report's "Beyond OR" section: whether the learned fusions (`Stacked`, `Late`) beat the
//! best single representation, by how much, at which scale and noise level, and whether in
//! Experiment 2 they keep static's stop-phase accuracy and dynamic's motion response.
//!
//! Every sentence is computed from the run's numbers. A difference counts only when it is
//! larger than the seeds' spread (the two standard deviations added in quadrature) and, in
//! Experiment 1 when the run simulated several datasets, larger than the datasets' spread too
//! ([`Spread`]); anything smaller is called a tie, so a verdict never rests on the luck of a few
//! seeds or of one dataset.

use std::fmt::Write as _;

use evtac_experiments::results::{Exp2Setting, MeanStd, Results};
use evtac_repr::ReprKind;

use super::dataset_seeds::{self, Spread};

/// Whether `fusion` beats `reference` (test MAE, lower is better) beyond `spread`.
fn beats(fusion: &MeanStd, reference: &MeanStd, spread: &Spread) -> bool {
    reference.mean - fusion.mean > spread.bound()
}

/// How `fusion` compares with `reference` (test MAE, lower is better), beyond `spread`.
fn compare(fusion: &MeanStd, reference: &MeanStd, spread: &Spread) -> String {
    let diff = fusion.mean - reference.mean;
    let percent = 100.0 * diff.abs() / reference.mean.max(f64::MIN_POSITIVE);
    if diff.abs() <= spread.bound() {
        format!("ties ({diff:+.3} deg, within {})", spread.describe())
    } else if diff < 0.0 {
        format!("beats it by {:.3} deg ({percent:.0} %)", -diff)
    } else {
        format!("is worse by {diff:.3} deg ({percent:.0} %)")
    }
}

/// The lower-MAE one of `Static` and `Dynamic` among `(kind, stats)`.
fn best_single(cells: &[(ReprKind, MeanStd)]) -> Option<(ReprKind, MeanStd)> {
    cells
        .iter()
        .filter(|(n, _)| matches!(n, ReprKind::Static | ReprKind::Dynamic))
        .min_by(|a, b| a.1.mean.total_cmp(&b.1.mean))
        .copied()
}

/// One line per fusion against the best single representation among `cells`; the wins
/// (`where_`, fusion, by how many degrees) are added to `wins`. `datasets_sd` gives a
/// representation's standard deviation across datasets where the run measured it.
fn against_best(
    md: &mut String,
    where_: &str,
    cells: &[(ReprKind, MeanStd)],
    datasets_sd: &dyn Fn(ReprKind) -> Option<f64>,
    wins: &mut Vec<String>,
) {
    let Some((best, best_stats)) = best_single(cells) else {
        return;
    };
    for fusion in ReprKind::FUSIONS {
        let Some((_, f)) = cells.iter().find(|(n, _)| *n == fusion) else {
            continue;
        };
        let spread = Spread::of(f, &best_stats, datasets_sd(fusion).zip(datasets_sd(best)));
        if beats(f, &best_stats, &spread) {
            wins.push(format!(
                "{fusion} at {where_} (by {:.3} deg)",
                best_stats.mean - f.mean
            ));
        }
        let _ = writeln!(
            md,
            "- {where_}: {fusion} ({}) against the best single representation, {best} ({}): \
             {}.",
            f.display(),
            best_stats.display(),
            compare(f, &best_stats, &spread)
        );
    }
}

/// The section, or nothing when the run trained no learned fusion.
pub(super) fn section(md: &mut String, r: &Results) {
    if !r.exp1.iter().any(|e| e.name.is_fusion()) {
        return;
    }
    let _ = writeln!(md, "## Beyond OR: learned fusion\n");
    let across = dataset_seeds::across(r);
    let _ = writeln!(
        md,
        "The paper fuses its two representations with a pixel-wise OR and leaves better fusion \
         to future work. evtac adds two learned fusions of the same tuned static and dynamic \
         parts (not tuned on their own): `Stacked`, both pooled frames side by side into one \
         1800-256-128-64-2 network, and `Late`, one 900-128 branch per frame whose outputs are \
         concatenated before the paper's 256-128-64-2 head. Scale `{}`; a difference counts only \
         beyond the seeds' spread{}.\n",
        r.run.scale,
        if across.is_empty() {
            ""
        } else {
            " and, in Experiment 1, beyond the datasets' too"
        }
    );
    let mut lines = String::new();
    let mut wins = Vec::new();
    let exp1: Vec<(ReprKind, MeanStd)> = r.exp1.iter().map(|e| (e.name, e.test.overall)).collect();
    let exp1_sd = |kind| dataset_seeds::datasets_sd(&across, kind);
    against_best(&mut lines, "Experiment 1", &exp1, &exp1_sd, &mut wins);
    let mut levels: Vec<f64> = r.noise.iter().map(|p| p.level).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    for level in levels.into_iter().filter(|&l| l != 1.0) {
        let cells: Vec<(ReprKind, MeanStd)> = r
            .noise
            .iter()
            .filter(|p| p.level == level)
            .map(|p| (p.name, p.test.overall))
            .collect();
        against_best(
            &mut lines,
            &format!("noise x{level}"),
            &cells,
            &|_| None,
            &mut wins,
        );
    }
    // Experiment 2 under the pause-inclusive setting: static's stop, dynamic's motion.
    let (setting, label) = (
        Exp2Setting::PauseMotionStop,
        Exp2Setting::PauseMotionStop.label(),
    );
    let cell = |kind: ReprKind| {
        r.exp2
            .iter()
            .find(|c| c.setting == setting && c.name == kind)
    };
    if let (Some(st), Some(dy)) = (cell(ReprKind::Static), cell(ReprKind::Dynamic)) {
        for fusion in ReprKind::FUSIONS {
            let Some(f) = cell(fusion) else { continue };
            let _ = writeln!(
                lines,
                "- Experiment 2, {label}: {fusion}'s stop phase ({}) against static's ({}): \
                 {}; its motion phase ({}) against dynamic's ({}): {}.",
                f.stop.overall.display(),
                st.stop.overall.display(),
                compare(
                    &f.stop.overall,
                    &st.stop.overall,
                    &Spread::of(&f.stop.overall, &st.stop.overall, None)
                ),
                f.motion.overall.display(),
                dy.motion.overall.display(),
                compare(
                    &f.motion.overall,
                    &dy.motion.overall,
                    &Spread::of(&f.motion.overall, &dy.motion.overall, None)
                )
            );
        }
    }
    let verdict = if wins.is_empty() {
        format!(
            "**In short:** at scale `{}`, no learned fusion beats the best single \
             representation beyond the spread, at any noise level measured.",
            r.run.scale
        )
    } else {
        format!(
            "**In short:** at scale `{}`, learned fusion beats the best single representation \
             beyond the spread for {}; everywhere else it does not.",
            r.run.scale,
            wins.join(", ")
        )
    };
    let _ = writeln!(md, "{verdict}\n");
    md.push_str(&lines);
    let _ = writeln!(
        md,
        "\nOn evtac's simulator, so a statement about the method on simulated data; the latency \
         table below has both fusions' cost per estimate (every static and dynamic update, and a \
         first layer over 1800 cells).\n"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(mean: f64, std: f64) -> MeanStd {
        MeanStd { mean, std, n: 3 }
    }

    fn seeds(a: &MeanStd, b: &MeanStd) -> String {
        compare(a, b, &Spread::of(a, b, None))
    }

    #[test]
    fn a_difference_counts_only_beyond_the_seeds_spread() {
        assert!(
            seeds(&ms(0.10, 0.01), &ms(0.20, 0.01)).starts_with("beats it by 0.100 deg (50 %)")
        );
        assert!(seeds(&ms(0.30, 0.01), &ms(0.20, 0.01)).starts_with("is worse by 0.100 deg"));
        assert!(seeds(&ms(0.21, 0.01), &ms(0.20, 0.01)).starts_with("ties (+0.010 deg"));
        // Beyond the seeds' spread but within the datasets': a tie.
        let (f, s) = (ms(0.10, 0.01), ms(0.20, 0.01));
        let wide = Spread::of(&f, &s, Some((0.1, 0.1)));
        assert!(compare(&f, &s, &wide).starts_with("ties (-0.100 deg, within the larger"));
        assert!(!beats(&f, &s, &wide));
        let cells = [
            (ReprKind::Static, ms(0.2, 0.0)),
            (ReprKind::Dynamic, ms(0.1, 0.0)),
            (ReprKind::Late, ms(0.05, 0.0)),
        ];
        assert_eq!(best_single(&cells).map(|b| b.0), Some(ReprKind::Dynamic));
        let (mut md, mut wins) = (String::new(), Vec::new());
        against_best(&mut md, "Experiment 1", &cells, &|_| None, &mut wins);
        assert_eq!(wins, ["Late at Experiment 1 (by 0.050 deg)"]);
        assert!(
            md.contains("Late (0.050 ± 0.000) against the best single representation, Dynamic"),
            "{md}"
        );
        assert!(md.contains("beats it by 0.050 deg (50 %)"), "{md}");
    }
}
