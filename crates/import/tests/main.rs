//! Integration tests of evtac-import on small simulated datasets and sessions.

mod check;
mod import;
mod session;

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
