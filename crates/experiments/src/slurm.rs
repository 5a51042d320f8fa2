//! Running a reproduction on a Slurm cluster: every stage's jobs become one Slurm job array
//! (`sbatch --array`), followed with `squeue` until it ends; the report is written by a last job
//! that depends on the final array (`--dependency=afterok`).
//!
//! Every job is a typed [`Job`] that is idempotent and marks its folder done (see
//! [`crate::jobs`]), so the jobs files ([`crate::job`]) are written from what is *not* finished, and a task that was cancelled or failed is found by
//! its missing `done` marker, not by trusting the scheduler's accounting (which many clusters
//! keep only for minutes, or not at all). Running the same command again resumes: only the
//! unfinished jobs are submitted. Tasks run the same jobs as a local run with the same seed, so
//! the results are the same bytes. What a task runs is the front end's to say (`task`: for the
//! CLI, `evtac jobs run FILE --index $SLURM_ARRAY_TASK_ID`): this library spells no command line
//! of evtac's.
//!
//! The stages, in order (each submitted only when the one before it has finished, because its
//! job list depends on the one before: Experiments 1 and 2 train the configs the tuning chose):
//!
//! 1. `simulate`: one task per dataset not yet simulated ([`Job::Simulate`]);
//! 2. `train`: the training jobs [`pipeline::export_jobs`] lists (first the tuning grid, then,
//!    once both tunings are done, Experiments 1 and 2);
//! 3. `report`: one task running the reproduction itself ([`Job::Reproduce`]), which finds every
//!    training done and evaluates, runs Experiment 3 and the latency study, and writes the
//!    report.
//!
//! A sensitivity study ([`Slurm::sensitivity`]) is one array, a task per point not yet finished
//! ([`Job::SensitivityPoint`]: each simulates, tunes and trains its Experiment 1 on its CPU);
//! the front end then writes the summary from the finished points.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use crate::job::{self, Job, ReproduceJob};
use crate::jobs;
use crate::pipeline::{self, Datasets};
use crate::plan::Plan;
use crate::progress::Progress;
use crate::stage::{PROTOCOLS, Stage};
use evtac_events::IoError;

/// What can go wrong running on Slurm.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A Slurm command could not be started (Slurm not installed, or not on the PATH).
    #[error("could not run `{command}` (is Slurm installed and on the PATH?): {source}")]
    Spawn {
        /// The command.
        command: String,
        /// The cause.
        source: std::io::Error,
    },
    /// A Slurm command failed.
    #[error("`{command}` failed: {stderr}")]
    Command {
        /// The command line.
        command: String,
        /// What it printed on stderr.
        stderr: String,
    },
    /// Tasks of an array ended without finishing their job.
    #[error(
        "{failed} of {tasks} tasks of the `{stage}` array (Slurm job {job}) did not finish: {details}. \
         Finished work is kept: run the same command again to resume"
    )]
    TasksFailed {
        /// The stage.
        stage: String,
        /// The array's Slurm job id.
        job: String,
        /// Tasks in the array.
        tasks: usize,
        /// Tasks that did not finish.
        failed: usize,
        /// Each failed task: its index, the state Slurm reports, its log file.
        details: String,
    },
    /// A log folder could not be made.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A jobs file could not be written.
    #[error(transparent)]
    JobsFile(#[from] job::FileError),
    /// Listing the jobs failed.
    #[error(transparent)]
    Pipeline(#[from] pipeline::Error),
}

/// How to submit: extra `sbatch` arguments (partition, account, time limit, ...) and how often
/// to poll.
#[derive(Debug, Clone)]
pub struct Slurm {
    /// Added to every `sbatch` call, split on whitespace (e.g. `--partition=cpu --time=2:00:00`).
    pub sbatch_args: Vec<String>,
    /// Time between two `squeue` polls.
    pub poll: Duration,
}

impl Default for Slurm {
    fn default() -> Self {
        Self {
            sbatch_args: Vec::new(),
            poll: Duration::from_secs(2),
        }
    }
}

/// A submitted job array.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArrayJob {
    /// Slurm's job id of the array.
    pub id: String,
    /// Tasks in the array.
    pub tasks: usize,
}

/// Runs `program args` and returns its stdout.
fn run(program: &str, args: &[String]) -> Result<String, Error> {
    let command = jobs::command_line(&[&[program.to_string()], args].concat());
    let out = Command::new(program)
        .args(args)
        .output()
        .map_err(|source| Error::Spawn {
            command: command.clone(),
            source,
        })?;
    if !out.status.success() {
        return Err(Error::Command {
            command,
            stderr: String::from_utf8_lossy(&out.stderr).trim().to_string(),
        });
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

impl Slurm {
    /// Submits `jobs` as one array named `evtac-<stage>`: they are written to the jobs file
    /// `logs/<stage>.jobs`, and task `k` runs the shell command `task(file)` (which must run job
    /// `$SLURM_ARRAY_TASK_ID` of the file), one CPU each, logging to
    /// `logs/<stage>-<job>_<task>.out`, after `after` (if any) has finished well.
    pub fn submit(
        &self,
        stage: &str,
        jobs: &[Job],
        task: &dyn Fn(&Path) -> String,
        logs: &Path,
        after: Option<&ArrayJob>,
    ) -> Result<ArrayJob, Error> {
        std::fs::create_dir_all(logs).map_err(IoError::at(logs))?;
        let file = logs.join(format!("{stage}.jobs"));
        job::write(&file, jobs)?;
        let wrap = task(&file);
        let mut args = vec![
            "--parsable".to_string(),
            format!("--array=0-{}", jobs.len().saturating_sub(1)),
            format!("--job-name=evtac-{stage}"),
            format!("--output={}/{stage}-%A_%a.out", logs.display()),
            "--cpus-per-task=1".to_string(),
        ];
        if let Some(after) = after {
            args.push(format!("--dependency=afterok:{}", after.id));
        }
        args.extend(self.sbatch_args.iter().cloned());
        args.push(format!("--wrap={wrap}"));
        let out = run("sbatch", &args)?;
        // `--parsable` prints `id` or `id;cluster`.
        let id = out.trim().split(';').next().unwrap_or_default().to_string();
        Ok(ArrayJob {
            id,
            tasks: jobs.len(),
        })
    }

    /// Waits until no task of `job` is pending or running, reporting each task that leaves the
    /// queue to `progress`.
    pub fn wait(&self, job: &ArrayJob, progress: &dyn Progress) -> Result<(), Error> {
        let mut left = job.tasks;
        loop {
            let out = run(
                "squeue",
                &[
                    "--noheader".into(),
                    "--array".into(),
                    format!("--jobs={}", job.id),
                    "--format=%i".into(),
                ],
            )?;
            let queued = out.lines().filter(|l| !l.trim().is_empty()).count();
            if queued < left {
                progress.advance((left - queued) as u64);
                left = queued;
            }
            if queued == 0 {
                return Ok(());
            }
            std::thread::sleep(self.poll);
        }
    }

    /// Cancels every task of `job` (`scancel`).
    pub fn cancel(&self, job: &ArrayJob) -> Result<(), Error> {
        run("scancel", std::slice::from_ref(&job.id)).map(|_| ())
    }

    /// The state Slurm reports for each task of `job` (`scontrol show job`, which keeps
    /// finished jobs for `MinJobAge`), by task index; empty when Slurm no longer knows them.
    pub fn task_states(&self, job: &ArrayJob) -> Vec<(usize, String)> {
        let Ok(out) = run(
            "scontrol",
            &[
                "--oneliner".into(),
                "show".into(),
                "job".into(),
                job.id.clone(),
            ],
        ) else {
            return Vec::new();
        };
        out.lines()
            .filter_map(|line| {
                let field = |key: &str| {
                    line.split_whitespace()
                        .find_map(|f| f.strip_prefix(key))
                        .map(str::to_string)
                };
                let task = field("ArrayTaskId=")?.parse().ok()?;
                Some((task, field("JobState=")?))
            })
            .collect()
    }
}

/// The simulation jobs of `reproduction` not yet finished (none when it has data of its own).
fn simulation_jobs(reproduction: &ReproduceJob) -> Vec<Job> {
    if reproduction.data.is_some() {
        return Vec::new();
    }
    let simulation = reproduction.simulation();
    PROTOCOLS
        .iter()
        .map(|&protocol| simulation.job(protocol, &sim_dir(reproduction)))
        .filter(|j| !jobs::is_done(&j.out))
        .map(Job::Simulate)
        .collect()
}

/// The folder of a reproduction's simulated datasets.
fn sim_dir(reproduction: &ReproduceJob) -> PathBuf {
    reproduction.out.join("data")
}

impl Slurm {
    /// Runs `reproduction` (with its `plan`) on the cluster: the simulation, the training jobs
    /// (two rounds: tuning, then Experiments 1 and 2), and the reproduction's own last task;
    /// returns when its report is written. Each task runs the shell command `task(jobs_file)`
    /// (see [`Slurm::submit`]).
    pub fn reproduce(
        &self,
        reproduction: &ReproduceJob,
        plan: &Plan,
        task: &dyn Fn(&Path) -> String,
        progress: &dyn Progress,
    ) -> Result<(), Error> {
        let slurm = self;
        let logs = reproduction.out.join("slurm");
        let sims = simulation_jobs(reproduction);
        if !sims.is_empty() {
            let job = submit(slurm, "simulate", &sims, task, &logs, None, progress)?;
            slurm.wait(&job, progress)?;
            let unfinished: Vec<usize> = (0..sims.len())
                .filter(|&k| !jobs::is_done(sims[k].out()))
                .collect();
            check(slurm, "simulate", &job, &unfinished, &logs)?;
        }
        let data = Datasets {
            inputs: reproduction.inputs.clone(),
            ..Datasets::in_dir(
                reproduction
                    .data
                    .as_deref()
                    .unwrap_or(&sim_dir(reproduction)),
            )
        };
        let (seed, out) = (reproduction.seed, &reproduction.out);
        let report = [Job::Reproduce(reproduction.clone())];
        let submitted = std::time::SystemTime::now();
        let mut round = 0;
        let report_job = loop {
            let train = pipeline::export_jobs(&data, plan, seed, out)?;
            if train.is_empty() {
                break submit(slurm, "report", &report, task, &logs, None, progress)?;
            }
            // Once both tunings are done, this round (Experiments 1 and 2) is the last: the
            // report task is queued behind it at once.
            let last = pipeline::tunings_finished(plan, out);
            round += 1;
            let stage = format!("train-{round}");
            let job = submit(slurm, &stage, &train, task, &logs, None, progress)?;
            let report_job = if last {
                let after = Some(&job);
                Some(submit(
                    slurm, "report", &report, task, &logs, after, progress,
                )?)
            } else {
                None
            };
            slurm.wait(&job, progress)?;
            let left = pipeline::export_jobs(&data, plan, seed, out)?;
            let unfinished: Vec<usize> = (0..train.len())
                .filter(|&k| left.contains(&train[k]))
                .collect();
            if let Err(e) = check(slurm, &stage, &job, &unfinished, &logs) {
                // A report behind a failed array would wait forever (DependencyNeverSatisfied).
                if let Some(report_job) = report_job {
                    slurm.cancel(&report_job)?;
                }
                return Err(e);
            }
            if let Some(report_job) = report_job {
                break report_job;
            }
        };
        slurm.wait(&report_job, progress)?;
        let written = std::fs::metadata(out.join("report.md"))
            .and_then(|m| m.modified())
            .is_ok_and(|t| t >= submitted);
        check(
            slurm,
            "report",
            &report_job,
            if written { &[] } else { &[0] },
            &logs,
        )
    }
}

impl Slurm {
    /// Runs the unfinished points among `points` (sensitivity-point jobs) as one array,
    /// `sensitivity`, logging under `logs`, and returns when every one has finished (or an
    /// error naming those that did not). The study's summary is the caller's to write, from
    /// the finished points.
    pub fn sensitivity(
        &self,
        points: &[Job],
        task: &dyn Fn(&Path) -> String,
        logs: &Path,
        progress: &dyn Progress,
    ) -> Result<(), Error> {
        let todo: Vec<Job> = points
            .iter()
            .filter(|j| !jobs::is_done(j.out()))
            .cloned()
            .collect();
        if todo.is_empty() {
            return Ok(());
        }
        let job = submit(self, "sensitivity", &todo, task, logs, None, progress)?;
        self.wait(&job, progress)?;
        let unfinished: Vec<usize> = (0..todo.len())
            .filter(|&k| !jobs::is_done(todo[k].out()))
            .collect();
        check(self, "sensitivity", &job, &unfinished, logs)
    }
}

/// Submits one stage's array (after `after`, if given) and says so.
fn submit(
    slurm: &Slurm,
    stage: &str,
    jobs: &[Job],
    task: &dyn Fn(&Path) -> String,
    logs: &Path,
    after: Option<&ArrayJob>,
    progress: &dyn Progress,
) -> Result<ArrayJob, Error> {
    let job = slurm.submit(stage, jobs, task, logs, after)?;
    progress.stage(Stage::SlurmTasks, jobs.len() as u64);
    let behind = after.map_or(String::new(), |a| format!(" after job {}", a.id));
    progress.message(&format!(
        "`{stage}`: {} task(s) submitted as Slurm job {}{behind}",
        jobs.len(),
        job.id
    ));
    Ok(job)
}

/// An error naming the tasks of `job` in `unfinished`, with Slurm's state and log of each.
fn check(
    slurm: &Slurm,
    stage: &str,
    job: &ArrayJob,
    unfinished: &[usize],
    logs: &Path,
) -> Result<(), Error> {
    if unfinished.is_empty() {
        return Ok(());
    }
    let states = slurm.task_states(job);
    let details = unfinished
        .iter()
        .map(|&k| {
            let state = states
                .iter()
                .find(|(t, _)| *t == k)
                // Slurm forgets a task cancelled before it started (and any task once its
                // record expires), so "not listed" is all that can honestly be said of it.
                .map_or(
                    "not listed by Slurm (cancelled before it started, or its record expired)",
                    |(_, s)| s.as_str(),
                );
            let log = logs.join(format!("{stage}-{}_{k}.out", job.id));
            format!("task {k} {state} (log {})", log.display())
        })
        .collect::<Vec<_>>()
        .join("; ");
    Err(Error::TasksFailed {
        stage: stage.to_string(),
        job: job.id.clone(),
        tasks: job.tasks,
        failed: unfinished.len(),
        details,
    })
}
