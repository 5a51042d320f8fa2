//! `evtac tune`: Experiment 1's grid search for one representation on a dataset: one training
//! run per (decay tau x threshold) or (window x threshold), the lowest validation MAE chosen; or
//! the grid of a kind the paper did not choose (time surface: tau x threshold; histogram:
//! window; voxel grid: window x bins; `evtac_experiments::dense_grid`).

use anyhow::Context;
use evtac_experiments::cache::FeatureCache;
use evtac_experiments::context::RunContext;
use evtac_experiments::dataset::Dataset;
use evtac_experiments::plan::Plan;
use evtac_experiments::tuning::{self, Kind};
use evtac_sim::Scale;
use std::path::PathBuf;

/// The representation to tune.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TuneKind {
    /// Decay tau x threshold.
    Static,
    /// Window x threshold.
    Dynamic,
    /// Tau x threshold (0: the continuous surface).
    TimeSurface,
    /// Window.
    Histogram,
    /// Window x bins.
    VoxelGrid,
}

/// Arguments of `evtac tune`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Dataset folder (with `trials.csv`).
    pub dataset: PathBuf,
    /// Representation to tune (the scale's grid of it: `evtac_experiments::plan`).
    #[arg(long, value_enum)]
    pub repr: TuneKind,
    /// Grid and epochs of this scale: tiny, small or paper (every combination of evtac's grid,
    /// as the paper searches every combination of its own; 100 epochs).
    #[arg(long, default_value = "paper")]
    pub scale: Scale,
    /// Epochs per run (overrides the scale's).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Seed of every run and of the split (when `splits.json` is missing).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output folder for the runs' models and `tuning-<repr>.json` (default: DATASET/tuning).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Opting out of the dataset's calibration or mask.
    #[command(flatten)]
    pub inputs: crate::inputs::InputArgs,
    /// Worker threads.
    #[command(flatten)]
    pub workers: crate::workers::Workers,
}

/// Runs `evtac tune`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut plan = Plan::for_scale(args.scale);
    if let Some(e) = args.epochs {
        plan.tuning_epochs = e;
    }
    let kind = match args.repr {
        TuneKind::Static => Kind::Static,
        TuneKind::Dynamic => Kind::Dynamic,
        TuneKind::TimeSurface => Kind::TimeSurface,
        TuneKind::Histogram => Kind::Histogram,
        TuneKind::VoxelGrid => Kind::VoxelGrid,
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| args.dataset.join("tuning"));
    let ds = Dataset::open(&args.dataset, args.inputs.inputs())
        .with_context(|| format!("opening dataset {}", args.dataset.display()))?;
    let splits = ds.splits(args.seed)?;
    let cache = FeatureCache::new(&ds)?;
    let pool = args.workers.pool()?;
    let bars = crate::progress::Bars::default();
    let run = RunContext {
        plan: &plan,
        seed: args.seed,
        models: &out,
        progress: &bars,
    };
    let t = pool.install(|| tuning::tune(&cache, &splits, kind, &run))?;
    bars.finish();
    let json_path = out.join(format!("tuning-{}.json", kind.name()));
    crate::outputs::write_text(&json_path, &serde_json::to_string_pretty(&t)?)?;
    println!(
        "{:>10} {:>9} {:>9} {:>7} {:>7}",
        t.time_name,
        kind.threshold_name(),
        "val MAE",
        "pitch",
        "roll"
    );
    for r in &t.runs {
        println!(
            "{:>10} {:>9} {:>9.4} {:>7.4} {:>7.4}",
            r.time_ms, r.threshold, r.val.overall, r.val.pitch, r.val.roll
        );
    }
    println!(
        "chosen: {} {} ms, {} {} ({})",
        t.time_name,
        t.chosen_time_ms,
        kind.threshold_name(),
        t.chosen_threshold,
        json_path.display()
    );
    Ok(())
}
