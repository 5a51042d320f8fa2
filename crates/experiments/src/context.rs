//! What the experiments of one reproduction share: the plan, the master seed, the folder their
//! models go to, and where progress is reported. Tuning and Experiments 1 and 2 take it whole,
//! so their signatures say what differs between them (the dataset, the representations) and
//! nothing else.

use crate::plan::Plan;
use crate::progress::Progress;
use std::path::Path;

/// The settings every experiment of a run shares.
#[derive(Clone, Copy)]
pub struct RunContext<'a> {
    /// Grids, epochs, seeds, latency settings.
    pub plan: &'a Plan,
    /// The master seed (splits, training).
    pub seed: u64,
    /// The folder models are written to (and resumed from).
    pub models: &'a Path,
    /// Where the run reports its stages.
    pub progress: &'a dyn Progress,
}

impl std::fmt::Debug for RunContext<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunContext")
            .field("scale", &self.plan.scale)
            .field("seed", &self.seed)
            .field("models", &self.models)
            .finish_non_exhaustive()
    }
}
