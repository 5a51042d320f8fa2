//! Experiment 1's dataset simulated again with other simulator parameters or another seed:
//! what the noise study (the background noise scaled), the sensitivity study (one parameter
//! scaled) and the spread across datasets (another simulation seed) each train and test on.
//! The same protocol and scale as Experiment 1's, so the same trial plan and splits; with the
//! same seed also the same camera, so only the parameters differ. The folder is marked done once
//! simulated, so a run resumes.

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::error::Error;
use crate::exp1;
use crate::jobs;
use crate::progress::Progress;
use crate::results::Exp1Repr;
use crate::simulation;
use crate::stage::{FeatureSet, Stage};
use evtac_import::inputs::Inputs;
use evtac_repr::ReprConfig;
use std::path::Path;

/// Where a variant lives and how its stages are reported: its dataset folder, its models
/// folder, and the stages of its simulation and of its features and training runs.
pub(crate) struct Place<'a> {
    /// The dataset folder.
    pub dir: &'a Path,
    /// The models folder.
    pub models: &'a Path,
    /// The simulation's stage.
    pub simulating: Stage,
    /// The features' and training runs' stages.
    pub training: (FeatureSet, Stage),
}

/// Simulates (or keeps) the variant `config` into `at.dir` and runs Experiment 1 on it for
/// `reprs` (settings tuned elsewhere), with `run`'s plan and seeds and its models under
/// `at.models`; returns the dataset (opened with `inputs`) and the results.
pub(crate) fn exp1_on(
    config: &evtac_sim::DatasetConfig,
    at: &Place<'_>,
    (reprs, inputs): (&[ReprConfig], Inputs),
    run: &RunContext<'_>,
) -> Result<(Dataset, Vec<Exp1Repr>), Error> {
    simulate(config, at.dir, at.simulating, run.progress)?;
    let ds = Dataset::open(at.dir, inputs)?;
    let splits = ds.splits(run.seed)?;
    let results = {
        let cache = FeatureCache::new(&ds)?;
        let in_place = RunContext {
            models: at.models,
            ..*run
        };
        exp1::run_as(&cache, &splits, reprs, &in_place, at.training)?
    };
    Ok((ds, results))
}

/// Simulates (or, when `dir` is marked done, keeps) the dataset of `config` into `dir`,
/// reporting its trials as `stage`.
pub(crate) fn simulate(
    config: &evtac_sim::DatasetConfig,
    dir: &Path,
    stage: Stage,
    progress: &dyn Progress,
) -> Result<(), Error> {
    if jobs::is_done(dir) {
        return Ok(());
    }
    progress.stage(stage, config.trials().len() as u64);
    simulation::into(config, dir, || progress.advance(1))
}
