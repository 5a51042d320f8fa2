//! `evtac simulate`: simulate one of the paper's experiments into a dataset folder (the sensor
//! model, its noise and the trial timing are evtac's choices: `docs/simulator.md`).

use std::path::PathBuf;

use anyhow::Context;
use evtac_sim::{DatasetConfig, Protocol, Scale, SimParams, simulate_dataset};

/// Arguments of `evtac simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Protocol: exp1, exp2, exp3-speed, exp3-depth or no-contact.
    #[arg(long)]
    pub protocol: Protocol,
    /// Size: tiny (tests), small (minutes) or paper (the paper's trial counts).
    #[arg(long, default_value = "small")]
    pub scale: Scale,
    /// Seed: the same seed gives the same bytes.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output dataset folder (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Worker threads.
    #[command(flatten)]
    pub workers: crate::workers::Workers,
    /// Simulator parameters as JSON (e.g. an edited `simulator.json`'s `params`); missing
    /// fields take their defaults.
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Simulate only the first N trials of the protocol.
    #[arg(long)]
    pub limit: Option<usize>,
}

/// Runs `evtac simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let params = match &args.params {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading {}", path.display()))?;
            serde_json::from_str::<SimParams>(&text)
                .with_context(|| format!("parsing simulator parameters {}", path.display()))?
        }
        None => SimParams::default(),
    };
    let config = DatasetConfig {
        params,
        limit: args.limit,
        ..DatasetConfig::new(args.protocol, args.scale, args.seed)
    };
    let trials = evtac_sim::plan(
        args.protocol,
        args.scale,
        args.seed,
        &config.params.timeline,
    )
    .len()
    .min(args.limit.unwrap_or(usize::MAX));
    let pool = args.workers.pool()?;
    let bar = crate::progress::bar(trials as u64, "simulating");
    let started = std::time::Instant::now();
    let manifest = pool
        .install(|| simulate_dataset(&config, &args.out, |_| bar.inc(1)))
        .with_context(|| format!("simulating {} into {}", args.protocol, args.out.display()))?;
    bar.finish_and_clear();
    // The dataset `evtac reproduce` would simulate here (default parameters, every trial) is
    // marked done as `reproduce` marks its own, so a reproduction (local or on Slurm, whose
    // simulation tasks run this command) resumes from it.
    if args.params.is_none() && args.limit.is_none() {
        evtac_experiments::jobs::mark_done(&args.out)?;
    }
    eprintln!(
        "simulated {} {} trials ({} scale, seed {}) into {} in {:.1} s",
        manifest.trials.len(),
        args.protocol,
        args.scale,
        args.seed,
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
