//! Where the commands that can run on Slurm (`reproduce`, `sensitivity`) run their jobs
//! (`--executor`, `--slurm-args`, one pair of flags flattened into both), and how they call
//! evtac back: the Slurm settings from `--slurm-args`, and each array task's shell command, this
//! same binary running one job of its array's jobs file.

use anyhow::Context;
use evtac_experiments::jobs::shell_quote;
use evtac_experiments::slurm::Slurm;
use std::path::Path;

/// Where the jobs of a reproduction (or the points of a sensitivity study) run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Executor {
    /// This machine, `--jobs` threads.
    Local,
    /// A Slurm cluster: `sbatch` job arrays, one task per job.
    Slurm,
}

/// The `--executor` and `--slurm-args` flags.
#[derive(Debug, Clone, clap::Args)]
pub struct ExecutorArgs {
    /// Where the jobs run: `local` (this machine's threads) or `slurm` (Slurm job arrays, one
    /// task per unfinished job, followed with squeue; OUT must be on storage every node sees).
    /// An interrupted or partly failed run resumes when run again.
    #[arg(long, value_enum, default_value_t = Executor::Local)]
    pub executor: Executor,
    /// Extra `sbatch` arguments for every Slurm job, e.g. "--partition=cpu --time=4:00:00".
    #[arg(long, allow_hyphen_values = true)]
    pub slurm_args: Option<String>,
}

impl ExecutorArgs {
    /// Whether the jobs go to Slurm; an error when `--slurm-args` is given without it (the
    /// settings would be silently ignored).
    pub fn on_slurm(&self) -> anyhow::Result<bool> {
        anyhow::ensure!(
            self.slurm_args.is_none() || self.executor == Executor::Slurm,
            "--slurm-args is for --executor slurm"
        );
        Ok(self.executor == Executor::Slurm)
    }

    /// The Slurm settings of `--slurm-args` (split on whitespace).
    pub fn slurm(&self) -> Slurm {
        Slurm {
            sbatch_args: self
                .slurm_args
                .as_deref()
                .unwrap_or_default()
                .split_whitespace()
                .map(str::to_string)
                .collect(),
            ..Slurm::default()
        }
    }
}

/// The shell command of an array task: this binary running job `$SLURM_ARRAY_TASK_ID` of the
/// jobs file it is given.
pub fn task() -> anyhow::Result<impl Fn(&Path) -> String> {
    let exe = std::env::current_exe().context("finding the evtac binary the tasks run")?;
    let exe = shell_quote(&exe.display().to_string());
    Ok(move |file: &Path| {
        let file = shell_quote(&file.display().to_string());
        format!("{exe} jobs run {file} --index \"$SLURM_ARRAY_TASK_ID\"")
    })
}
