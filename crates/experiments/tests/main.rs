//! Integration tests of evtac-experiments on small simulated datasets.

mod cache;
mod figures;
mod inputs;
mod results;
mod resume;

use evtac_sim::{DatasetConfig, Protocol, Scale, simulate_dataset};
use std::path::Path;

/// Simulates the first `limit` trials of `protocol` at the tiny scale into `dir`.
pub fn simulate(dir: &Path, protocol: Protocol, limit: usize) {
    let config = DatasetConfig {
        limit: Some(limit),
        ..DatasetConfig::new(protocol, Scale::Tiny, 3)
    };
    simulate_dataset(&config, dir, |_| {}).expect("simulation runs");
}
