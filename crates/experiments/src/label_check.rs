//! The labels of a dataset checked against what is known without them (`evtac-report` writes
//! the section): the
//! integrated tilt over each stop against the robot's commanded stop angle (the paper's own
//! validation, -0.01 +- 0.04 deg) and, for simulated data, against the exact ground truth, over
//! whole trials and over each stop.
//!
//! It reads the labels the experiments trained on (`labels/<trial>.csv`, computed when missing),
//! so the figure describes those labels and not a fresh computation.

use crate::dataset::{self, Dataset};
pub use crate::results::LabelCheck;
use evtac_labels::validation::check_stop;
use evtac_labels::{LabelConfig, LabelSeries, LabelSource, Summary, TruthError};

/// Checks the labels of every trial of `ds` (computing those that are missing).
pub fn of_dataset(ds: &Dataset) -> Result<LabelCheck, dataset::Error> {
    let margin_us = LabelConfig::default().stop_margin_us;
    let (mut stops, mut rms, mut stop_rms) = (Vec::new(), Vec::new(), Vec::new());
    for meta in &ds.manifest.trials {
        let stop = meta.stop_start_us.zip(meta.stop_end_us).zip(meta.stop_deg);
        if stop.is_none() && meta.truth.is_none() {
            continue;
        }
        let labels = ds.labels(meta)?;
        let window = stop.map(|((start, end), _)| (start + margin_us, end - margin_us));
        // Labels from the command hold the commanded stop angle by construction.
        let stop = stop.filter(|_| ds.label_source == LabelSource::Imu);
        if let Some(((start, end), deg)) = stop {
            // A stop too short for its margins has nothing to average: not a label error.
            if let Ok(check) = check_stop(&labels, start, end, margin_us, deg) {
                stops.push(check.error_deg);
            }
        }
        if let Some(file) = &meta.truth {
            let path = ds.dir.join(file);
            let truth = LabelSeries::read_csv(&path).map_err(|e| dataset::Error::Labels {
                trial: meta.trial.clone(),
                message: format!("{}: {e}", path.display()),
            })?;
            if let Some(e) = TruthError::compare(&labels, &truth) {
                rms.push(e.rms_deg);
            }
            // The same margins as the stop check: the labels' filter rings at the stop's edges.
            if let Some((start, end)) = window
                && let Some(e) = TruthError::compare(&labels, &within(&truth, start, end))
            {
                stop_rms.push(e.rms_deg);
            }
        }
    }
    Ok(LabelCheck {
        stop_error_deg: Summary::of(&stops),
        truth_rms_deg: Summary::of(&rms),
        label_source: ds.label_source,
        truth_stop_rms_deg: Summary::of(&stop_rms),
    })
}

/// The rows of `series` with `start <= t_us <= end`.
fn within(series: &LabelSeries, start: i64, end: i64) -> LabelSeries {
    let keep: Vec<usize> = (0..series.t_us.len())
        .filter(|&i| (start..=end).contains(&series.t_us[i]))
        .collect();
    let pick = |v: &[f64]| keep.iter().map(|&i| v[i]).collect();
    LabelSeries {
        t_us: keep.iter().map(|&i| series.t_us[i]).collect(),
        theta_deg: pick(&series.theta_deg),
        pitch_deg: pick(&series.pitch_deg),
        roll_deg: pick(&series.roll_deg),
    }
}
