//! Times `simulate_dataset` on a prefix of a protocol's trials and extrapolates to the whole
//! protocol by simulated duration:
//! `cargo run --release -p evtac-sim --example dataset_timing -- exp1 paper 100 [threads]`.

use evtac_sim::{DatasetConfig, Motion, Protocol, Scale, plan, simulate_dataset};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let protocol: Protocol = args.get(1).map_or("exp1", String::as_str).parse()?;
    let scale: Scale = args.get(2).map_or("paper", String::as_str).parse()?;
    let limit: usize = args.get(3).map_or(Ok(100), |s| s.parse())?;
    let threads: usize = args.get(4).map_or(Ok(2), |s| s.parse())?;
    let config = DatasetConfig {
        limit: Some(limit),
        ..DatasetConfig::new(protocol, scale, 0)
    };
    let timeline = &config.params.timeline;
    let all = plan(protocol, scale, 0, timeline);
    let duration = |n: usize| -> f64 {
        all.iter()
            .take(n)
            .map(|s| Motion::new(s, timeline, config.params.contact.approach_gap_mm).end_s)
            .sum()
    };
    let dir = tempfile::tempdir()?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let start = std::time::Instant::now();
    let manifest = pool.install(|| simulate_dataset(&config, dir.path(), |_| {}))?;
    let wall = start.elapsed().as_secs_f64();
    let bytes: u64 = std::fs::read_dir(dir.path())?
        .filter_map(|e| e.ok()?.metadata().ok())
        .map(|m| m.len())
        .sum();
    let (part, whole) = (duration(manifest.trials.len()), duration(all.len()));
    println!(
        "{protocol} {scale}: {} of {} trials, {part:.0} simulated s in {wall:.1} s on {threads} threads \
         ({:.1} simulated s per wall s), {:.0} MB; whole protocol: {whole:.0} simulated s, \
         extrapolated {:.0} s",
        manifest.trials.len(),
        all.len(),
        part / wall,
        bytes as f64 / 1e6,
        wall * whole / part
    );
    Ok(())
}
