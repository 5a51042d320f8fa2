//! How the commands that run on Slurm (`reproduce`, `sensitivity`) call evtac back: the Slurm
//! settings from `--slurm-args`, and each array task's shell command, this same binary running
//! one job of its array's jobs file.

use anyhow::Context;
use evtac_experiments::jobs::shell_quote;
use evtac_experiments::slurm::Slurm;
use std::path::Path;

/// The Slurm settings for `--slurm-args` (split on whitespace).
pub fn slurm(slurm_args: Option<&str>) -> Slurm {
    Slurm {
        sbatch_args: slurm_args
            .unwrap_or_default()
            .split_whitespace()
            .map(str::to_string)
            .collect(),
        ..Slurm::default()
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
