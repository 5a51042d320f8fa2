//! The labels of a dataset checked against what is known without them, for the report: the
//! integrated tilt over each stop against the robot's commanded stop angle (the paper's own
//! validation, -0.01 +- 0.04 deg) and, for simulated data, against the exact ground truth.
//!
//! It reads the labels the experiments trained on (`labels/<trial>.csv`, computed when missing),
//! so the figure describes those labels and not a fresh computation.

use crate::dataset::{self, Dataset};
pub use crate::results::LabelCheck;
use evtac_labels::validation::check_stop;
use evtac_labels::{LabelConfig, LabelSeries, Summary, TruthError};

/// The paper's label validation at the stops: mean and standard deviation, degrees.
pub const PAPER_STOP_ERROR_DEG: (f64, f64) = (-0.01, 0.04);

/// Checks the labels of every trial of `ds` (computing those that are missing).
pub fn of_dataset(ds: &Dataset) -> Result<LabelCheck, dataset::Error> {
    let margin_us = LabelConfig::default().stop_margin_us;
    let (mut stops, mut rms) = (Vec::new(), Vec::new());
    for meta in &ds.manifest.trials {
        let stop = meta.stop_start_us.zip(meta.stop_end_us).zip(meta.stop_deg);
        if stop.is_none() && meta.truth.is_none() {
            continue;
        }
        let labels = ds.labels(meta)?;
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
        }
    }
    Ok(LabelCheck {
        stop_error_deg: Summary::of(&stops),
        truth_rms_deg: Summary::of(&rms),
    })
}

/// The report's section on the labels: the stop check beside the paper's, and the error against
/// the ground truth when there is one.
pub fn section(check: Option<&LabelCheck>) -> String {
    let mut md = String::from("## Labels\n\n");
    let Some(check) = check else {
        md.push_str(
            "Not checked: no Experiment 2 dataset (its stops are what the check uses).\n\n",
        );
        return md;
    };
    let (mean, sd) = PAPER_STOP_ERROR_DEG;
    match &check.stop_error_deg {
        Some(s) => md.push_str(&format!(
            "Mean labelled tilt over each stop of Experiment 2 minus the robot's commanded stop \
             angle: {:+.3} ± {:.3} deg over {} stops (range {:+.3} .. {:+.3}); the paper: \
             {mean:+.2} ± {sd:.2} deg.",
            s.mean, s.std, s.n, s.min, s.max
        )),
        None => md.push_str("No trial of Experiment 2 has a stop to check the labels against."),
    }
    if let Some(r) = &check.truth_rms_deg {
        md.push_str(&format!(
            " Against the simulator's exact ground truth, the labels' RMS error over pitch and \
             roll is {:.3} deg per trial on average (at most {:.3}, {} trials): on simulated \
             data the stop check measures mostly the robot's repeatability, which the simulator \
             draws (`rig.angle_sd_deg` in `docs/simulator.md`).",
            r.mean, r.max, r.n
        ));
    }
    md.push_str("\n\n");
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_section_puts_the_stop_check_beside_the_paper_s() {
        let check = LabelCheck {
            stop_error_deg: Summary::of(&[-0.05, 0.01, 0.02]),
            truth_rms_deg: Summary::of(&[0.01, 0.03]),
        };
        let md = section(Some(&check));
        assert!(md.contains("-0.007 ± 0.038 deg over 3 stops"), "{md}");
        assert!(md.contains("the paper: -0.01 ± 0.04 deg"), "{md}");
        assert!(
            md.contains("0.020 deg per trial on average (at most 0.030, 2 trials)"),
            "{md}"
        );
        assert!(section(None).contains("Not checked"));
    }
}
