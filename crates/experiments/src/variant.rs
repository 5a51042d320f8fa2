//! Experiment 1's dataset simulated again with other simulator parameters: what the noise study
//! (the background noise scaled) and the sensitivity study (one parameter scaled) each train
//! and test on. The same protocol, scale and seed as Experiment 1's, so the same trials, splits
//! and camera; only the parameters differ. The folder is marked done once simulated, so a run
//! resumes.

use crate::error::Error;
use crate::jobs;
use crate::progress::Progress;
use crate::stage::Stage;
use evtac_sim::{Protocol, Scale, SimParams};
use std::path::Path;

/// Simulates (or, when `dir` is marked done, keeps) Experiment 1's dataset at `scale` and
/// `seed` with `params` into `dir`, reporting its trials as `stage`.
pub(crate) fn simulate(
    params: &SimParams,
    (scale, seed): (Scale, u64),
    dir: &Path,
    stage: Stage,
    progress: &dyn Progress,
) -> Result<(), Error> {
    if jobs::is_done(dir) {
        return Ok(());
    }
    let config = evtac_sim::DatasetConfig {
        params: params.clone(),
        ..evtac_sim::DatasetConfig::new(Protocol::Exp1, scale, seed)
    };
    let n = evtac_sim::plan(Protocol::Exp1, scale, seed, &config.params.timeline).len();
    progress.stage(stage, n as u64);
    evtac_sim::simulate_dataset(&config, dir, |_| progress.advance(1)).map_err(|source| {
        Error::Simulation {
            protocol: Protocol::Exp1,
            dir: dir.to_path_buf(),
            source: Box::new(source),
        }
    })?;
    jobs::mark_done(dir)?;
    Ok(())
}
