//! `evtac sensitivity`: which of the paper's conclusions survive the simulator's unmeasured
//! parameters. Experiment 1, tuning included, on a dataset simulated with each parameter at
//! x0.5 and x1.5 of its default, one at a time, beside the defaults
//! (`evtac_experiments::sensitivity`); writes `OUT/README.md`, `OUT/sensitivity.json` and
//! `OUT/gap-tornado.png` (`evtac_report::sensitivity`). Every point resumes from its finished
//! simulation and training runs.

use crate::progress::Bars;
use evtac_experiments::context::RunContext;
use evtac_experiments::plan::Plan;
use evtac_experiments::sensitivity::{self, FACTORS, PARAMETERS, Parameter};
use evtac_sim::Scale;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `evtac sensitivity`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Parameters: pin_rings, pin_size, normal_gain, spread_gain, skin_tau, \
    shear, trial_variation, creep, on_threshold, off_threshold, threshold_mismatch, cutoff, \
    refractory, leak_rate, shot_noise, hot_pixels, imu_noise (each described in OUT/README.md).\n\n\
    Example: evtac sensitivity --scale small --out sensitivity  (35 points, about an hour on \
    2 cores)"
)]
pub struct Args {
    /// Size of each point's dataset and plan: tiny (tests), small or paper.
    #[arg(long, default_value = "small")]
    pub scale: Scale,
    /// Master seed (simulation, splits, training), the same at every point.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output folder: `points/<parameter>/x<factor>/` (data, models), the summary.
    #[arg(long)]
    pub out: PathBuf,
    /// Parameters to vary, comma-separated (default: all 17).
    #[arg(long, value_delimiter = ',')]
    pub parameters: Option<Vec<String>>,
    /// Factors on each parameter's default, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = FACTORS)]
    pub factors: Vec<f64>,
    /// Worker threads.
    #[command(flatten)]
    pub workers: crate::workers::Workers,
}

/// The parameters `names` asks for, or every one.
fn chosen(names: Option<&[String]>) -> anyhow::Result<Vec<Parameter>> {
    let Some(names) = names else {
        return Ok(PARAMETERS.to_vec());
    };
    names
        .iter()
        .map(|n| {
            sensitivity::parameter(n).ok_or_else(|| {
                let all: Vec<&str> = PARAMETERS.iter().map(|p| p.name).collect();
                anyhow::anyhow!(
                    "--parameters: no simulator parameter {n:?}; the parameters are {}",
                    all.join(", ")
                )
            })
        })
        .collect()
}

/// Runs `evtac sensitivity`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let started = Instant::now();
    let parameters = chosen(args.parameters.as_deref())?;
    if let Some(bad) = args
        .factors
        .iter()
        .find(|f| !(f.is_finite() && **f > 0.0) || **f == 1.0)
    {
        anyhow::bail!(
            "--factors: {bad} is not a factor to vary by (finite, above 0, and not 1: the \
             baseline is always run)"
        );
    }
    let plan = Plan {
        fusions: false,
        noise_levels: Vec::new(),
        ..Plan::for_scale(args.scale)
    };
    let pool = args.workers.pool()?;
    let bars = Bars::default();
    let models = args.out.join("points");
    let run = RunContext {
        plan: &plan,
        seed: args.seed,
        models: &models,
        progress: &bars,
    };
    let study = pool.install(|| sensitivity::run(&parameters, &args.factors, &args.out, &run))?;
    let written = evtac_report::sensitivity::write(&args.out, &study)?;
    bars.finish();
    for path in &written {
        println!("{}", path.display());
    }
    for (name, (k, n)) in sensitivity::Conclusions::NAMES.iter().zip(study.shares()) {
        println!("{name}: holds at {k} of {n} perturbed points");
    }
    eprintln!(
        "sensitivity at scale {}: {} points in {:.1} s",
        args.scale,
        study.points.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
