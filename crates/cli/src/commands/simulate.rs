//! `evtac simulate`: simulate one of the paper's experiments into a dataset folder, or, with
//! `--session`, into a session folder as a real rig records it (`evtac_sim::session`). The
//! sensor model, its noise and the trial timing are evtac's choices: `docs/simulator.md`.

use std::path::PathBuf;

use anyhow::Context;
use evtac_import::filtering::FilteringCapture;
use evtac_sim::{
    DatasetConfig, Protocol, SessionConfig, SimParams, read_params, simulate_captured,
    simulate_session,
};

/// Arguments of `evtac simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Protocol: exp1, exp2, exp3-speed, exp3-depth or no-contact.
    #[arg(long)]
    pub protocol: Protocol,
    #[command(flatten)]
    pub scale_seed: crate::scale_seed::ScaleSeed,
    /// Output folder, a dataset or with --session a session (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Worker threads.
    #[command(flatten)]
    pub workers: crate::workers::Workers,
    /// Simulator parameters as JSON (e.g. an edited `simulator.json`'s `params`, or what
    /// `evtac stats --sim-params` measured on a recording); missing fields take their defaults,
    /// a misspelt field or a value the model cannot use is an error naming the field.
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Simulate only the first N trials of the protocol.
    #[arg(long)]
    pub limit: Option<usize>,
    /// Passes over the conditions of Experiments 1 and 2, each with the sensor seated again,
    /// instead of the scale's (2 at `paper`, 1 at `small` and `tiny`).
    #[arg(long, value_name = "N", value_parser = super::reproduce::parse_repeats)]
    pub repeats: Option<usize>,
    /// Write a recording session instead of a dataset: one session.aedat4 with every trial
    /// back to back (still gaps between them, a trigger at each motion onset), the robot's log
    /// robot_log.csv on its own clock (a seeded offset, jittered times), no_contact.aedat4,
    /// calibration.json, truth/ on the session's clock and session.json (the true clock
    /// offset); `evtac import` cuts it into a dataset.
    #[arg(long)]
    pub session: bool,
    /// With --session: the largest error of a logged time, microseconds.
    #[arg(long, default_value_t = 300, requires = "session", value_name = "US")]
    pub jitter_us: i64,
    // Each recording (every trial, no_contact.aedat4) is saved through these, from its first
    // event, as a filtering capture saves it; simulator.json records them. Not with --session,
    // whose one stream `evtac filter` (or `evtac import --filter`) filters.
    #[command(flatten)]
    pub filter: crate::filtering::FilterArgs,
}

/// Runs `evtac simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.session && !args.filter.filters.is_empty() {
        anyhow::bail!(
            "--filter saves each trial of a dataset filtered; a --session is one stream: filter \
             its session.aedat4 with `evtac filter`, or import it with `evtac import --filter`"
        );
    }
    let params = match &args.params {
        Some(path) => read_params(path).context("--params")?,
        None => SimParams::default(),
    };
    let config = DatasetConfig {
        params,
        limit: args.limit,
        repeats: args.repeats,
        ..DatasetConfig::new(args.protocol, args.scale_seed.scale, args.scale_seed.seed)
    };
    let trials = config.trials().len();
    let pool = args.workers.pool()?;
    let bar = crate::progress::bar(trials as u64, "simulating");
    let started = std::time::Instant::now();
    let what = if args.session { "session" } else { "dataset" };
    let written = if args.session {
        let session = SessionConfig {
            dataset: config,
            jitter_us: args.jitter_us,
            ..SessionConfig::new(args.protocol, args.scale_seed.scale, args.scale_seed.seed)
        };
        let record = pool
            .install(|| simulate_session(&session, &args.out, |_| bar.inc(1)))
            .with_context(|| format!("simulating {} into {}", args.protocol, args.out.display()))?;
        eprintln!(
            "robot clock offset {} us (pass it as evtac import --clock-offset-us)",
            record.clock_offset_us
        );
        record.trials.len()
    } else {
        let capture = FilteringCapture {
            specs: args.filter.filters.clone(),
        };
        pool.install(|| simulate_captured(&config, &args.out, &capture, |_| bar.inc(1)))
            .with_context(|| format!("simulating {} into {}", args.protocol, args.out.display()))?
            .trials
            .len()
    };
    bar.finish_and_clear();
    // The dataset `evtac reproduce` would simulate here (default parameters, every trial) is
    // marked done as `reproduce` marks its own, so a reproduction (local or on Slurm, whose
    // simulation tasks run this command) resumes from it. A session is no such dataset.
    if !args.session
        && args.params.is_none()
        && args.limit.is_none()
        && args.filter.filters.is_empty()
    {
        evtac_experiments::jobs::mark_done(&args.out)?;
    }
    eprintln!(
        "simulated {written} {} trials ({} scale, seed {}) as a {what} into {} in {:.1} s",
        args.protocol,
        args.scale_seed.scale,
        args.scale_seed.seed,
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
