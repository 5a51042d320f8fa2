//! Experiment 1 on datasets simulated with other seeds: how much of a difference between
//! representations belongs to the one dataset it was measured on.
//!
//! The training seeds' spread says how much a result moves when the same data is trained on
//! again. It says nothing of how much it moves on other data of the same kind: another set of
//! trials, another camera (its fixed pattern), other noise. A real study cannot re-record its
//! dataset cheaply; a simulated one can. So, beside Experiment 1's own dataset, the run
//! simulates [`crate::plan::Plan::datasets`] − 1 more with the same parameters, protocol and
//! scale and the seeds that follow it ([`seeds`]), and trains the same representations with the
//! settings tuned on Experiment 1's dataset and the same training seeds on each. The report
//! sets the standard deviation across datasets (of each dataset's mean over training seeds)
//! beside the training seeds' and claims a difference only beyond both.
//!
//! The settings are not tuned again per dataset: the spread measured is that of the data given
//! the settings, which is what a reader applying the paper's settings to a new sensor meets.
//!
//! Each dataset lives under `OUT/datasets/seed<S>/`, its models under
//! `models/datasets/seed<S>/`; both mark their folders done, so a run resumes. Like the noise
//! study, this needs a simulated Experiment 1 dataset (`simulator.json`).

use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::error::Error;
use crate::results::{DatasetSeedPoint, Exp1Repr};
use crate::stage::{FeatureSet, Stage};
use crate::variant;
use evtac_repr::ReprConfig;
use std::path::{Path, PathBuf};

/// The simulation seeds of `n` datasets, Experiment 1's (`first`) first: consecutive seeds,
/// each giving independent trials and camera through `evtac_sim::trial_seed`.
pub fn seeds(first: u64, n: usize) -> Vec<u64> {
    (0..n as u64).map(|k| first.wrapping_add(k)).collect()
}

/// The dataset folder of simulation seed `seed` under `out` (the run's output folder, or its
/// models folder).
pub fn dataset_dir(out: &Path, seed: u64) -> PathBuf {
    out.join("datasets").join(format!("seed{seed}"))
}

fn points(dataset_seed: u64, results: &[Exp1Repr]) -> Vec<DatasetSeedPoint> {
    results
        .iter()
        .map(|r| DatasetSeedPoint {
            dataset_seed,
            name: r.name,
            runs: r.runs.clone(),
            test: r.test,
            test_truth: r.test_truth,
        })
        .collect()
}

/// Experiment 1 on every dataset of the plan, for `reprs` (the settings tuned on `ds1`); `e1`
/// are Experiment 1's results on `ds1`, `out` the run's output folder. Empty when the plan has
/// one dataset or `ds1` was not simulated.
pub fn run(
    ds1: &Dataset,
    e1: &[Exp1Repr],
    reprs: &[ReprConfig],
    run: &RunContext<'_>,
    out: &Path,
) -> Result<Vec<DatasetSeedPoint>, Error> {
    if run.plan.datasets < 2 {
        return Ok(Vec::new());
    }
    let Some(sim) = ds1.simulator()? else {
        return Ok(Vec::new());
    };
    let all_seeds = seeds(sim.seed, run.plan.datasets);
    let mut all = points(all_seeds[0], e1);
    for &seed in &all_seeds[1..] {
        let at = variant::Place {
            dir: &dataset_dir(out, seed),
            models: &dataset_dir(run.models, seed),
            simulating: Stage::DatasetSeedSimulating,
            training: (FeatureSet::DatasetSeed, Stage::DatasetSeedTraining),
        };
        let (_, results) =
            variant::exp1_on(&sim.config(seed), &at, (reprs, ds1.inputs.clone()), run)?;
        all.extend(points(seed, &results));
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn experiment_1s_seed_comes_first_and_the_rest_follow_it() {
        assert_eq!(seeds(7, 3), [7, 8, 9]);
        assert_eq!(seeds(u64::MAX, 2), [u64::MAX, 0]);
        assert!(seeds(0, 0).is_empty());
        assert_eq!(
            dataset_dir(Path::new("out"), 3),
            Path::new("out/datasets/seed3")
        );
    }
}
