//! `evtac evaluate`: MAE of a trained model on a dataset split, overall, pitch and roll, and per
//! phase (motion, stop) when the dataset has stops.

use anyhow::Context;
use evtac_experiments::cache::FeatureCache;
use evtac_experiments::dataset::Dataset;
use evtac_experiments::results::Mae;
use evtac_experiments::sampling::{Phase, Sampling};
use evtac_experiments::splits::Split;
use evtac_experiments::training;
use evtac_learn::Model;
use std::path::PathBuf;

/// Arguments of `evtac evaluate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Model folder (written by `evtac train`).
    #[arg(long)]
    pub model: PathBuf,
    /// Dataset folder (with `trials.csv`).
    pub dataset: PathBuf,
    /// Split to evaluate: train, val, test, or all (every trial, e.g. Experiment 3's datasets).
    #[arg(long, default_value = "test")]
    pub split: String,
    /// Seed of the split, used when `splits.json` is missing.
    #[arg(long, default_value_t = 0)]
    pub splits_seed: u64,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Opting out of the dataset's calibration or mask (as the model was trained).
    #[command(flatten)]
    pub inputs: crate::inputs::InputArgs,
}

/// Runs `evtac evaluate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let model = Model::load(&args.model)
        .with_context(|| format!("loading model {}", args.model.display()))?;
    let ds = Dataset::open(&args.dataset, args.inputs.inputs())
        .with_context(|| format!("opening dataset {}", args.dataset.display()))?;
    let names: Vec<String> = if args.split == "all" {
        ds.manifest.trials.iter().map(|t| t.trial.clone()).collect()
    } else {
        let split: Split = args.split.parse().map_err(anyhow::Error::msg)?;
        ds.splits(args.splits_seed)?.get(split).to_vec()
    };
    let trials = ds.trials(&names)?;
    let stops = ds.has_stops();
    let sampling = if stops {
        Sampling::WITH_STOP
    } else {
        Sampling::MOTION
    };
    let cache = FeatureCache::new(&ds)?;
    let bar = crate::progress::bar(trials.len() as u64, "features");
    let config = model.repr_config();
    // The features are the model's representation on the model's crop, but masked with this
    // dataset's no-contact mask: a different mask is different features.
    let made = cache.provenance(&config)?;
    if let Some(why) = made.mismatch(&model.feature_provenance()) {
        anyhow::bail!(
            "the features of {} do not match the model {}: {why} (the dataset's \
             no_contact.aedat4, or --no-mask, gives the mask, and --filter the filters; the \
             model was trained with others)",
            args.dataset.display(),
            args.model.display()
        );
    }
    cache.ensure(&trials, std::slice::from_ref(&config), sampling, &|_| {
        bar.inc(1)
    })?;
    bar.finish_and_clear();
    let set = cache.load(&trials, &config, sampling, &[Phase::Motion, Phase::Stop])?;
    anyhow::ensure!(
        !set.samples.is_empty(),
        "the {} split has no samples",
        args.split
    );
    let pred = training::predict(&model, &set)?;
    let mut rows: Vec<(&str, Mae, usize)> = vec![(
        "all",
        training::mae_in(&set, &pred, None),
        set.samples.len(),
    )];
    if stops {
        for (name, phase) in [("motion", Phase::Motion), ("stop", Phase::Stop)] {
            let n = set.samples.iter().filter(|s| s.phase == phase).count();
            rows.push((name, training::mae_in(&set, &pred, Some(phase)), n));
        }
    }
    if args.json {
        let json = serde_json::json!({
            "model": args.model,
            "dataset": args.dataset,
            "split": args.split,
            "trials": trials.len(),
            "mae": rows.iter().map(|(name, m, n)| serde_json::json!({
                "phase": name, "samples": n,
                "overall": m.overall, "pitch": m.pitch, "roll": m.roll,
            })).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&json)?);
    } else {
        println!(
            "{} trials of the {} split of {}",
            trials.len(),
            args.split,
            args.dataset.display()
        );
        println!("phase    samples  MAE overall  pitch    roll   (deg)");
        for (name, m, n) in rows {
            println!(
                "{name:<8} {n:>7}  {:>11.4}  {:>6.4}  {:>6.4}",
                m.overall, m.pitch, m.roll
            );
        }
    }
    Ok(())
}
