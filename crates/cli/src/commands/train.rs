//! `evtac train`: train the MLP regressor on a dataset's training split (features computed and
//! cached when missing, splits made when missing), select on its validation split, save a model
//! bundle.

use anyhow::Context;
use evtac_experiments::job::TrainJob;
use evtac_experiments::jobs;
use evtac_experiments::sampling::{Phase, Sampling};
use evtac_experiments::training::TrainSpec;
use evtac_learn::TrainConfig;
use evtac_repr::{DenseSettings, DynamicConfig, ReprConfig, ReprKind, StaticConfig};
use std::path::PathBuf;

/// Representation settings shared by `train` and `tune`.
#[derive(Debug, Clone, clap::Args)]
pub struct ReprArgs {
    /// Representation: static, dynamic, combined (the paper's three), stacked or late (learned
    /// fusions of the static and dynamic frames), or time-surface, histogram, voxel-grid (the
    /// real-valued kinds the paper did not choose, as tonic computes them).
    #[arg(long, value_parser = crate::kinds::parser())]
    pub repr: ReprKind,
    /// Decay constant tau in ms: the static part's [default: 1000, the paper's] or a time
    /// surface's [default: 100].
    #[arg(long)]
    pub tau_ms: Option<f64>,
    /// Binarization threshold: the static part's, in event contributions [default: 2, the
    /// paper's]; a time surface's, in (0, 1) [default: none, continuous values].
    #[arg(long)]
    pub threshold: Option<f64>,
    /// Window length in ms: the dynamic part's, a histogram's or a voxel grid's [default: 640,
    /// the paper's dynamic window].
    #[arg(long)]
    pub window_ms: Option<f64>,
    /// Dynamic binarization threshold in events per pixel (the default is the paper's choice).
    #[arg(long, default_value_t = DynamicConfig::default().count_threshold)]
    pub count_threshold: u32,
    /// A voxel grid's temporal bins [default: 5].
    #[arg(long)]
    pub bins: Option<u32>,
    /// A full representation config as JSON (`evtac_repr::ReprConfig`), overriding the flags
    /// above (for the static accumulator's other settings).
    #[arg(long)]
    pub repr_json: Option<PathBuf>,
}

impl ReprArgs {
    /// The representation config these flags describe.
    pub fn config(&self) -> anyhow::Result<ReprConfig> {
        if let Some(path) = &self.repr_json {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading {}", path.display()))?;
            let config: ReprConfig = serde_json::from_str(&text)
                .with_context(|| format!("{} is not a representation config", path.display()))?;
            config.validate()?;
            return Ok(config);
        }
        let settings = DenseSettings {
            tau_ms: self.tau_ms,
            threshold: self.threshold,
            window_ms: self.window_ms,
            bins: self.bins,
        };
        if let Some(config) = crate::kinds::dense_config(self.repr, settings)? {
            return Ok(config);
        }
        let (s, d) = (StaticConfig::default(), DynamicConfig::default());
        let s = StaticConfig {
            tau_ms: self.tau_ms.unwrap_or(s.tau_ms),
            // Static thresholds are float32 contributions; the flag's decimal text is parsed
            // once, so an f32's shortest text comes back as that f32.
            threshold: self.threshold.map_or(s.threshold, |t| t as f32),
            ..s
        };
        let d = DynamicConfig {
            window_ms: self.window_ms.unwrap_or(d.window_ms),
            count_threshold: self.count_threshold,
        };
        let config = self.repr.config(s, d);
        config.validate()?;
        Ok(config)
    }
}

/// Arguments of `evtac train`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Dataset folder (with `trials.csv`).
    pub dataset: PathBuf,
    /// The representation.
    #[command(flatten)]
    pub repr: ReprArgs,
    /// Training epochs (the default is the paper's).
    #[arg(long, default_value_t = TrainConfig::default().epochs)]
    pub epochs: usize,
    /// Add Gaussian noise of this standard deviation (degrees) to every training label, seeded
    /// by --seed (validation and test labels are left alone): how much label noise costs.
    #[arg(long, default_value_t = 0.0, value_name = "SD")]
    pub label_noise_deg: f64,
    /// Seed of the initial weights and the shuffling.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Seed of the train/validation/test split, used when `splits.json` is missing.
    #[arg(long, default_value_t = 0)]
    pub splits_seed: u64,
    /// Also sample 10 points of each trial's stop phase (Experiment 2's sampling).
    #[arg(long)]
    pub stop_samples: bool,
    /// Train and validate on the stop samples too (needs `--stop-samples`).
    #[arg(long, requires = "stop_samples")]
    pub train_on_stop: bool,
    /// Model folder to write (a model bundle).
    #[arg(long)]
    pub out: PathBuf,
    /// Opting out of the dataset's calibration or mask.
    #[command(flatten)]
    pub inputs: crate::inputs::InputArgs,
    /// Train again even when `OUT` holds a finished model.
    #[arg(long)]
    pub force: bool,
    /// No progress bar or summary.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs `evtac train`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if jobs::is_done(&args.out) && !args.force {
        if !args.quiet {
            eprintln!(
                "{} already holds a finished model (use --force to train again)",
                args.out.display()
            );
        }
        return Ok(());
    }
    let sampling = if args.stop_samples {
        Sampling::WITH_STOP
    } else {
        Sampling::MOTION
    };
    let phases = if args.train_on_stop {
        vec![Phase::Motion, Phase::Stop]
    } else {
        vec![Phase::Motion]
    };
    let job = TrainJob {
        dataset: args.dataset.clone(),
        inputs: args.inputs.inputs(),
        splits_seed: args.splits_seed,
        spec: TrainSpec {
            repr: args.repr.config()?,
            seed: args.seed,
            epochs: args.epochs,
            sampling,
            phases,
            label_noise_deg: args.label_noise_deg,
        },
        out: args.out.clone(),
    };
    anyhow::ensure!(
        args.label_noise_deg.is_finite() && args.label_noise_deg >= 0.0,
        "--label-noise-deg {}: give a standard deviation in degrees, 0 or more",
        args.label_noise_deg
    );
    let trials =
        evtac_events::manifest::Manifest::read(&args.dataset).map_or(0, |m| m.trials.len() as u64);
    let hidden = || indicatif::ProgressBar::hidden();
    let fbar = if args.quiet {
        hidden()
    } else {
        crate::progress::bar(trials, "features")
    };
    let bar = if args.quiet {
        hidden()
    } else {
        crate::progress::bar(args.epochs as u64, "training")
    };
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "training [{elapsed_precise}] {wide_bar} epoch {pos}/{len} {msg} (eta {eta})",
    ) {
        bar.set_style(style);
    }
    let started = std::time::Instant::now();
    // What each part took: the features (built or read from the cache, with the dataset's
    // loading) end where the first epoch began; the epochs say what their steps and their
    // validation took.
    let (mut training_started, mut steps_s, mut validation_s) = (None, 0.0, 0.0);
    let val = evtac_experiments::training::run_job(&job, &|_| fbar.inc(1), |r| {
        fbar.finish_and_clear();
        training_started.get_or_insert_with(|| {
            std::time::Instant::now() - std::time::Duration::from_secs_f64(r.seconds)
        });
        let validation = r.validation_seconds.unwrap_or(0.0);
        (steps_s, validation_s) = (steps_s + r.seconds - validation, validation_s + validation);
        bar.set_message(format!(
            "loss {:.4} val MAE {:.3} deg",
            r.train_loss, r.val_mae
        ));
        bar.inc(1);
    })
    .with_context(|| format!("training into {}", args.out.display()))?;
    bar.finish_and_clear();
    if !args.quiet {
        let features_s = training_started.map_or(0.0, |t| (t - started).as_secs_f64());
        eprintln!(
            "features {features_s:.1} s ({trials} trials, built or from the cache); trained {} \
             epochs in {:.1} s (steps {steps_s:.1} s, validation {validation_s:.1} s): best \
             validation MAE {:.3} deg (pitch {:.3}, roll {:.3}); model in {}",
            args.epochs,
            steps_s + validation_s,
            val.overall,
            val.pitch,
            val.roll,
            args.out.display()
        );
    }
    Ok(())
}
