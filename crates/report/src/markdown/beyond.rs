//! The report's "Beyond the paper's representations" section: the time surfaces, polarity
//! histograms and voxel grids (tonic's transforms, `evtac_repr::dense`) that Experiment 1
//! compared when the run asked for them (`evtac reproduce --beyond`), each with the settings
//! its own grid chose, its errors against the labels and the simulator's truth, its latency per
//! estimate, and whether it beats the paper's best representation by the report's one rule
//! ([`super::verdict`]: beyond the seeds' spread and, where measured, the datasets').

use std::fmt::Write as _;

use evtac_experiments::results::{Results, Tuning};
use evtac_repr::{ReprConfig, ReprKind};

use super::verdict::{self, Verdict};

/// The chosen settings of a real-valued kind, in words.
fn settings(config: &ReprConfig) -> String {
    match config {
        ReprConfig::TimeSurface(c) => match c.threshold {
            Some(x) => format!("tau {} ms, binarized above {x}", c.tau_ms),
            None => format!("tau {} ms, continuous", c.tau_ms),
        },
        ReprConfig::Histogram(c) => format!("window {} ms", c.window_ms),
        ReprConfig::VoxelGrid(c) => format!("window {} ms, {} bins", c.window_ms, c.bins),
        other => other.cache_key(),
    }
}

/// The tuning of `kind`, if the run has one.
fn tuning(r: &Results, kind: ReprKind) -> Option<&Tuning> {
    r.tuning.iter().find(|t| t.repr == kind)
}

/// The section, or nothing when Experiment 1 compared none of these kinds.
pub(super) fn section(md: &mut String, r: &Results) {
    let beyond: Vec<ReprKind> = ReprKind::in_order(r.exp1.iter().map(|e| e.name))
        .into_iter()
        .filter(|k| k.is_dense())
        .collect();
    if beyond.is_empty() {
        return;
    }
    let datasets = verdict::exp1_datasets(r);
    let _ = writeln!(
        md,
        "## Beyond the paper's representations: time surfaces, histograms, voxel grids\n\n\
         The paper builds its static frames by decaying integration and names time surfaces as \
         the other family; the field's libraries also feed networks polarity histograms and \
         voxel grids. evtac computes each as tonic 1.7 does (at each sample time, from the \
         events before it), pools every channel 8x8 into the same MLP (one 900-feature block per \
         channel), tunes each on its own grid and trains it with Experiment 1's seeds on the \
         same datasets. These are results on evtac's simulator, at scale `{}`: they say how the \
         kinds compare on its events, not on a real sensor. A difference counts only beyond the \
         seeds' spread{}.\n",
        r.run.scale,
        if datasets == 1 {
            ""
        } else {
            " and beyond the datasets'"
        }
    );
    let truth = r.exp1.iter().any(|e| e.test_truth.is_some());
    let _ = writeln!(
        md,
        "| Representation | Chosen settings | Test MAE against the labels |{} Latency per \
         estimate (median, p99; 1 ms grid) |\n| --- | --- | ---: |{} --- |",
        if truth {
            " against the truth (Experiment 1's dataset, over seeds) |"
        } else {
            ""
        },
        if truth { " ---: |" } else { "" }
    );
    for &kind in &beyond {
        let Some(e) = r.exp1.iter().find(|e| e.name == kind) else {
            continue;
        };
        let chosen =
            tuning(r, kind).map_or_else(|| settings(&e.config), |t| settings(&t.chosen_config));
        let side = verdict::exp1_side(r, kind);
        let mae = side.map_or_else(|| "-".into(), |s| s.display(datasets));
        let against_truth = match (truth, e.test_truth) {
            (true, Some(t)) => format!(" {:.3} ± {:.3} |", t.overall.mean, t.overall.std),
            (true, None) => " - |".into(),
            (false, _) => String::new(),
        };
        let latency = r
            .latency
            .iter()
            .filter(|c| c.name == kind)
            .min_by_key(|c| c.interval_ms)
            .map_or_else(
                || "-".into(),
                |c| format!("{:.0} µs, {:.0} µs", c.median_us, c.p99_us),
            );
        let _ = writeln!(
            md,
            "| {kind} | {chosen} | {mae} |{against_truth} {latency} |"
        );
    }
    let _ = writeln!(md);
    // Each against the paper's best representation of this run, by the one rule.
    let best = ReprKind::PAPER
        .into_iter()
        .filter_map(|k| Some((k, verdict::exp1_side(r, k)?)))
        .min_by(|a, b| a.1.mean.total_cmp(&b.1.mean));
    let Some((best, best_side)) = best else {
        return;
    };
    let mut better = Vec::new();
    for &kind in &beyond {
        let Some(side) = verdict::exp1_side(r, kind) else {
            continue;
        };
        let judged = verdict::judge(&side, &best_side);
        let text = match judged.verdict {
            Verdict::FirstLower => {
                better.push(kind);
                format!(
                    "lower by {:.3} deg, beyond {}",
                    judged.diff,
                    judged.spread.describe()
                )
            }
            Verdict::SecondLower => format!(
                "higher by {:.3} deg, beyond {}",
                -judged.diff,
                judged.spread.describe()
            ),
            Verdict::Tied => format!(
                "tied ({:+.3} deg, within {})",
                -judged.diff,
                judged.spread.describe()
            ),
        };
        let _ = writeln!(
            md,
            "- {kind} against the paper's best here, {best} ({}): {text}.",
            best_side.display(datasets)
        );
    }
    let names = |kinds: &[ReprKind]| {
        kinds
            .iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let _ = writeln!(
        md,
        "\n**In short:** on this simulator at scale `{}`, {}.\n",
        r.run.scale,
        if better.is_empty() {
            format!(
                "none of {} beats the paper's best representation ({best}) beyond the spread",
                names(&beyond)
            )
        } else {
            format!(
                "{} beat{} the paper's best representation ({best}) beyond the spread",
                names(&better),
                if better.len() == 1 { "s" } else { "" }
            )
        }
    );
}
