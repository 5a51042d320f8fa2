//! `evtac jobs`: run one job of a jobs file, as a Slurm array task (or any scheduler) does.
//!
//! A jobs file (`evtac_experiments::job`) holds one typed job per line, as `evtac reproduce
//! --export-jobs` and `--executor slurm` write them. `evtac jobs run FILE --index
//! $SLURM_ARRAY_TASK_ID` runs job `index` (counted from 0, as array task ids are) in this
//! process, as `evtac simulate`, `evtac train` or `evtac reproduce` would, so a user's own
//! `sbatch --array=0-(N-1)` script needs nothing else (see `docs/cluster.md`). `evtac jobs show`
//! prints each job as the command it equals.

use std::path::{Path, PathBuf};

use crate::inputs::InputArgs;
use anyhow::{Context, bail};
use evtac_experiments::job::{self, Job, TrainJob};
use evtac_experiments::jobs::command_line;
use evtac_repr::ReprConfig;
use evtac_sim::Scale;

/// Arguments of `evtac jobs`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub action: Action,
}

/// What to do with a jobs file.
#[derive(Debug, clap::Subcommand)]
pub enum Action {
    /// Run one job of a jobs file (quietly, as an array task); exits non-zero if it fails.
    Run {
        /// The jobs file (`reproduce --export-jobs`, or `OUT/slurm/<stage>.jobs`).
        file: PathBuf,
        /// The job to run, from 0 (e.g. `$SLURM_ARRAY_TASK_ID`).
        #[arg(long)]
        index: usize,
    },
    /// Print how many jobs a jobs file holds (for `sbatch --array=0-(N-1)`).
    Count {
        /// The jobs file.
        file: PathBuf,
    },
    /// Print each job as the `evtac` command it equals, one per line.
    Show {
        /// The jobs file.
        file: PathBuf,
    },
}

/// Runs `evtac jobs`.
pub fn run(args: Args) -> anyhow::Result<()> {
    match args.action {
        Action::Count { file } => {
            println!("{}", job::read(&file)?.len());
            Ok(())
        }
        Action::Show { file } => {
            for job in job::read(&file)? {
                println!("{}", command_line(&equivalent_command("evtac", &job)));
            }
            Ok(())
        }
        Action::Run { file, index } => {
            let jobs = job::read(&file)?;
            let Some(job) = jobs.get(index) else {
                // An empty file has no range of indices to name (not "0 to 0").
                if jobs.is_empty() {
                    bail!("{} holds no jobs; there is no job {index}", file.display());
                }
                bail!(
                    "{} holds {} jobs (indices 0 to {}); there is no job {index}",
                    file.display(),
                    jobs.len(),
                    jobs.len() - 1
                );
            };
            let line = command_line(&equivalent_command("evtac", job));
            eprintln!("job {index} of {}: {line}", file.display());
            run_job(job).with_context(|| format!("job {index} of {} failed", file.display()))
        }
    }
}

/// Runs `job` in this process, on one worker thread: an array task has one CPU, and the
/// node's other cores are other tasks' (what `--jobs 1` said in the command lines).
fn run_job(job: &Job) -> anyhow::Result<()> {
    let pool = crate::workers::Workers { jobs: Some(1) }.pool()?;
    pool.install(|| {
        match job {
            Job::Simulate(j) => evtac_experiments::simulation::run(j, || {})?,
            Job::Train(j) => {
                if !evtac_experiments::jobs::is_done(&j.out) {
                    evtac_experiments::training::run_job(j, &|_| {}, |_| {})?;
                }
            }
            Job::Reproduce(j) => super::reproduce::run_job(j)?,
            Job::SensitivityPoint(j) => {
                evtac_experiments::sensitivity::run_point(j, &evtac_experiments::progress::Quiet)?
            }
        }
        Ok(())
    })
}

fn path(p: &Path) -> String {
    p.display().to_string()
}

/// `--scale S --seed N --out DIR --jobs 1`: what `simulate` and `reproduce` share (a task has
/// one CPU).
fn one_thread(scale: Scale, seed: u64, out: &Path) -> [String; 8] {
    [
        "--scale".into(),
        scale.name().into(),
        "--seed".into(),
        seed.to_string(),
        "--out".into(),
        path(out),
        "--jobs".into(),
        "1".into(),
    ]
}

/// The `exe ...` command `job` equals (for people reading a jobs file, and for logs). A training
/// job's representation is shown by the flags the experiments vary (tau, threshold, window,
/// count threshold); the jobs file holds its whole config.
pub fn equivalent_command(exe: &str, job: &Job) -> Vec<String> {
    let mut args: Vec<String> = vec![exe.into()];
    match job {
        Job::Simulate(j) => {
            args.extend([
                "simulate".into(),
                "--protocol".into(),
                j.protocol.name().into(),
            ]);
            args.extend(one_thread(j.scale, j.seed, &j.out));
            if let Some(n) = j.repeats {
                args.extend(["--repeats".into(), n.to_string()]);
            }
        }
        Job::Train(j) => args.extend(train_args(j)),
        Job::Reproduce(j) => {
            args.push("reproduce".into());
            args.extend(one_thread(j.scale, j.seed, &j.out));
            if let Some(data) = &j.data {
                args.extend(["--data".into(), path(data)]);
            }
            args.extend(InputArgs::of(&j.inputs).words());
            if let Some(levels) = &j.noise_levels {
                let levels: Vec<String> = levels.iter().map(f64::to_string).collect();
                args.extend(["--noise-levels".into(), levels.join(",")]);
            }
            if !j.fusions {
                args.push("--no-fusions".into());
            }
            if j.beyond {
                args.push("--beyond".into());
            }
            if let Some(sd) = j.label_noise_deg {
                args.extend(["--label-noise-deg".into(), sd.to_string()]);
            }
            if let Some(n) = j.datasets {
                args.extend(["--datasets".into(), n.to_string()]);
            }
            if let Some(n) = j.repeats {
                args.extend(["--repeats".into(), n.to_string()]);
            }
            if !j.repeat_split {
                args.push("--no-repeat-split".into());
            }
            if let Some(grid) = j.grid {
                args.extend(["--grid".into(), grid.name().into()]);
            }
            if !j.recheck {
                args.push("--no-recheck".into());
            }
            if let Some(spec) = &j.capture_filter {
                args.extend(["--capture-filter".into(), spec.to_string()]);
            }
            if !j.capture_ablation {
                args.push("--no-capture-filter".into());
            }
        }
        Job::SensitivityPoint(j) => {
            args.push("sensitivity".into());
            args.extend(one_thread(j.scale, j.seed, &j.out));
            args.extend(["--point".into(), format!("{}:{}", j.parameter, j.factor)]);
            if j.keep_data {
                args.push("--keep-data".into());
            }
        }
    }
    args
}

/// `train DATASET ...` for a training job.
fn train_args(j: &TrainJob) -> Vec<String> {
    let mut args = vec!["train".into(), path(&j.dataset)];
    let spec = &j.spec;
    if spec.label_noise_deg > 0.0 {
        args.extend(["--label-noise-deg".into(), spec.label_noise_deg.to_string()]);
    }
    args.extend(["--repr".into(), spec.repr.kind().name().into()]);
    if let Some(s) = spec.repr.static_part() {
        args.extend(["--tau-ms".into(), s.tau_ms.to_string()]);
        args.extend(["--threshold".into(), s.threshold.to_string()]);
    }
    if let Some(d) = spec.repr.dynamic_part() {
        args.extend(["--window-ms".into(), d.window_ms.to_string()]);
        args.extend(["--count-threshold".into(), d.count_threshold.to_string()]);
    }
    match spec.repr {
        ReprConfig::TimeSurface(c) => {
            args.extend(["--tau-ms".into(), c.tau_ms.to_string()]);
            if let Some(x) = c.threshold {
                args.extend(["--threshold".into(), x.to_string()]);
            }
        }
        ReprConfig::Histogram(c) => args.extend(["--window-ms".into(), c.window_ms.to_string()]),
        ReprConfig::VoxelGrid(c) => {
            args.extend(["--window-ms".into(), c.window_ms.to_string()]);
            args.extend(["--bins".into(), c.bins.to_string()]);
        }
        ReprConfig::Static(_)
        | ReprConfig::Dynamic(_)
        | ReprConfig::Combined { .. }
        | ReprConfig::Stacked { .. }
        | ReprConfig::Late { .. } => {}
    }
    args.extend(["--epochs".into(), spec.epochs.to_string()]);
    args.extend(["--seed".into(), spec.seed.to_string()]);
    args.extend(["--splits-seed".into(), j.splits_seed.to_string()]);
    if spec.sampling == evtac_experiments::sampling::Sampling::WITH_STOP {
        args.push("--stop-samples".into());
        if spec.phases.len() > 1 {
            args.push("--train-on-stop".into());
        }
    }
    args.extend(InputArgs::of(&j.inputs).words());
    args.extend(["--out".into(), path(&j.out), "--quiet".into()]);
    args
}
