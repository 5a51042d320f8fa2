//! The report: `OUT/report.md` (tables, with the paper's numbers beside ours), `OUT/results.json`
//! (every number) and the figures under `OUT/figures/`.

use crate::plots;
use evtac_events::IoError;
use evtac_experiments::results::{
    Exp2Setting, Exp3Point, MaeStats, NoisePoint, Results, RunInfo, Scale, SensorKind,
};
use evtac_repr::ReprKind;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod beyond;
mod capture_filter;
mod dataset_seeds;
mod fusion;
mod label_noise;
mod labels;
mod paced_latency;
mod paired;
mod repeat_split;
mod tuning;
mod verdict;

pub use verdict::{Verdict, exp1_verdicts};

/// Test runs whose pitch, roll and overall MAE are each `values`' value: the sections' tests
/// build their results from these.
#[cfg(test)]
fn runs_of(values: &[f64]) -> Vec<evtac_experiments::results::Mae> {
    values
        .iter()
        .map(|&m| evtac_experiments::results::Mae {
            overall: m,
            pitch: m,
            roll: m,
        })
        .collect()
}

/// An Experiment 1 result of `name` with test runs of `values` (see [`runs_of`]).
#[cfg(test)]
fn repr_of(name: ReprKind, values: &[f64]) -> evtac_experiments::results::Exp1Repr {
    let runs = runs_of(values);
    evtac_experiments::results::Exp1Repr {
        name,
        config: name.config(Default::default(), Default::default()),
        seeds: (0..values.len() as u64).collect(),
        test: evtac_experiments::results::MaeStats::of(&runs),
        val_runs: runs.clone(),
        runs,
        truth_runs: Vec::new(),
        test_truth: None,
        labels_truth: None,
    }
}

/// A mean and a standard deviation, in degrees.
pub type MeanStd = (f64, f64);

/// The paper's Table (Experiment 1, test MAE in degrees, mean ± std over ten runs):
/// (representation, overall, pitch, roll).
pub const PAPER_TABLE: [(ReprKind, MeanStd, MeanStd, MeanStd); 3] = [
    (
        ReprKind::Static,
        (0.160, 0.004),
        (0.158, 0.005),
        (0.163, 0.008),
    ),
    (
        ReprKind::Dynamic,
        (0.186, 0.007),
        (0.183, 0.007),
        (0.189, 0.010),
    ),
    (
        ReprKind::Combined,
        (0.173, 0.006),
        (0.169, 0.008),
        (0.177, 0.006),
    ),
];
/// A plan's list or pair as JSON (`[250.0,1000.0]`), as `results.json` holds it.
fn json<T: serde::Serialize + ?Sized>(value: &T) -> String {
    serde_json::to_string(value).unwrap_or_else(|e| format!("? ({e})"))
}

/// The report names of `kinds`, as a table row's cells.
fn titles(kinds: &[ReprKind]) -> String {
    kinds
        .iter()
        .map(|k| k.title())
        .collect::<Vec<_>>()
        .join(" | ")
}

/// The paper's best Experiment 2 numbers (static, pause-inclusive): motion and stop MAE.
pub const PAPER_EXP2_STATIC: (f64, f64) = (0.211, 0.251);

/// Errors writing the report.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be written.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A figure could not be drawn.
    #[error(transparent)]
    Plot(#[from] plots::Error),
}

/// The figures of a report: file name (under `figures/`) and one-line caption.
pub const FIGURES: [(&str, &str); 9] = [
    (
        "tuning.png",
        "Validation MAE of the static (decay tau, threshold) and dynamic (window, threshold) settings, one parameter varied with the other fixed; the chosen setting in red.",
    ),
    (
        "phase_mae.png",
        "Experiment 2: motion- and stop-phase test MAE per representation under the three training settings (mean ± std over seeds).",
    ),
    (
        "example_trial.png",
        "Experiment 2: an example test trial's pitch and roll, ground truth and each representation's estimate (pause-inclusive motion + stop models), the stop shaded.",
    ),
    (
        "contours.png",
        "Static and dynamic binary contours at half the total tilt: slowest vs fastest speed and shallowest vs deepest depth (red: first, orange: second, white: both).",
    ),
    (
        "speed_depth.png",
        "Experiment 3: test MAE of the Experiment 1 models against speed and depth (mean ± std over seeds); hollow markers are unseen (interpolated) values.",
    ),
    (
        "latency.png",
        "Processing time per estimate (events in to estimate out, as `evtac online` reports it) at each sampling interval: box 25-75 %, black bar median, triangle P99, whiskers min-max; dashed the interval, solid the paper's 10 ms bound.",
    ),
    (
        "noise.png",
        "Experiment 1 at other background noise: test MAE per representation against the factor on the simulator's leak, shot and hot-pixel noise (mean ± std over seeds; 1 is Experiment 1).",
    ),
    (
        "representations.png",
        "The paper's Fig. 2 for one Experiment 1 test sample (the middle motion sample of the first test trial): the events of the last dynamic window (ON red, OFF blue, both magenta), the static, dynamic and combined binary frames (240x240, tuned settings, no-contact mask applied), and below each frame its 30x30 pooled features, the models' input (black 0, white 1).",
    ),
    (
        "sensor.png",
        "The sensor: what the camera inside the tip sees at rest and in contact (in contact: the test trial of the next figure, at its sample's tilt), the centered 240x240 crop outlined.",
    ),
];

/// The caption of `sensor.png` for what it shows: the simulator's camera images, or event counts
/// of a recorded dataset (which has no frames to show).
fn sensor_caption(kind: SensorKind) -> String {
    match kind {
        SensorKind::Simulated => format!(
            "{} Simulated: the simulator's camera brightness (gamma 0.5) of the pins out of \
             contact and pressed in at the trial's depth and the sample's tilt.",
            FIGURES[8].1
        ),
        SensorKind::EventCounts => {
            "The sensor as recorded: a real dataset has no camera frames, so \
             these are event-count images (events per pixel, log scale) of the no-contact \
             recording (when the dataset was opened with its mask) and of the first test trial's \
             motion phase, the centered 240x240 crop outlined."
                .to_string()
        }
    }
}

fn cell(s: &evtac_experiments::results::MeanStd) -> String {
    if s.n == 0 { "-".into() } else { s.display() }
}

/// A cell of a table whose columns are representations: the MAE against the labels and, where
/// the run measured it, against the simulator's exact truth ("0.309 ± 0.010 / 0.301").
fn cell_with_truth(
    labels: &evtac_experiments::results::MeanStd,
    truth: Option<&evtac_experiments::results::MaeStats>,
) -> String {
    match truth {
        Some(t) if labels.n > 0 => format!("{} / {:.3}", labels.display(), t.overall.mean),
        _ => cell(labels),
    }
}

/// The sentence under a table whose cells are [`cell_with_truth`]s.
const TRUTH_CELLS: &str = "Each cell: mean ± std over seeds against the labels / the mean against the \
                           simulator's exact truth.";

fn paper(v: (f64, f64)) -> String {
    format!("{:.3} ± {:.3}", v.0, v.1)
}

/// One sentence on an Experiment 3 axis's design: the seen and unseen levels of `axis` (e.g.
/// `speed`) in `unit`, and how far each unseen level is from the nearest seen one. The paper
/// gives neither its levels nor their count, so the sentence says these are evtac's.
fn exp3_design(values: &[(f64, bool)], axis: &str, unit: &str) -> String {
    let list = |seen: bool| {
        let v: Vec<String> = values
            .iter()
            .filter(|&&(_, s)| s == seen)
            .map(|(v, _)| v.to_string())
            .collect();
        if v.is_empty() {
            "none".into()
        } else {
            v.join(", ")
        }
    };
    let nearest_seen = |v: f64| {
        values
            .iter()
            .filter(|&&(_, seen)| seen)
            .map(|&(s, _)| (s - v).abs())
            .min_by(f64::total_cmp)
    };
    let gaps: Vec<f64> = values
        .iter()
        .filter(|&&(_, seen)| !seen)
        .filter_map(|&(v, _)| nearest_seen(v))
        .collect();
    let widest = gaps.iter().copied().reduce(f64::max);
    let narrowest = gaps.iter().copied().reduce(f64::min);
    let spacing = match (narrowest, widest) {
        (Some(n), Some(w)) if (w - n).abs() < 1e-9 => {
            format!(" Each unseen {axis} is {w} {unit} from the nearest seen one.")
        }
        (Some(n), Some(w)) => {
            format!(" Unseen {axis}s are {n} to {w} {unit} from the nearest seen one.")
        }
        _ => String::new(),
    };
    format!(
        "Seen {axis}s (in the training set, {unit}): {}; unseen: {}.{spacing} The paper gives \
         neither its levels nor their count: these are evtac's.",
        list(true),
        list(false)
    )
}

/// The unseen levels of one Experiment 3 axis whose mean error exceeds both seen neighbours'
/// (the nearest seen level below and above) beyond the seeds' spread (by the report's one rule,
/// [`verdict::judge`], against each neighbour), per representation, as a sentence; the paper reports none ("did not cause
/// abrupt mean error increases"), so any found is said in words, not left to the table.
fn unseen_penalties(points: &[Exp3Point], (axis, unit): (&str, &str)) -> (String, bool) {
    let mut found = Vec::new();
    for name in ReprKind::in_order(points.iter().map(|p| p.name)) {
        let mut own: Vec<&Exp3Point> = points.iter().filter(|p| p.name == name).collect();
        own.sort_by(|a, b| a.value.total_cmp(&b.value));
        for (i, p) in own.iter().enumerate().filter(|(_, p)| !p.seen) {
            let below = own[..i].iter().rev().find(|q| q.seen);
            let above = own[i + 1..].iter().find(|q| q.seen);
            let (Some(lo), Some(hi)) = (below, above) else {
                continue;
            };
            let (m, a, b) = (
                p.stats.overall.mean,
                lo.stats.overall.mean,
                hi.stats.overall.mean,
            );
            let unseen = verdict::Side::of(&p.stats.overall);
            let below = verdict::judge(&verdict::Side::of(&lo.stats.overall), &unseen);
            let above = verdict::judge(&verdict::Side::of(&hi.stats.overall), &unseen);
            if below.verdict == Verdict::FirstLower && above.verdict == Verdict::FirstLower {
                let spread = below.spread.seeds.max(above.spread.seeds);
                found.push(format!(
                    "{} at {} {unit} ({m:.3} against {a:.3} at {} and {b:.3} at {}; seeds' \
                     spread at most {spread:.3})",
                    name.title(),
                    p.value,
                    lo.value,
                    hi.value
                ));
            }
        }
    }
    if found.is_empty() {
        let text = format!(
            "No unseen {axis} is worse than both its seen neighbours by more than the seeds' \
             spread (the paper reports no such penalty either)."
        );
        (text, false)
    } else {
        let text = format!(
            "**Unseen {axis}s worse than both seen neighbours by more than the seeds' spread:** \
             {}. The paper reports no such penalty (\"did not cause abrupt mean error \
             increases\"): on this simulator, these models do not interpolate between the \
             {axis}s they were trained on as the paper's did.",
            found.join("; ")
        );
        (text, true)
    }
}

/// An Experiment 3 table, after the sentence on its design, and the sentence on unseen levels;
/// returns whether it names any (see [`unseen_penalties`]).
fn exp3_table(md: &mut String, points: &[Exp3Point], (axis, unit): (&str, &str)) -> bool {
    let mut values: Vec<(f64, bool)> = points.iter().map(|p| (p.value, p.seen)).collect();
    values.sort_by(|a, b| a.0.total_cmp(&b.0));
    values.dedup_by(|a, b| a.0 == b.0);
    let _ = writeln!(md, "{}\n", exp3_design(&values, axis, unit));
    let unit_name = unit;
    let unit = format!("{axis} ({unit})");
    let names = ReprKind::in_order(points.iter().map(|p| p.name));
    let _ = writeln!(
        md,
        "| {unit} | seen | trials | {} |\n| ---: | :---: | ---: |{}",
        titles(&names),
        " ---: |".repeat(names.len())
    );
    for (v, seen) in values {
        let get = |name: ReprKind| {
            points
                .iter()
                .find(|p| p.value == v && p.name == name)
                .map_or("-".to_string(), |p| {
                    cell_with_truth(&p.stats.overall, p.truth.as_ref())
                })
        };
        let trials = points.iter().find(|p| p.value == v).map_or(0, |p| p.trials);
        let cells: Vec<String> = names.iter().map(|&n| get(n)).collect();
        let _ = writeln!(
            md,
            "| {v} | {} | {trials} | {} |",
            if seen { "seen" } else { "unseen" },
            cells.join(" | ")
        );
    }
    if points.iter().any(|p| p.truth.is_some()) {
        let _ = writeln!(md, "\n{TRUTH_CELLS}");
    }
    let (text, flagged) = unseen_penalties(points, (axis, unit_name));
    let _ = writeln!(md, "\n{text}");
    flagged
}

/// What the sensor figure shows: from its view when the run made one, else from
/// `results.json`'s record of it.
fn sensor_kind(r: &Results) -> Option<SensorKind> {
    r.sensor.as_ref().map(|v| v.kind).or(r.sensor_kind)
}

/// Whether the run's data came from evtac's simulator: its sensor figure is the simulator's, or
/// its labels were checked against the simulator's exact truth (which recordings do not have).
fn simulated(r: &Results) -> bool {
    sensor_kind(r) == Some(SensorKind::Simulated)
        || r.labels.as_ref().is_some_and(|l| l.truth_rms_deg.is_some())
}

/// The report's first paragraph after its heading: what the numbers are about, and what they do
/// not show. On simulated data every result is a result about the method on evtac's simulator;
/// nothing here was measured on a real sensor, so no sentence may say that a comparison carries
/// over to one.
fn scope(r: &Results) -> String {
    let mut text = if simulated(r) {
        "**What this report measures.** The data are evtac's simulator's (`evtac simulate`; its \
         model and parameters in `docs/simulator.md`), so every number below, the absolute \
         errors and the comparisons between representations and settings alike, is a result \
         about the method on that simulator. No real labelled recording went through these \
         experiments, and nothing here measures how any of it transfers to a real NeuroTac. \
         Before it can be said of a real sensor, that sensor's labelled recordings must go \
         through the same experiments (`evtac import`, then `evtac reproduce --data DIR`: \
         `docs/real-data.md`), and the simulator's unmeasured parameters be set from what those \
         recordings show (`evtac stats --sim-params`)."
            .to_string()
    } else {
        "**What this report measures.** The data are recordings given with `--data` (made a \
         dataset by `evtac import`), so the numbers below are about the method on those \
         recordings and their labels; the simulator plays no part in them."
            .to_string()
    };
    if r.run.plan.datasets <= 1 && r.dataset_seeds.is_empty() {
        text.push_str(
            " Experiment 1 ran on one dataset, so its standard deviations are over training \
             seeds only: the spread across datasets was not measured (`evtac reproduce \
             --datasets N`), and every difference below is judged against the seeds' spread \
             alone, which may understate it.",
        );
    }
    if r.repeat_split.is_some() {
        text.push_str(
            " Experiment 1's headline split is the paper's (a condition's repeats may fall in \
             training and test); \"Repeats across the split\" gives it beside a split that \
             keeps each condition's repeats on one side.",
        );
    } else if !r.run.plan.repeat_split {
        text.push_str(
            " Experiment 1's split is the paper's, so a condition's repeats may fall in \
             training and test; the split that keeps them on one side was not run here, so \
             these errors include what a repeat of the test condition in training gives.",
        );
    }
    text
}

/// The report's Markdown.
pub fn markdown(r: &Results, figures: &[&str]) -> String {
    let mut md = String::new();
    let plan = &r.run.plan;
    let _ = writeln!(
        md,
        "# evtac reproduction report\n\nScale `{}`, seed {}. Every number below was measured by \
         this run (`results.json` has them all); the paper's numbers are quoted beside ours where \
         they compare.\n",
        r.run.scale, r.run.seed
    );
    let _ = writeln!(md, "{}\n", scope(r));
    let _ = writeln!(md, "## Run\n");
    let _ = writeln!(md, "| dataset | trials |\n| --- | ---: |");
    for (name, n) in &r.run.datasets {
        let _ = writeln!(md, "| {name} | {n} |");
    }
    let _ = writeln!(md);
    if let Some(inputs) = &r.run.inputs {
        let _ = writeln!(
            md,
            "Calibration: {}. No-contact mask: {}.{}\n",
            inputs.calibration_text(),
            inputs.mask_text(),
            match inputs.filters.is_empty() {
                true => String::new(),
                false => format!(
                    " Event filters on every recording, before the crop: {}.",
                    inputs.filters_text()
                ),
            }
        );
    }
    let _ = writeln!(
        md,
        "Plan: static taus {} ms x thresholds {}; dynamic windows {} ms x thresholds {} (the {} \
         grid); {}{}; {} epochs per tuning run, {} epochs per final run; {} seeds per \
         representation in Experiment 1, {} in Experiment 2; Experiment 1 on {} simulated \
         dataset{}; latency on up to {} test trials at {} ms.\n",
        json(&plan.static_taus_ms),
        json(&plan.static_thresholds),
        json(&plan.dynamic_windows_ms),
        json(&plan.dynamic_thresholds),
        plan.grid.name(),
        if plan.full_grid {
            "every combination (the paper's grid search)".to_string()
        } else {
            format!(
                "a cross through the paper's chosen settings (static {}, dynamic {}: one parameter \
                 varied with the other fixed) instead of the full grid, to fit the time budget",
                json(&plan.static_center),
                json(&plan.dynamic_center)
            )
        },
        plan.recheck_text()
            .map_or(String::new(), |text| format!("; {text}")),
        plan.tuning_epochs,
        plan.epochs,
        plan.seeds,
        plan.exp2_seeds,
        plan.datasets,
        if plan.datasets == 1 { "" } else { "s" },
        plan.latency_trials,
        json(&plan.latency_intervals_ms),
    );
    if r.run.scale != Scale::Paper {
        let _ = writeln!(
            md,
            "The paper trains 100 epochs and repeats ten seeds; this scale uses fewer (above) to \
             finish in minutes, so its standard deviations rest on few runs.\n"
        );
    }
    stage_table(&mut md, &r.run);

    md.push_str(&labels::section(r.labels.as_ref()));

    if figures.contains(&FIGURES[7].0) || figures.contains(&FIGURES[8].0) {
        let _ = writeln!(md, "## The sensor and the representations\n");
        figure(&mut md, figures, 8, sensor_kind(r));
        figure(&mut md, figures, 7, None);
    }

    tuning::section(&mut md, r);
    figure(&mut md, figures, 0, None);

    let _ = writeln!(md, "## Experiment 1: representations (test MAE, degrees)\n");
    let truth = r.exp1.iter().any(|e| e.test_truth.is_some());
    let _ = writeln!(
        md,
        "| Representation | Overall MAE | Pitch MAE | Roll MAE |{} Paper overall | Paper pitch | \
         Paper roll |\n| --- | ---: | ---: | ---: |{} ---: | ---: | ---: |",
        if truth {
            " Overall vs truth | Pitch vs truth | Roll vs truth |"
        } else {
            ""
        },
        if truth { " ---: | ---: | ---: |" } else { "" }
    );
    // The paper's three always (its numbers beside ours), then the learned fusions and the
    // kinds beyond the paper that ran.
    let others = ReprKind::in_order(r.exp1.iter().map(|e| e.name));
    let names = PAPER_TABLE
        .iter()
        .map(|p| p.0)
        .chain(others.into_iter().filter(|n| !ReprKind::PAPER.contains(n)));
    for name in names {
        let ours = r.exp1.iter().find(|e| e.name == name);
        let s = ours.map(|e| e.test).unwrap_or_default();
        let theirs = match PAPER_TABLE.iter().find(|p| p.0 == name) {
            Some(&(_, po, pp, pr)) => format!("{} | {} | {}", paper(po), paper(pp), paper(pr)),
            None => "not in the paper | - | -".to_string(),
        };
        let against_truth = if truth {
            let t = ours.and_then(|e| e.test_truth).unwrap_or_default();
            format!(
                " {} | {} | {} |",
                cell(&t.overall),
                cell(&t.pitch),
                cell(&t.roll)
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} |{against_truth} {theirs} |",
            cell(&s.overall),
            cell(&s.pitch),
            cell(&s.roll),
        );
    }
    let _ = writeln!(md);
    if let Some(n) = r.exp1.first().map(|e| e.runs.len()) {
        let _ = writeln!(
            md,
            "Ours: mean ± sample std over {n} seeds; the paper's over ten.{}\n",
            match r.exp1.iter().find_map(|e| e.labels_truth) {
                Some(l) if truth => format!(
                    " Against the labels, as the paper scores; against the simulator's exact \
                     truth (the pose in the sensor's frame) beside them. The test labels \
                     themselves are {:.3} deg from the truth on the same samples (pitch {:.3}, \
                     roll {:.3}): a model's MAE against the labels includes their error.",
                    l.overall, l.pitch, l.roll
                ),
                _ => String::new(),
            }
        );
    }

    dataset_seeds::section(&mut md, r);
    repeat_split::section(&mut md, r.repeat_split.as_ref());
    noise_section(&mut md, r, figures);
    md.push_str(&label_noise::section(r.label_noise.as_ref()));
    md.push_str(&capture_filter::section(r.capture_filter.as_ref()));

    let _ = writeln!(
        md,
        "## Experiment 2: motion interrupted by a stop (test MAE, degrees)\n"
    );
    if r.exp2.is_empty() {
        let _ = writeln!(md, "Not run: no pause dataset.\n");
    } else {
        let exp2_truth = r.exp2.iter().any(|c| c.motion_truth.is_some());
        let _ = writeln!(
            md,
            "| training setting | representation | motion phase | stop phase |{}\n| --- | --- | \
             ---: | ---: |{}",
            if exp2_truth {
                " motion vs truth | stop vs truth |"
            } else {
                ""
            },
            if exp2_truth { " ---: | ---: |" } else { "" }
        );
        for setting in Exp2Setting::ALL {
            let label = setting.label();
            for c in r.exp2.iter().filter(|c| c.setting == setting) {
                let against_truth = if exp2_truth {
                    let t = |s: Option<evtac_experiments::results::MaeStats>| {
                        cell(&s.unwrap_or_default().overall)
                    };
                    format!(" {} | {} |", t(c.motion_truth), t(c.stop_truth))
                } else {
                    String::new()
                };
                let _ = writeln!(
                    md,
                    "| {label} | {} | {} | {} |{against_truth}",
                    c.name,
                    cell(&c.motion.overall),
                    cell(&c.stop.overall)
                );
            }
        }
        let _ = writeln!(
            md,
            "\nPaper: the static representation trained with pause-inclusive data reached {} \
             (motion) and {} (stop); continuous-only models were substantially worse in both \
             phases.\n",
            PAPER_EXP2_STATIC.0, PAPER_EXP2_STATIC.1
        );
        figure(&mut md, figures, 1, None);
        figure(&mut md, figures, 2, None);
    }

    let _ = writeln!(
        md,
        "## Experiment 3: speed and depth (test MAE overall, degrees)\n"
    );
    if r.exp3_speed.is_empty() && r.exp3_depth.is_empty() {
        let _ = writeln!(md, "Not run: no speed-wise or depth-wise dataset.\n");
    } else {
        if !r.exp3_speed.is_empty() {
            let _ = exp3_table(&mut md, &r.exp3_speed, ("speed", "deg/s"));
            let _ = writeln!(md);
        }
        if !r.exp3_depth.is_empty() {
            let flagged = exp3_table(&mut md, &r.exp3_depth, ("depth", "mm"));
            let simulated = sensor_kind(r) == Some(SensorKind::Simulated);
            if simulated && flagged {
                let _ = writeln!(
                    md,
                    "\nThis run does not say why. One explanation, that the simulated robot sets \
                     each depth to its 3 µm repeatability so Experiment 1 trains on five exact \
                     depths, was tested once, at scale `small` with an earlier binary \
                     (`docs/simulator.md`, \"Unseen depths: why they cost accuracy here\"); it \
                     has not been re-tested with this one, so it is not claimed here."
                );
            }
            let _ = writeln!(md);
        }
    }
    figure(&mut md, figures, 3, None);
    figure(&mut md, figures, 4, None);
    fusion::section(&mut md, r);
    beyond::section(&mut md, r);

    let _ = writeln!(
        md,
        "## Latency (processing time per estimate, microseconds)\n"
    );
    if r.latency.is_empty() {
        let _ = writeln!(md, "Not measured.\n");
    } else {
        let _ = writeln!(
            md,
            "Sequential, one thread, on this machine's CPU (the paper: an Intel Core Ultra 7 165H \
             plus an RTX 2080 Ti for inference), through the estimator `evtac online` runs. Each \
             figure is the time `evtac online` reports as an estimate's processing time: \
             everything the estimator does from the step's events in to the estimate out \
             (cropping, the representation update, advancing to the step's time, pooling, the \
             MLP, and the work it does ahead of the estimate between estimates, such as the \
             dynamic window dropping what leaves it), with nothing done before the timer starts. \
             This is processing time only: the estimator is handed one step's events at a \
             time (one chunk per step holding that interval's events) and each step starts when \
             the one before has finished, so no step waits in a queue, and transmission from the \
             sensor is excluded, as in the paper. It is not the delay a robot sees: a step that \
             takes longer than the interval delays the ones after it, which these figures do \
             not show. Paper: every representation under 10 ms at every interval; static and \
             dynamic under the interval, combined over it for a few samples at 1 and 2 ms.\n"
        );
        let _ = writeln!(
            md,
            "| representation | interval (ms) | samples | median | P99 | max | over interval | over 10 ms |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
        );
        for c in &r.latency {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.0} | {:.0} | {:.0} | {} | {} |",
                c.name,
                c.interval_ms,
                c.samples,
                c.median_us,
                c.p99_us,
                c.max_us,
                c.over_interval,
                c.over_10ms
            );
        }
        let _ = writeln!(md);
        figure(&mut md, figures, 5, None);
        paced_latency::section(&mut md, r);
    }
    choices_section(&mut md, &r.choices);
    md
}

/// Test MAE statistics of `name` at noise `level`, if measured.
fn noise_stats(
    points: &[NoisePoint],
    level: f64,
    name: ReprKind,
) -> Option<evtac_experiments::results::MeanStd> {
    points
        .iter()
        .find(|p| p.level == level && p.name == name)
        .map(|p| p.test.overall)
}

/// The dynamic - static gap at one noise level: `(level, gap, spread)`, the spread being the
/// seeds' standard deviations of the two added in quadrature.
type Gap = (f64, f64, f64);

/// Whether two levels' gaps differ, by the report's one rule ([`verdict::judge`]): each gap a
/// side with its seeds' spread.
fn gaps_differ(gi: f64, si: f64, gj: f64, sj: f64) -> bool {
    let side = |mean, seeds_sd| verdict::Side {
        mean,
        seeds_sd,
        datasets_sd: None,
    };
    verdict::judge(&side(gi, si), &side(gj, sj)).verdict != Verdict::Tied
}

/// One sentence on what drives the dynamic - static gap, from the gaps measured at each noise
/// level (ascending). Every pair of levels is compared, not only the ends: a change counts when
/// two levels' gaps differ beyond their spreads in quadrature ([`gaps_differ`]). The sentence says whether
/// the gap changes at all, whether every change goes the same way as the noise, and whether it
/// is there without noise (the lowest level).
fn noise_verdict(gaps: &[Gap]) -> String {
    let list: Vec<String> = gaps
        .iter()
        .map(|(l, g, _)| format!("{g:+.3} deg at x{l}"))
        .collect();
    let head = format!("Dynamic minus static test MAE: {}.", list.join(", "));
    if gaps.len() < 2 {
        return head;
    }
    let levels: Vec<String> = gaps.iter().map(|(l, _, _)| format!("x{l}")).collect();
    let levels = levels.join(", ");
    // (lower level, higher level, change of the gap) for each pair that differs beyond spread.
    let mut changes: Vec<(f64, f64, f64)> = Vec::new();
    for (i, &(li, gi, si)) in gaps.iter().enumerate() {
        for &(lj, gj, sj) in &gaps[i + 1..] {
            if gaps_differ(gi, si, gj, sj) {
                changes.push((li, lj, gj - gi));
            }
        }
    }
    let (lo, low, _) = gaps[0];
    let reference = gaps
        .iter()
        .find(|(l, _, _)| *l == 1.0)
        .map_or(gaps[gaps.len() - 1].1, |&(_, g, _)| g);
    let pairs = |sign: f64| {
        let v: Vec<String> = changes
            .iter()
            .filter(|c| c.2 * sign > 0.0)
            .map(|(a, b, _)| format!("x{a} to x{b}"))
            .collect();
        v.join(", ")
    };
    let verdict = if changes.is_empty() {
        format!(
            "At no two of the levels ({levels}) do the gaps differ by more than the seeds' \
             spread, so these runs do not tie the gap to the simulator's background noise: in \
             evtac's data it is the representations' own."
        )
    } else if changes.iter().all(|c| c.2 > 0.0) {
        let grows = pairs(1.0);
        if low.abs() < 0.5 * reference.abs() {
            format!(
                "Where the gap changes beyond the seeds' spread ({grows}), it grows with the \
                 noise, and it mostly vanishes without noise (x{lo}), so in \
                 evtac's data the simulator's background noise drives it (the dynamic window at \
                 threshold 0 keeps every noise event; the static threshold and mask remove \
                 most), not the representations themselves."
            )
        } else {
            format!(
                "Where the gap changes beyond the seeds' spread ({grows}), it grows with the \
                 noise, but it stays at x{lo}, so background noise widens it while \
                 most of it is the representations' own in evtac's data."
            )
        }
    } else if changes.iter().all(|c| c.2 < 0.0) {
        format!(
            "Where the gap changes beyond the seeds' spread ({}), it shrinks as the noise grows, \
             so background noise does not drive it in evtac's data.",
            pairs(-1.0)
        )
    } else {
        format!(
            "The gap rises ({}) and falls ({}) between levels beyond the seeds' spread: no trend \
             with the noise, so these runs do not tie it to the background noise either way.",
            pairs(1.0),
            pairs(-1.0)
        )
    };
    format!("{head} {verdict}")
}

/// Experiment 1 at other background noise: the table, the sentence on the gap and the figure.
fn noise_section(md: &mut String, r: &Results, figures: &[&str]) {
    let _ = writeln!(
        md,
        "## Experiment 1 at other background noise (test MAE, degrees)\n"
    );
    if r.noise.is_empty() {
        let _ = writeln!(
            md,
            "Not run: it needs a simulated Experiment 1 dataset and `--noise-levels`.\n"
        );
        return;
    }
    let _ = writeln!(
        md,
        "The simulator's leak, shot and hot-pixel noise scaled together by each factor; the same \
         trials, splits, seeds and the settings tuned at x1 (Experiment 1 itself). Background \
         events/s: the 240x240 crop of each dataset's no-contact recording.\n"
    );
    let mut levels: Vec<f64> = r.noise.iter().map(|p| p.level).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let names = ReprKind::in_order(r.noise.iter().map(|p| p.name));
    let _ = writeln!(
        md,
        "| noise | background events/s | {} | dynamic - static |\n| ---: | ---: |{} ---: |",
        titles(&names),
        " ---: |".repeat(names.len())
    );
    let mut gaps = Vec::new();
    for &level in &levels {
        let cell_of = |name: ReprKind| {
            r.noise
                .iter()
                .find(|p| p.level == level && p.name == name)
                .map_or("-".to_string(), |p| {
                    cell_with_truth(&p.test.overall, p.test_truth.as_ref())
                })
        };
        let rate = r
            .noise
            .iter()
            .find(|p| p.level == level)
            .map_or(0.0, |p| p.no_contact_events_per_s);
        let gap = noise_stats(&r.noise, level, ReprKind::Dynamic)
            .zip(noise_stats(&r.noise, level, ReprKind::Static))
            .map(|(d, s)| (d.mean - s.mean, d.std.hypot(s.std)));
        if let Some((g, spread)) = gap {
            gaps.push((level, g, spread));
        }
        let cells: Vec<String> = names.iter().map(|&n| cell_of(n)).collect();
        let _ = writeln!(
            md,
            "| x{level} | {rate:.0} | {} | {} |",
            cells.join(" | "),
            gap.map_or("-".to_string(), |(g, _)| format!("{g:+.3}"))
        );
    }
    if r.noise.iter().any(|p| p.test_truth.is_some()) {
        let _ = writeln!(md, "\n{TRUTH_CELLS}");
    }
    let _ = writeln!(md, "\n{}\n", noise_verdict(&gaps));
    figure(md, figures, 6, None);
}

/// The title of the section listing the values evtac chose where the paper states none.
pub const CHOICES_TITLE: &str = "Choices the paper does not state";

/// The section listing [`evtac_experiments::results::Choice`]s: what, value used, why, how to change it.
fn choices_section(md: &mut String, choices: &[evtac_experiments::results::Choice]) {
    let _ = writeln!(md, "## {CHOICES_TITLE}\n");
    if choices.is_empty() {
        let _ = writeln!(md, "Not recorded by the run that wrote `results.json`.\n");
        return;
    }
    let _ = writeln!(
        md,
        "The paper leaves these open; evtac chose them. Results that depend on them are evtac's \
         as much as the method's. Every value below is the one this run used, read from the \
         code and the datasets.\n"
    );
    let _ = writeln!(md, "| choice | value used | why | changed by |");
    let _ = writeln!(md, "| --- | --- | --- | --- |");
    for c in choices {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} |",
            c.what, c.value, c.why, c.change
        );
    }
    let _ = writeln!(md);
}

/// Figure `i` of [`FIGURES`] with its caption, if it was drawn; the sensor figure's caption
/// says what it shows (`sensor`).
fn figure(md: &mut String, present: &[&str], i: usize, sensor: Option<SensorKind>) {
    let (file, caption) = FIGURES[i];
    let caption = sensor.map_or_else(|| caption.to_string(), sensor_caption);
    if present.contains(&file) {
        let _ = writeln!(md, "![{caption}](figures/{file})\n\n*{caption}*\n");
    }
}

/// Draws every figure the results allow, writes `results.json` and `report.md` into `out`.
/// Returns the figure files written.
pub fn write(out: &Path, r: &Results) -> Result<Vec<PathBuf>, Error> {
    let fig_dir = out.join("figures");
    std::fs::create_dir_all(&fig_dir).map_err(IoError::at(&fig_dir))?;
    let mut written = Vec::new();
    let mut names = Vec::new();
    let mut draw = |name: &'static str, f: &dyn Fn(&Path) -> Result<(), plots::Error>| {
        let path = fig_dir.join(name);
        f(&path)?;
        written.push(path);
        names.push(name);
        Ok::<(), Error>(())
    };
    if !r.tuning.is_empty() {
        draw(FIGURES[0].0, &|p| plots::tuning_curves(p, &r.tuning))?;
    }
    if !r.exp2.is_empty() {
        draw(FIGURES[1].0, &|p| plots::phase_bars(p, &r.exp2))?;
    }
    if let Some(ex) = &r.example {
        draw(FIGURES[2].0, &|p| plots::example_curves(p, ex))?;
    }
    if !r.overlays.is_empty() {
        draw(FIGURES[3].0, &|p| plots::overlays(p, &r.overlays))?;
    }
    if !r.exp3_speed.is_empty() || !r.exp3_depth.is_empty() {
        draw(FIGURES[4].0, &|p| {
            plots::speed_depth(p, &r.exp3_speed, &r.exp3_depth)
        })?;
    }
    if !r.latency.is_empty() {
        draw(FIGURES[5].0, &|p| plots::latency(p, &r.latency))?;
    }
    if !r.noise.is_empty() {
        draw(FIGURES[6].0, &|p| plots::noise(p, &r.noise))?;
    }
    if let Some(ex) = &r.repr_example {
        draw(FIGURES[7].0, &|p| plots::representations(p, ex))?;
    }
    if let Some(view) = &r.sensor {
        draw(FIGURES[8].0, &|p| plots::sensor(p, view))?;
    }
    let json_path = out.join("results.json");
    let json = serde_json::to_string_pretty(r).map_err(IoError::at(&json_path))?;
    evtac_events::output::write_atomic(&json_path, json.as_bytes())
        .map_err(IoError::at(&json_path))?;
    let md_path = out.join("report.md");
    let markdown = markdown(r, &names);
    evtac_events::output::write_atomic(&md_path, markdown.as_bytes())
        .map_err(IoError::at(&md_path))?;
    Ok(written)
}

/// Statistics shown for a representation in Experiment 1, if present.
pub fn exp1_stats(r: &Results, name: ReprKind) -> Option<&MaeStats> {
    r.exp1.iter().find(|e| e.name == name).map(|e| &e.test)
}

/// The stage times: every invocation's that worked on the output folder (a resumed
/// reproduction's report states what the whole took), or this invocation's in results written
/// before the log was kept.
fn stage_table(md: &mut String, run: &RunInfo) {
    let history = &run.stage_history;
    let invocations = history.iter().map(|r| r.invocation).max().unwrap_or(0);
    if invocations > 1 {
        let _ = writeln!(
            md,
            "This output folder was produced by {invocations} invocations, each resuming the one \
             before it (finished jobs are skipped, so a later invocation's stage can be short); \
             the total is their sum.\n"
        );
        let _ = writeln!(
            md,
            "| invocation | stage | seconds |\n| ---: | --- | ---: |"
        );
        for r in history {
            let _ = writeln!(md, "| {} | {} | {:.1} |", r.invocation, r.stage, r.seconds);
        }
        let total: f64 = history.iter().map(|r| r.seconds).sum();
        let _ = writeln!(md, "| | total | {total:.1} |\n");
        return;
    }
    let rows: Vec<(&str, f64)> = if history.is_empty() {
        run.stage_seconds
            .iter()
            .map(|(s, t)| (s.as_str(), *t))
            .collect()
    } else {
        history
            .iter()
            .map(|r| (r.stage.as_str(), r.seconds))
            .collect()
    };
    let _ = writeln!(md, "| stage | seconds |\n| --- | ---: |");
    for (stage, s) in &rows {
        let _ = writeln!(md, "| {stage} | {s:.1} |");
    }
    let total: f64 = rows.iter().map(|r| r.1).sum();
    let _ = writeln!(md, "| total | {total:.1} |\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_noise_sentence_follows_the_measured_gaps() {
        let driven = noise_verdict(&[(0.0, 0.01, 0.05), (1.0, 0.4, 0.05), (3.0, 0.9, 0.05)]);
        assert!(
            driven.starts_with("Dynamic minus static test MAE: +0.010 deg at x0, +0.400 deg at x1")
        );
        assert!(driven.contains("background noise drives it"), "{driven}");
        let own = noise_verdict(&[(0.0, 0.3, 0.05), (1.0, 0.4, 0.05), (3.0, 0.6, 0.05)]);
        assert!(own.contains("widens it"), "{own}");
        // Gaps 0.1 apart against spreads of 0.08 each (0.113 in quadrature): no change.
        let flat = noise_verdict(&[(0.0, 0.3, 0.08), (1.0, 0.2, 0.08), (3.0, 0.2, 0.08)]);
        assert!(
            flat.contains("At no two of the levels (x0, x1, x3)"),
            "{flat}"
        );
        // A rise within the seeds' spread is no evidence.
        let spread = noise_verdict(&[(0.0, 0.01, 0.4), (1.0, 0.4, 0.4), (3.0, 0.5, 0.4)]);
        assert!(spread.contains("At no two of the levels"), "{spread}");
        // The ends alike, the middle apart: seen only by comparing every level.
        let middle = noise_verdict(&[(0.0, 0.1, 0.01), (1.0, 0.5, 0.01), (3.0, 0.1, 0.01)]);
        assert!(
            middle.contains("rises (x0 to x1) and falls (x1 to x3)"),
            "{middle}"
        );
        let shrinks = noise_verdict(&[(0.0, 0.5, 0.01), (1.0, 0.3, 0.01), (3.0, 0.3, 0.01)]);
        assert!(shrinks.contains("shrinks"), "{shrinks}");
        assert!(shrinks.contains("x0 to x1, x0 to x3"), "{shrinks}");
        assert!(!noise_verdict(&[(1.0, 0.3, 0.0)]).contains("gap"));
    }

    #[test]
    fn an_unseen_level_worse_than_both_seen_neighbours_beyond_the_spread_is_named() {
        let point = |name, value: f64, seen, mean: f64, sd: f64| {
            let runs = [mean - sd, mean + sd].map(|m| evtac_experiments::results::Mae {
                overall: m,
                pitch: m,
                roll: m,
            });
            Exp3Point {
                name,
                value,
                seen,
                trials: 6,
                stats: evtac_experiments::results::MaeStats::of(&runs),
                runs: runs.to_vec(),
                truth: None,
            }
        };
        let s = ReprKind::Static;
        let d = ReprKind::Dynamic;
        let points = [
            point(s, 1.0, true, 0.17, 0.005),
            point(s, 1.5, false, 0.24, 0.005),
            point(s, 2.0, true, 0.18, 0.005),
            // Worse than both, but within the spread: not named.
            point(d, 1.0, true, 0.30, 0.04),
            point(d, 1.5, false, 0.33, 0.04),
            point(d, 2.0, true, 0.31, 0.04),
        ];
        let (text, flagged) = unseen_penalties(&points, ("depth", "mm"));
        assert!(flagged);
        assert!(
            text.contains("Static at 1.5 mm (0.240 against 0.170 at 1 and 0.180 at 2"),
            "{text}"
        );
        assert!(!text.contains("Dynamic"), "{text}");
        let (calm, flagged) = unseen_penalties(&points[3..], ("depth", "mm"));
        assert!(!flagged);
        assert!(calm.starts_with("No unseen depth is worse"), "{calm}");
    }

    #[test]
    fn the_exp3_design_sentence_gives_the_spacing_and_whose_levels_they_are() {
        let even = [
            (2.0, true),
            (3.0, false),
            (4.0, true),
            (5.0, false),
            (6.0, true),
        ];
        let s = exp3_design(&even, "speed", "deg/s");
        assert!(s.starts_with("Seen speeds (in the training set, deg/s): 2, 4, 6; unseen: 3, 5."));
        assert!(
            s.contains("Each unseen speed is 1 deg/s from the nearest seen one."),
            "{s}"
        );
        assert!(
            s.ends_with("The paper gives neither its levels nor their count: these are evtac's.")
        );
        assert!(!s.contains("as in the paper"));
        let uneven = [
            (1.0, true),
            (1.25, false),
            (2.0, true),
            (2.5, false),
            (3.0, true),
        ];
        let s = exp3_design(&uneven, "depth", "mm");
        assert!(s.contains("0.25 to 0.5 mm"), "{s}");
        let none = [(1.0, true)];
        assert!(exp3_design(&none, "depth", "mm").contains("unseen: none. The paper"));
    }
}
