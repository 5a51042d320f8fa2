//! `evtac reproduce`: the paper end to end. Simulates the datasets when none are given (every
//! protocol), then labels, splits, tuning, Experiments 1-3, the latency study and the report
//! (`OUT/report.md`, `OUT/results.json`, `OUT/figures/`). Interrupted runs resume from finished
//! jobs; `--export-jobs` writes the ready training jobs as `evtac train` lines instead.

use super::tune::Bars;
use anyhow::Context;
use evtac_experiments::jobs::{self, Progress};
use evtac_experiments::pipeline::{self, Datasets};
use evtac_experiments::plan::Plan;
use evtac_sim::{DatasetConfig, Protocol, Scale, simulate_dataset};
use std::path::{Path, PathBuf};
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

fn simulate_all(dir: &Path, scale: Scale, seed: u64, bars: &Bars) -> anyhow::Result<()> {
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
    let data_dir = match &args.data {
        Some(d) => d.clone(),
        None => {
            let d = args.out.join("data");
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
