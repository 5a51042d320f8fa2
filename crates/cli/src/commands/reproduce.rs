//! `evtac reproduce`: the paper end to end. Simulates the datasets when none are given (every
//! protocol), then labels, splits, tuning, Experiments 1-3, the latency study and the report
//! (`OUT/report.md`, `OUT/results.json`, `OUT/figures/`). Interrupted runs resume from finished
//! jobs; `--export-jobs` writes the ready training jobs as `evtac train` lines instead.

use super::tune::Bars;
use anyhow::Context;
use evtac_events::manifest::Manifest;
use evtac_experiments::jobs::{self, Progress};
use evtac_experiments::pipeline::{self, Datasets};
use evtac_experiments::plan::Plan;
use evtac_sim::{DatasetConfig, Protocol, Scale, simulate_dataset};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// Arguments of `evtac reproduce`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Size: tiny (tests, a few minutes), small (under 20 minutes on 2 cores) or paper.
    #[arg(long, default_value = "small")]
    pub scale: Scale,
    /// Folder with the datasets `exp1/` (required), `exp2/`, `exp3-speed/`, `exp3-depth/`
    /// (simulated into `OUT/data` when not given).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Master seed (simulation, splits, training).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output folder: models, report, figures.
    #[arg(long)]
    pub out: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Write the training jobs that are ready (not finished) to FILE, one `evtac train` command
    /// per line (for a Slurm array or GNU parallel), and stop. Run them, then run `evtac
    /// reproduce` again with the same arguments: it resumes from the finished jobs.
    #[arg(long)]
    pub export_jobs: Option<PathBuf>,
}

const PROTOCOLS: [Protocol; 4] = [
    Protocol::Exp1,
    Protocol::Exp2,
    Protocol::Exp3Speed,
    Protocol::Exp3Depth,
];

/// Reference costs, in seconds on the 2-core development machine, measured in `evtac reproduce
/// --scale small` (7.7 min): they weigh the stages of the overall progress bar, whose ETA then
/// follows this machine's actual pace.
mod cost {
    /// Simulating one trial (52 s for 448 trials).
    pub const SIMULATE_TRIAL: f64 = 0.116;
    /// Features of one trial for every configuration of one pass.
    pub const FEATURES_TRIAL: f64 = 0.03;
    /// One training epoch of one run, per training trial (about 0.13 s per epoch for the 84
    /// training trials of the small Experiment 1 dataset).
    pub const EPOCH_TRAIN_TRIAL: f64 = 0.0015;
    /// One latency measurement (representation x interval) per test trial.
    pub const LATENCY_TRIAL: f64 = 0.033;
    /// Share of a dataset's trials in its training split.
    pub const TRAIN_SHARE: f64 = 0.7;
}

/// Trial counts of the datasets a reproduction will run on.
#[derive(Debug, Clone, Copy, Default)]
struct TrialCounts {
    exp1: usize,
    exp2: usize,
    exp3: usize,
    /// Trials still to simulate.
    simulate: usize,
}

/// Estimated seconds of a stage that starts with `total` units, from its name.
fn stage_cost(name: &str, total: u64, plan: &Plan, counts: &TrialCounts) -> f64 {
    let total = total as f64;
    let train = |n: usize| n as f64 * cost::TRAIN_SHARE * cost::EPOCH_TRAIN_TRIAL;
    if name.starts_with("simulating") {
        total * cost::SIMULATE_TRIAL
    } else if name.starts_with("tuning") {
        total * plan.tuning_epochs as f64 * train(counts.exp1)
    } else if name == "experiment 1 training" {
        total * plan.epochs as f64 * train(counts.exp1)
    } else if name == "experiment 2 training" {
        total * plan.epochs as f64 * train(counts.exp2)
    } else if name == "latency" {
        let trials = plan.latency_trials.min(counts.exp1.div_ceil(6).max(1));
        total * trials as f64 * cost::LATENCY_TRIAL
    } else {
        total * cost::FEATURES_TRIAL
    }
}

/// Estimated seconds of the whole reproduction (the stages [`stage_cost`] will see).
fn total_cost(plan: &Plan, counts: &TrialCounts) -> f64 {
    let c = |name: &str, total: usize| stage_cost(name, total as u64, plan, counts);
    let tuning_trials = (counts.exp1 as f64 * 0.85).round() as usize;
    let mut sum = c("simulating", counts.simulate)
        + c(
            "features",
            2 * tuning_trials + counts.exp1 + counts.exp2 + counts.exp3,
        )
        + c(
            "tuning",
            plan.static_grid().len() + plan.dynamic_grid().len(),
        )
        + c("experiment 1 training", 3 * plan.seeds)
        + c("latency", 3 * plan.latency_intervals_ms.len());
    if counts.exp2 > 0 {
        sum += c("experiment 2 training", 9 * plan.exp2_seeds);
    }
    sum
}

/// The stage bars plus an overall bar over the estimated cost of every stage: its ETA is the
/// estimate of the time left for the whole run.
struct Overall<'a> {
    bars: &'a Bars,
    overall: indicatif::ProgressBar,
    plan: &'a Plan,
    counts: TrialCounts,
    /// Milliseconds of estimated cost per unit of the current stage.
    per_unit: Mutex<f64>,
}

impl<'a> Overall<'a> {
    fn new(bars: &'a Bars, plan: &'a Plan, counts: TrialCounts) -> Self {
        let total_ms = (total_cost(plan, &counts) * 1000.0).round() as u64;
        let overall = bars.add(crate::progress::bar(total_ms.max(1), "overall"));
        overall.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:>12} [{elapsed_precise}] {wide_bar} {percent:>3}% (eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        Self {
            bars,
            overall,
            plan,
            counts,
            per_unit: Mutex::new(0.0),
        }
    }

    fn finish(&self) {
        self.overall.finish_and_clear();
        self.bars.finish();
    }
}

impl Progress for Overall<'_> {
    fn stage(&self, name: &str, total: u64) {
        self.bars.stage(name, total);
        if let Ok(mut per_unit) = self.per_unit.lock() {
            let cost = stage_cost(name, total, self.plan, &self.counts) * 1000.0;
            *per_unit = if total > 0 { cost / total as f64 } else { 0.0 };
        }
    }
    fn advance(&self, n: u64) {
        self.bars.advance(n);
        if let Ok(per_unit) = self.per_unit.lock() {
            self.overall.inc((*per_unit * n as f64).round() as u64);
        }
    }
    fn message(&self, text: &str) {
        self.bars.message(text);
    }
}

/// Trial counts: from the simulation plans for datasets still to simulate, else from the
/// datasets' manifests.
fn trial_counts(data: Option<&Path>, dir: &Path, scale: Scale, seed: u64) -> TrialCounts {
    let mut counts = TrialCounts::default();
    for protocol in PROTOCOLS {
        let n = match data {
            Some(d) => Manifest::read(d.join(protocol.name())).map_or(0, |m| m.trials.len()),
            None => {
                let out = dir.join(protocol.name());
                let config = DatasetConfig::new(protocol, scale, seed);
                let n = evtac_sim::plan(protocol, scale, seed, &config.params.timeline).len();
                if !jobs::is_done(&out) {
                    counts.simulate += n;
                }
                n
            }
        };
        match protocol {
            Protocol::Exp1 => counts.exp1 = n,
            Protocol::Exp2 => counts.exp2 = n,
            _ => counts.exp3 += n,
        }
    }
    counts
}

fn simulate_all(dir: &Path, scale: Scale, seed: u64, bars: &dyn Progress) -> anyhow::Result<()> {
    for protocol in PROTOCOLS {
        let out = dir.join(protocol.name());
        if jobs::is_done(&out) {
            continue;
        }
        let config = DatasetConfig::new(protocol, scale, seed);
        let n = evtac_sim::plan(protocol, scale, seed, &config.params.timeline).len();
        bars.stage(&format!("simulating {protocol}"), n as u64);
        simulate_dataset(&config, &out, |_| bars.advance(1))
            .with_context(|| format!("simulating {protocol} into {}", out.display()))?;
        jobs::mark_done(&out)?;
    }
    Ok(())
}

/// Runs `evtac reproduce`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let started = Instant::now();
    let plan = Plan::for_scale(args.scale.name())
        .with_context(|| format!("no plan for scale {}", args.scale))?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()
        .context("starting worker threads")?;
    let bars = Bars::default();
    let sim_dir = args.out.join("data");
    let counts = trial_counts(args.data.as_deref(), &sim_dir, args.scale, args.seed);
    let bars = Overall::new(&bars, &plan, counts);
    let data_dir = match &args.data {
        Some(d) => d.clone(),
        None => {
            let d = sim_dir;
            pool.install(|| simulate_all(&d, args.scale, args.seed, &bars))?;
            bars.message(&format!(
                "simulated datasets ready in {:.1} s",
                started.elapsed().as_secs_f64()
            ));
            d
        }
    };
    let data = Datasets::in_dir(&data_dir);
    anyhow::ensure!(
        data.exp1.join(evtac_events::manifest::FILE_NAME).is_file(),
        "{} has no Experiment 1 dataset (exp1/trials.csv)",
        data_dir.display()
    );
    if let Some(file) = &args.export_jobs {
        let exe = std::env::current_exe()
            .map(|p| p.display().to_string())
            .unwrap_or_else(|_| "evtac".into());
        let lines = pipeline::export_jobs(&data, &plan, args.seed, &args.out, &exe)?;
        let mut text = lines.join("\n");
        if !text.is_empty() {
            text.push('\n');
        }
        std::fs::write(file, text).with_context(|| format!("writing {}", file.display()))?;
        bars.finish();
        eprintln!(
            "wrote {} training jobs to {}; run them (e.g. `parallel < {}`), then run this command again without --export-jobs",
            lines.len(),
            file.display(),
            file.display()
        );
        return Ok(());
    }
    let results =
        pool.install(|| pipeline::reproduce(&data, &plan, args.seed, &args.out, &bars))?;
    bars.finish();
    println!("{}", args.out.join("report.md").display());
    for e in &results.exp1 {
        println!(
            "{:<9} test MAE {} deg (pitch {}, roll {})",
            e.name,
            e.test.overall.display(),
            e.test.pitch.display(),
            e.test.roll.display()
        );
    }
    eprintln!(
        "reproduced at scale {} in {:.1} s",
        args.scale,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
