//! Experiment 1 at other background noise: the simulator's leak, shot and hot-pixel noise scaled
//! together by each factor of [`crate::plan::Plan::noise_levels`], the three representations
//! with the settings tuned at factor 1 trained and tested on each, so a report can tell what
//! the simulator's noise does to their gap.
//!
//! Factor 1 is Experiment 1 itself (its dataset, models and results). Every other factor is a
//! dataset simulated like Experiment 1's (same protocol, scale, seed and parameters, so the same
//! trials, splits and camera) with only the noise scaled, under `OUT/noise/x<factor>/`, and its
//! models under `models/noise/x<factor>/`; both mark their folders done, so a run resumes. It
//! needs a simulated Experiment 1 dataset (`simulator.json`): recordings cannot be re-recorded at
//! another noise.

use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::error::Error;
use crate::results::{Exp1Repr, NoisePoint};
use crate::stage::{FeatureSet, Stage};
use crate::variant;
use evtac_repr::ReprConfig;
use std::path::{Path, PathBuf};

/// The dataset folder of factor `level` under the run's output folder.
pub fn dataset_dir(out: &Path, level: f64) -> PathBuf {
    out.join("noise").join(format!("x{level}"))
}

/// Events per second in the crop of `ds`'s no-contact recording, which lasts `seconds`.
fn background_rate(ds: &Dataset, seconds: f64) -> Result<f64, Error> {
    let n = ds.no_contact()?.map_or(0, |nc| nc.cropped.len());
    Ok(if seconds > 0.0 {
        n as f64 / seconds
    } else {
        0.0
    })
}

fn points(level: f64, rate: f64, results: &[Exp1Repr]) -> Vec<NoisePoint> {
    results
        .iter()
        .map(|r| NoisePoint {
            level,
            name: r.name,
            no_contact_events_per_s: rate,
            runs: r.runs.clone(),
            test: r.test,
            test_truth: r.test_truth,
        })
        .collect()
}

/// Experiment 1 at every factor of the plan's noise levels, for `reprs` (the settings tuned on
/// `ds1`); `e1` are Experiment 1's results (factor 1), `out` the run's output folder. Empty when
/// `ds1` was not simulated.
pub fn run(
    ds1: &Dataset,
    e1: &[Exp1Repr],
    reprs: &[ReprConfig],
    run: &RunContext<'_>,
    out: &Path,
) -> Result<Vec<NoisePoint>, Error> {
    let Some(sim) = ds1.simulator()? else {
        return Ok(Vec::new());
    };
    let seconds = sim.params.timeline.no_contact_s;
    let mut all = Vec::new();
    for level in run.plan.unique_noise_levels() {
        if level == 1.0 {
            // Experiment 1 itself, for the representations this study trains (not the kinds
            // beyond the paper Experiment 1 may also compare).
            let e1: Vec<Exp1Repr> = e1
                .iter()
                .filter(|e| reprs.iter().any(|c| c.kind() == e.name))
                .cloned()
                .collect();
            all.extend(points(level, background_rate(ds1, seconds)?, &e1));
            continue;
        }
        // Same protocol, scale and seed as Experiment 1's dataset: only the noise differs.
        let mut config = sim.config(sim.seed);
        config.params.dvs = config.params.dvs.with_noise_scaled(level);
        let at = variant::Place {
            dir: &dataset_dir(out, level),
            models: &dataset_dir(run.models, level),
            simulating: Stage::NoiseSimulating,
            training: (FeatureSet::Noise, Stage::NoiseTraining),
        };
        let (ds, results) = variant::exp1_on(&config, &at, (reprs, ds1.inputs.clone()), run)?;
        all.extend(points(level, background_rate(&ds, seconds)?, &results));
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::Plan;

    #[test]
    fn factor_one_is_experiment_1_and_repeats_count_once() {
        let plan = |noise_levels: &[f64]| Plan {
            noise_levels: noise_levels.to_vec(),
            ..Plan::for_scale(evtac_sim::Scale::Tiny)
        };
        assert_eq!(
            plan(&[0.0, 1.0, 3.0, 0.0]).simulated_noise_levels(),
            [0.0, 3.0]
        );
        assert!(plan(&[1.0]).simulated_noise_levels().is_empty());
        assert_eq!(
            dataset_dir(Path::new("out"), 0.5),
            Path::new("out/noise/x0.5")
        );
    }
}
