//! The report's "Experiment 1: hyperparameter search" section: each representation's grid of
//! validation MAEs, the setting chosen, and what the grid can and cannot say of that choice.
//!
//! Two things are said in words rather than left to the table. A chosen setting on the edge of
//! its grid (the largest or smallest time tried, or the largest threshold) is flagged: the
//! optimum may lie beyond it, so the grid is too small to place it. And the margin between the
//! chosen setting and the next best is judged by the report's one rule ([`super::verdict`])
//! against the spread over training seeds that Experiment 1 measured for the chosen setting on
//! validation: tuning runs are single runs, so a margin within that spread does not single out
//! the choice.

use std::fmt::Write as _;

#[cfg(test)]
use evtac_experiments::results::{MaeStats, Recheck};
use evtac_experiments::results::{MeanStd, Results, Tuning, TuningRun};
use evtac_repr::ReprKind;

use super::verdict::{self, Side, Verdict};

/// Where a chosen value sits in the values tried.
fn edge_of(values: &[f64], chosen: f64, lower_bound_is_natural: bool) -> Option<&'static str> {
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if values.len() < 2 || lo == hi {
        None
    } else if chosen == hi {
        Some("the largest")
    } else if chosen == lo && !lower_bound_is_natural {
        Some("the smallest")
    } else {
        None
    }
}

/// The distinct values of one parameter among `runs`, ascending.
fn distinct(runs: &[TuningRun], of: fn(&TuningRun) -> f64) -> Vec<f64> {
    let mut v: Vec<f64> = runs.iter().map(of).collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// The sentence flagging a chosen setting on its grid's edge, with the validation MAE along the
/// edge's parameter at the chosen other one; `None` when the choice is inside the grid.
fn edge_sentence(t: &Tuning, unit: &str) -> Option<String> {
    let second = axes(t.repr).1;
    let times = distinct(&t.runs, |r| r.time_ms);
    let thresholds = distinct(&t.runs, |r| r.threshold);
    // A time of zero is no decay / no window: nothing lies below the smallest positive one in
    // that direction that the grid could have missed, but the largest time is an edge.
    let time_edge = edge_of(&times, t.chosen_time_ms, false);
    // Threshold 0 keeps every event: no smaller threshold exists.
    let threshold_edge = edge_of(&thresholds, t.chosen_threshold, true);
    let mut parts = Vec::new();
    if let Some(which) = time_edge {
        let along: Vec<String> = t
            .runs
            .iter()
            .filter(|r| r.threshold == t.chosen_threshold)
            .map(|r| format!("{:.3} at {} ms", r.val.overall, r.time_ms))
            .collect();
        parts.push(format!(
            "the chosen {unit} ({} ms) is {which} tried (validation MAE at {second} {}: {})",
            t.chosen_time_ms,
            t.chosen_threshold,
            along.join(", ")
        ));
    }
    if let Some(which) = threshold_edge {
        parts.push(format!(
            "the chosen {second} ({}) is {which} tried",
            t.chosen_threshold
        ));
    }
    (!parts.is_empty()).then(|| {
        format!(
            "**On the grid's edge:** {}. The optimum may lie beyond it: this grid is too small to \
             place it.",
            parts.join("; ")
        )
    })
}

/// The sentence on the chosen setting's margin over the next best, judged against the spread
/// over training seeds Experiment 1 measured for the chosen setting on validation.
fn margin_sentence(t: &Tuning, r: &Results, unit: &str) -> Option<String> {
    let second = axes(t.repr).1;
    let mut runs: Vec<&TuningRun> = t.runs.iter().collect();
    runs.sort_by(|a, b| a.val.overall.total_cmp(&b.val.overall));
    let (best, next) = (runs.first()?, runs.get(1)?);
    let exp1 = r.exp1.iter().find(|e| e.name == t.repr)?;
    let val: Vec<f64> = exp1.val_runs.iter().map(|m| m.overall).collect();
    if val.len() < 2 {
        return None;
    }
    let seeds_sd = MeanStd::of(&val).std;
    let side = |run: &TuningRun| Side {
        mean: run.val.overall,
        seeds_sd,
        datasets_sd: None,
    };
    let judged = verdict::judge(&side(best), &side(next));
    let (is, _) = match judged.verdict {
        Verdict::Tied => ("within", false),
        _ => ("beyond", true),
    };
    Some(format!(
        "The next best setting ({unit} {} ms, {second} {}) is {:.3} deg higher on validation, \
         {is} {} (each single tuning run given the spread of the chosen setting's validation \
         MAE over Experiment 1's {} training seeds; the grid's settings were not trained again \
         with more seeds){}.",
        next.time_ms,
        next.threshold,
        judged.diff,
        judged.spread.describe(),
        val.len(),
        if judged.verdict == Verdict::Tied {
            ": the grid does not single out the choice"
        } else {
            ""
        }
    ))
}

/// The recheck of the best settings with several seeds ([`Tuning::recheck`]): a table, and
/// whether the chosen setting is lower than each other one beyond the seeds' spread.
fn recheck(md: &mut String, t: &Tuning, unit: &str) {
    let Some(chosen) = t.recheck.first() else {
        return;
    };
    let second = axes(t.repr).1;
    let _ = writeln!(
        md,
        "The {} best settings trained again, each with {} seeds (the grid's run the first) and \
         the grid's epochs:\n\n| {unit} (ms) | {second} | val MAE over seeds |\n| ---: | ---: | \
         ---: |",
        t.recheck.len(),
        chosen.seeds.len(),
    );
    for c in &t.recheck {
        let _ = writeln!(
            md,
            "| {} | {} | {} |",
            c.time_ms,
            c.threshold,
            c.val.overall.display()
        );
    }
    let (mut beyond, mut within, mut reversed) = (Vec::new(), Vec::new(), Vec::new());
    for other in &t.recheck[1..] {
        let judged = verdict::judge(
            &Side::of(&chosen.val.overall),
            &Side::of(&other.val.overall),
        );
        let name = format!("{unit} {} ms, {second} {}", other.time_ms, other.threshold);
        match judged.verdict {
            Verdict::FirstLower => beyond.push(name),
            Verdict::Tied => within.push(format!("{name} ({:+.3} deg)", judged.diff)),
            Verdict::SecondLower => reversed.push(format!("{name} (by {:.3} deg)", -judged.diff)),
        }
    }
    let mut parts = Vec::new();
    if !beyond.is_empty() {
        parts.push(format!(
            "the chosen setting is lower than {} beyond the seeds' spread",
            beyond.join(", ")
        ));
    }
    if !within.is_empty() {
        parts.push(format!(
            "it is not lower beyond the seeds' spread than {}",
            within.join(", ")
        ));
    }
    if !reversed.is_empty() {
        parts.push(format!(
            "{} {} lower than it beyond the seeds' spread",
            reversed.join(", "),
            if reversed.len() == 1 { "is" } else { "are" }
        ));
    }
    let verdict = if within.is_empty() && reversed.is_empty() {
        format!("{}: the choice stands.", parts.join("; "))
    } else {
        format!(
            "{}: with these seeds the grid's single runs do not single out the choice.",
            parts.join("; ")
        )
    };
    let _ = writeln!(md, "\nBy the report's rule, {verdict}\n");
}

/// A tuned kind's time axis, its second axis, and what the paper chose: the paper's two, and the
/// kinds beyond the paper (whose grids are evtac's: `evtac_experiments::dense_grid`).
fn axes(kind: ReprKind) -> (&'static str, &'static str, &'static str) {
    match kind {
        ReprKind::Static => ("tau", "threshold", "paper: 1000 ms, threshold 2"),
        ReprKind::TimeSurface => (
            "tau",
            "threshold",
            "threshold 0 is the continuous surface; the paper tunes none",
        ),
        ReprKind::Histogram => ("window", "threshold", "the paper tunes none"),
        ReprKind::VoxelGrid => ("window", "bins", "the paper tunes none"),
        _ => ("window", "threshold", "paper: 640 ms, threshold 0"),
    }
}

/// The section.
pub(super) fn section(md: &mut String, r: &Results) {
    let _ = writeln!(md, "## Experiment 1: hyperparameter search\n");
    for t in &r.tuning {
        let (unit, second, paper_choice) = axes(t.repr);
        let _ = writeln!(
            md,
            "{}: chosen {unit} {} ms, {second} {} ({paper_choice}).\n",
            t.repr, t.chosen_time_ms, t.chosen_threshold
        );
        let _ = writeln!(
            md,
            "| {unit} (ms) | {second} | val MAE overall | pitch | roll |\n| ---: | ---: | ---: | \
             ---: | ---: |"
        );
        for run in &t.runs {
            let _ = writeln!(
                md,
                "| {} | {} | {:.3} | {:.3} | {:.3} |",
                run.time_ms, run.threshold, run.val.overall, run.val.pitch, run.val.roll
            );
        }
        let _ = writeln!(md);
        if let Some(sentence) = edge_sentence(t, unit) {
            let _ = writeln!(md, "{sentence}\n");
        }
        // With the recheck's seeds the margin is measured; without, it is judged against the
        // spread Experiment 1 measured.
        if t.recheck.is_empty() {
            if let Some(sentence) = margin_sentence(t, r, unit) {
                let _ = writeln!(md, "{sentence}\n");
            }
        } else {
            recheck(md, t, unit);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_experiments::results::Mae;

    fn run(time_ms: f64, threshold: f64, mae: f64) -> TuningRun {
        TuningRun {
            time_ms,
            threshold,
            val: Mae {
                overall: mae,
                pitch: mae,
                roll: mae,
            },
        }
    }

    fn example() -> Results {
        serde_json::from_str(include_str!("../../../../docs/report-example/results.json"))
            .expect("the example report's results")
    }

    #[test]
    fn a_choice_on_the_largest_time_or_threshold_is_flagged_and_one_inside_is_not() {
        let mut t = example().tuning[0].clone();
        t.runs = vec![
            run(100.0, 0.0, 0.5),
            run(1000.0, 0.0, 0.4),
            run(100.0, 2.0, 0.45),
            run(1000.0, 2.0, 0.3),
        ];
        (t.chosen_time_ms, t.chosen_threshold) = (1000.0, 2.0);
        let text = edge_sentence(&t, "tau").expect("on the edge");
        assert!(
            text.contains("the chosen tau (1000 ms) is the largest tried"),
            "{text}"
        );
        assert!(text.contains("0.450 at 100 ms, 0.300 at 1000 ms"), "{text}");
        assert!(
            text.contains("the chosen threshold (2) is the largest tried"),
            "{text}"
        );
        t.runs.push(run(3000.0, 2.0, 0.35));
        t.runs.push(run(1000.0, 4.0, 0.6));
        assert_eq!(edge_sentence(&t, "tau"), None);
        // Threshold 0 is not an edge: no smaller threshold exists. The smallest time is.
        (t.chosen_time_ms, t.chosen_threshold) = (100.0, 0.0);
        let text = edge_sentence(&t, "tau").expect("on the edge");
        assert!(text.contains("is the smallest tried"), "{text}");
        assert!(!text.contains("threshold (0)"), "{text}");
    }

    #[test]
    fn the_margin_over_the_next_best_is_judged_against_the_seeds_spread() {
        let mut r = example();
        let mut t = r.tuning[0].clone();
        t.runs = vec![run(100.0, 0.0, 0.50), run(1000.0, 0.0, 0.30)];
        let kind = t.repr;
        let exp1 = r.exp1.iter_mut().find(|e| e.name == kind).expect("ran");
        exp1.val_runs = same_axes(&[0.30, 0.31, 0.29]);
        let text = margin_sentence(&t, &r, "tau").expect("a margin");
        assert!(
            text.contains("0.200 deg higher on validation, beyond"),
            "{text}"
        );
        t.runs[0].val.overall = 0.305;
        let text = margin_sentence(&t, &r, "tau").expect("a margin");
        assert!(text.contains("within"), "{text}");
        assert!(
            text.ends_with("the grid does not single out the choice."),
            "{text}"
        );
    }

    /// One MAE per value, the same on both axes.
    fn same_axes(maes: &[f64]) -> Vec<Mae> {
        maes.iter()
            .map(|&m| Mae {
                overall: m,
                pitch: m,
                roll: m,
            })
            .collect()
    }

    #[test]
    fn the_recheck_says_whether_the_choice_stands_beyond_the_seeds_spread() {
        let rechecked = |time_ms, maes: &[f64]| {
            let val_runs = same_axes(maes);
            Recheck {
                time_ms,
                threshold: 2.0,
                seeds: (0..maes.len() as u64).collect(),
                val: MaeStats::of(&val_runs),
                val_runs,
            }
        };
        let mut t = example().tuning[0].clone();
        t.recheck = vec![
            rechecked(2000.0, &[0.30, 0.31, 0.29]),
            rechecked(3000.0, &[0.50, 0.51, 0.49]),
        ];
        let mut md = String::new();
        recheck(&mut md, &t, "tau");
        assert!(md.contains("| 3000 | 2 | 0.500 ± 0.010 |"), "{md}");
        assert!(md.contains("the choice stands"), "{md}");
        t.recheck.push(rechecked(5000.0, &[0.31, 0.30, 0.32]));
        t.recheck.push(rechecked(10000.0, &[0.10, 0.11, 0.09]));
        let mut md = String::new();
        recheck(&mut md, &t, "tau");
        assert!(
            md.contains("the chosen setting is lower than tau 3000 ms, threshold 2 beyond"),
            "{md}"
        );
        assert!(
            md.contains("not lower beyond the seeds' spread than tau 5000 ms, threshold 2 (+0.010"),
            "{md}"
        );
        assert!(
            md.contains("tau 10000 ms, threshold 2 (by 0.200 deg) is lower than it beyond"),
            "{md}"
        );
        assert!(md.contains("do not single out the choice"), "{md}");
    }
}
