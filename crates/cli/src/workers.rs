//! `--jobs`: the worker threads of the commands that run many jobs side by side (simulation,
//! tuning, the reproduction).

use anyhow::Context;

/// The `--jobs` flag, flattened into each command that takes it.
#[derive(Debug, Clone, clap::Args)]
pub struct Workers {
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
}

impl Workers {
    /// A thread pool of `--jobs` threads (all cores when absent).
    pub fn pool(&self) -> anyhow::Result<rayon::ThreadPool> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(self.jobs.unwrap_or(0))
            .build()
            .context("starting worker threads")
    }
}
