//! The report's "Beyond OR" section: whether the learned fusions (`Stacked`, `Late`) beat the
//! best single representation, by how much, at which scale and noise level, and whether in
//! Experiment 2 they keep static's stop-phase accuracy and dynamic's motion response.
//!
//! Every sentence is computed from the run's numbers and judged by the report's one rule
//! ([`super::verdict`]): a difference counts only beyond the seeds' spread and, in Experiment 1
//! when the run simulated several datasets, beyond the datasets' spread too, on the same numbers
//! the datasets section compares; anything smaller is called a tie, so a verdict never rests on
//! the luck of a few seeds or of one dataset.

use std::fmt::Write as _;

use evtac_experiments::results::{Exp2Setting, Results};
use evtac_repr::ReprKind;

use super::verdict::{self, Side, Verdict};

/// How `fusion` compares with `reference` (test MAE, lower is better), by the report's rule.
fn compare(fusion: &Side, reference: &Side) -> (String, Verdict) {
    let judged = verdict::judge(fusion, reference);
    let diff = -judged.diff; // the fusion's mean minus the reference's
    let percent = 100.0 * diff.abs() / reference.mean.max(f64::MIN_POSITIVE);
    let text = match judged.verdict {
        Verdict::Tied => format!("ties ({diff:+.3} deg, within {})", judged.spread.describe()),
        Verdict::FirstLower => format!("beats it by {:.3} deg ({percent:.0} %)", -diff),
        Verdict::SecondLower => format!("is worse by {diff:.3} deg ({percent:.0} %)"),
    };
    (text, judged.verdict)
}

/// The lower-MAE one of `Static` and `Dynamic` among `(kind, side)`.
fn best_single(cells: &[(ReprKind, Side)]) -> Option<(ReprKind, Side)> {
    cells
        .iter()
        .filter(|(n, _)| matches!(n, ReprKind::Static | ReprKind::Dynamic))
        .min_by(|a, b| a.1.mean.total_cmp(&b.1.mean))
        .copied()
}

/// One line per fusion against the best single representation among `cells` (each side shown as
/// over `datasets` datasets where it measured their spread); the wins (`where_`, fusion, by how
/// many degrees) are added to `wins`.
fn against_best(
    md: &mut String,
    where_: &str,
    cells: &[(ReprKind, Side)],
    datasets: usize,
    wins: &mut Vec<String>,
) {
    let Some((best, best_side)) = best_single(cells) else {
        return;
    };
    for fusion in ReprKind::FUSIONS {
        let Some((_, f)) = cells.iter().find(|(n, _)| *n == fusion) else {
            continue;
        };
        let (text, verdict) = compare(f, &best_side);
        if verdict == Verdict::FirstLower {
            wins.push(format!(
                "{fusion} at {where_} (by {:.3} deg)",
                best_side.mean - f.mean
            ));
        }
        let _ = writeln!(
            md,
            "- {where_}: {fusion} ({}) against the best single representation, {best} ({}): \
             {text}.",
            f.display(datasets),
            best_side.display(datasets),
        );
    }
}

/// The section, or nothing when the run trained no learned fusion.
pub(super) fn section(md: &mut String, r: &Results) {
    if !r.exp1.iter().any(|e| e.name.is_fusion()) {
        return;
    }
    let _ = writeln!(md, "## Beyond OR: learned fusion\n");
    let datasets = verdict::exp1_datasets(r);
    let _ = writeln!(
        md,
        "The paper fuses its two representations with a pixel-wise OR and leaves better fusion \
         to future work. evtac adds two learned fusions of the same tuned static and dynamic \
         parts (not tuned on their own): `Stacked`, both pooled frames side by side into one \
         1800-256-128-64-2 network, and `Late`, one 900-128 branch per frame whose outputs are \
         concatenated before the paper's 256-128-64-2 head. Scale `{}`; a difference counts only \
         beyond the seeds' spread{}.\n",
        r.run.scale,
        if datasets == 1 {
            ""
        } else {
            " and, in Experiment 1, beyond the datasets' too"
        }
    );
    let mut lines = String::new();
    let mut wins = Vec::new();
    let exp1: Vec<(ReprKind, Side)> = ReprKind::in_order(r.exp1.iter().map(|e| e.name))
        .into_iter()
        .filter_map(|kind| Some((kind, verdict::exp1_side(r, kind)?)))
        .collect();
    against_best(&mut lines, "Experiment 1", &exp1, datasets, &mut wins);
    let mut levels: Vec<f64> = r.noise.iter().map(|p| p.level).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    for level in levels.into_iter().filter(|&l| l != 1.0) {
        let cells: Vec<(ReprKind, Side)> = r
            .noise
            .iter()
            .filter(|p| p.level == level)
            .map(|p| (p.name, Side::of(&p.test.overall)))
            .collect();
        against_best(&mut lines, &format!("noise x{level}"), &cells, 1, &mut wins);
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
                compare(&Side::of(&f.stop.overall), &Side::of(&st.stop.overall)).0,
                f.motion.overall.display(),
                dy.motion.overall.display(),
                compare(&Side::of(&f.motion.overall), &Side::of(&dy.motion.overall)).0
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

    fn side(mean: f64, std: f64) -> Side {
        Side {
            mean,
            seeds_sd: std,
            datasets_sd: None,
        }
    }

    #[test]
    fn a_difference_counts_only_beyond_the_seeds_spread() {
        let text = |a: Side, b: Side| compare(&a, &b).0;
        assert!(
            text(side(0.10, 0.01), side(0.20, 0.01)).starts_with("beats it by 0.100 deg (50 %)")
        );
        assert!(text(side(0.30, 0.01), side(0.20, 0.01)).starts_with("is worse by 0.100 deg"));
        assert!(text(side(0.21, 0.01), side(0.20, 0.01)).starts_with("ties (+0.010 deg"));
        // Beyond the seeds' spread but within the datasets': a tie.
        let wide = |mean| Side {
            mean,
            seeds_sd: 0.01,
            datasets_sd: Some(0.1),
        };
        let (text_wide, verdict) = compare(&wide(0.10), &wide(0.20));
        assert!(
            text_wide.starts_with("ties (-0.100 deg, within the larger"),
            "{text_wide}"
        );
        assert_eq!(verdict, Verdict::Tied);
        let cells = [
            (ReprKind::Static, side(0.2, 0.0)),
            (ReprKind::Dynamic, side(0.1, 0.0)),
            (ReprKind::Late, side(0.05, 0.0)),
        ];
        assert_eq!(best_single(&cells).map(|b| b.0), Some(ReprKind::Dynamic));
        let (mut md, mut wins) = (String::new(), Vec::new());
        against_best(&mut md, "Experiment 1", &cells, 1, &mut wins);
        assert_eq!(wins, ["Late at Experiment 1 (by 0.050 deg)"]);
        assert!(
            md.contains("Late (0.050 ± 0.000) against the best single representation, Dynamic"),
            "{md}"
        );
        assert!(md.contains("beats it by 0.050 deg (50 %)"), "{md}");
    }
}
