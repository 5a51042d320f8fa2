//! `evtac sensitivity`: which of the paper's conclusions survive the simulator's unmeasured
//! parameters. Experiment 1, tuning included, on a dataset simulated with each parameter at
//! x0.5 and x1.5 of its default, one at a time, beside the defaults
//! (`evtac_experiments::sensitivity`); writes `OUT/README.md`, `OUT/sensitivity.json` and
//! `OUT/gap-tornado.png` (`evtac_report::sensitivity`). Every point resumes from its finished
//! simulation and training runs. `--executor slurm` runs the unfinished points as one Slurm
//! array (each task `evtac jobs run FILE --index K`, which is `evtac sensitivity --point`), then
//! writes the summary here.

use crate::progress::Bars;
use anyhow::Context;
use evtac_experiments::context::RunContext;
use evtac_experiments::job::{Job, SensitivityPointJob};
use evtac_experiments::sensitivity::{self, FACTORS, PARAMETERS, Parameter, Varied};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `evtac sensitivity`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "The parameters and what each is: OUT/README.md, or the error a name \
    that is none of them gets. Every point has the same --seed. With --executor slurm the \
    unfinished points run as one Slurm job array, a task each, and the summary is written here \
    once every point has finished.\n\nExample: evtac sensitivity --scale small --out sensitivity \
    (39 points, about 90 minutes on 2 cores)"
)]
pub struct Args {
    /// Each point's size and seed (the same seed at every point).
    #[command(flatten)]
    pub scale_seed: crate::scale_seed::ScaleSeed,
    /// Output folder: the summary, and `points/<parameter>/x<factor>/` (each point's
    /// `point.json`, `simulator.json` and models; its dataset too with --keep-data).
    #[arg(long)]
    pub out: PathBuf,
    /// Parameters to vary, comma-separated (default: all 19).
    #[arg(long, value_delimiter = ',')]
    pub parameters: Option<Vec<String>>,
    /// Factors on each parameter's default, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = FACTORS)]
    pub factors: Vec<f64>,
    /// Worker threads.
    #[command(flatten)]
    pub workers: crate::workers::Workers,
    #[command(flatten)]
    pub executor: crate::cluster::ExecutorArgs,
    /// Keep each finished point's dataset and feature cache (about 1.1 GB a point at small
    /// scale); by default they are removed once the point's results are in its `point.json`,
    /// and its models are kept.
    #[arg(long)]
    pub keep_data: bool,
    /// Run one point only, PARAMETER:FACTOR (`baseline:1` for the defaults), into OUT as the
    /// point's folder, and write no summary: a Slurm task's work.
    #[arg(long, value_name = "PARAMETER:FACTOR")]
    pub point: Option<String>,
}

/// Runs the single point `spec` (`name:factor`) into `args.out`.
fn one_point(args: &Args, spec: &str) -> anyhow::Result<()> {
    let (name, factor) = spec
        .rsplit_once(':')
        .and_then(|(n, f)| Some((n, f.parse::<f64>().ok()?)))
        .with_context(|| format!("--point {spec}: give PARAMETER:FACTOR, e.g. cutoff:0.5"))?;
    let job = SensitivityPointJob {
        scale: args.scale_seed.scale,
        seed: args.scale_seed.seed,
        parameter: Varied::from(name),
        factor,
        out: args.out.clone(),
        keep_data: args.keep_data,
    };
    let pool = args.workers.pool()?;
    let bars = Bars::default();
    pool.install(|| sensitivity::run_point(&job, &bars))?;
    bars.finish();
    eprintln!("point {name} x{factor} finished in {}", args.out.display());
    Ok(())
}

/// Runs every unfinished point of the study on Slurm, one array task each.
fn points_on_slurm(args: &Args, parameters: &[Parameter]) -> anyhow::Result<()> {
    let out = std::path::absolute(&args.out).with_context(|| args.out.display().to_string())?;
    let jobs: Vec<Job> = sensitivity::points(parameters, &args.factors)
        .into_iter()
        .map(|(name, factor)| {
            Job::SensitivityPoint(SensitivityPointJob {
                scale: args.scale_seed.scale,
                seed: args.scale_seed.seed,
                out: sensitivity::point_dir(&out, &name, factor),
                parameter: name,
                factor,
                keep_data: args.keep_data,
            })
        })
        .collect();
    let (slurm, task) = (args.executor.slurm(), crate::cluster::task()?);
    let bars = Bars::default();
    slurm.sensitivity(&jobs, &task, &out.join("slurm"), &bars)?;
    bars.finish();
    Ok(())
}

/// The parameters `names` asks for, or every one.
fn chosen(names: Option<&[String]>) -> anyhow::Result<Vec<Parameter>> {
    let Some(names) = names else {
        return Ok(PARAMETERS.to_vec());
    };
    names
        .iter()
        .map(|n| {
            sensitivity::parameter(n)
                .ok_or_else(|| sensitivity::PerturbError::Unknown { name: n.clone() })
                .context("--parameters")
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
    let on_slurm = args.executor.on_slurm()?;
    if let Some(spec) = &args.point {
        anyhow::ensure!(
            !on_slurm,
            "--point runs one point here (a Slurm task's work): it takes no --executor slurm"
        );
        return one_point(&args, spec);
    }
    if on_slurm {
        points_on_slurm(&args, &parameters)?;
    }
    // Locally: every point; after Slurm: every point is finished, and reading them back is
    // quick.
    let plan = sensitivity::plan(args.scale_seed.scale);
    let pool = args.workers.pool()?;
    let bars = Bars::default();
    let models = args.out.join("points");
    let run = RunContext {
        plan: &plan,
        seed: args.scale_seed.seed,
        models: &models,
        progress: &bars,
    };
    let study = pool.install(|| {
        sensitivity::run(&parameters, &args.factors, &args.out, args.keep_data, &run)
    })?;
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
        args.scale_seed.scale,
        study.points.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
