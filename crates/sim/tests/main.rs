//! Integration tests of the simulator: one test binary, one module per concern.

mod behaviour;
mod dataset;
mod docs_table;
mod session;

use evtac_sim::{DatasetConfig, Protocol, Scale};

/// The first `limit` trials of a tiny dataset, tilting to 10 degrees only (stops at 2-8) to
/// keep the tests fast.
pub fn config(protocol: Protocol, seed: u64, limit: usize) -> DatasetConfig {
    let mut config = DatasetConfig {
        limit: Some(limit),
        ..DatasetConfig::new(protocol, Scale::Tiny, seed)
    };
    config.params.timeline.total_deg = 10.0;
    config.params.timeline.stop_range_deg = [2.0, 8.0];
    config
}

/// The files `simulate(seed, dir)` writes: with `seed`, with `seed` again on one thread, and
/// with `seed + 1`.
pub fn three_runs(
    seed: u64,
    simulate: impl Fn(u64, &std::path::Path) + Sync,
) -> [Vec<(String, Vec<u8>)>; 3] {
    let dirs: [_; 3] = std::array::from_fn(|_| tempfile::tempdir().unwrap());
    simulate(seed, dirs[0].path());
    // A different thread count must not change anything.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| simulate(seed, dirs[1].path()));
    simulate(seed + 1, dirs[2].path());
    dirs.map(|d| files(d.path()))
}

/// Every file of a folder, relative path and bytes, sorted.
pub fn files(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let rel = path.strip_prefix(dir).unwrap().display().to_string();
                out.push((rel, std::fs::read(&path).unwrap()));
            }
        }
    }
    out.sort();
    out
}
