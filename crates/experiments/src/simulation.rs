//! Simulating one dataset into its folder and marking it done: what a [`SimulateJob`] asks for
//! (`evtac jobs run`, the pipeline's [`crate::pipeline::simulate_all`]) and what the studies on
//! other simulated datasets start with. A dataset whose folder is marked done is kept, so an
//! interrupted simulation resumes.

use std::path::Path;

use crate::error::Error;
use crate::job::SimulateJob;
use crate::jobs;

/// Simulates the dataset `job` describes (nothing when it is done already), calling `on_trial`
/// after each trial, and marks it done.
pub fn run(job: &SimulateJob, on_trial: impl Fn() + Sync) -> Result<(), Error> {
    if jobs::is_done(&job.out) {
        return Ok(());
    }
    into(&job.config(), &job.out, on_trial)
}

/// Simulates `config` into `dir`, calling `on_trial` after each trial, and marks it done.
pub(crate) fn into(
    config: &evtac_sim::DatasetConfig,
    dir: &Path,
    on_trial: impl Fn() + Sync,
) -> Result<(), Error> {
    evtac_sim::simulate_dataset(config, dir, |_| on_trial()).map_err(|source| {
        Error::Simulation {
            protocol: config.protocol,
            dir: dir.to_path_buf(),
            source: Box::new(source),
        }
    })?;
    jobs::mark_done(dir)?;
    Ok(())
}
