//! `evtac jobs`: run one line of a jobs file, as a Slurm array task (or any scheduler) does.
//!
//! A jobs file holds one shell command line per job, as `evtac reproduce --export-jobs` and
//! `--executor slurm` write them. `evtac jobs run FILE --index $SLURM_ARRAY_TASK_ID` runs line
//! `index` (counted from 0, as array task ids are) through `/bin/sh -c`, and exits with its
//! status, so a user's own `sbatch --array=0-(N-1)` script needs nothing else (see
//! `docs/cluster.md`).

use std::path::PathBuf;
use std::process::Command;

use anyhow::{Context, bail};

/// Arguments of `evtac jobs`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub action: Action,
}

/// What to do with a jobs file.
#[derive(Debug, clap::Subcommand)]
pub enum Action {
    /// Run one job (line) of a jobs file; exits with the job's status.
    Run {
        /// The jobs file: one shell command line per job.
        file: PathBuf,
        /// The line to run, from 0 (e.g. `$SLURM_ARRAY_TASK_ID`).
        #[arg(long)]
        index: usize,
    },
    /// Print how many jobs a jobs file holds (for `sbatch --array=0-(N-1)`).
    Count {
        /// The jobs file.
        file: PathBuf,
    },
}

/// The job lines of `file` (blank lines are not jobs).
fn lines(file: &PathBuf) -> anyhow::Result<Vec<String>> {
    let text = std::fs::read_to_string(file)
        .with_context(|| format!("reading the jobs file {}", file.display()))?;
    Ok(text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(str::to_string)
        .collect())
}

/// Runs `evtac jobs`.
pub fn run(args: Args) -> anyhow::Result<()> {
    match args.action {
        Action::Count { file } => {
            println!("{}", lines(&file)?.len());
            Ok(())
        }
        Action::Run { file, index } => {
            let jobs = lines(&file)?;
            let Some(line) = jobs.get(index) else {
                bail!(
                    "{} holds {} jobs (indices 0 to {}); there is no job {index}",
                    file.display(),
                    jobs.len(),
                    jobs.len().saturating_sub(1)
                );
            };
            eprintln!("job {index} of {}: {line}", file.display());
            let status = Command::new("/bin/sh")
                .arg("-c")
                .arg(line)
                .status()
                .with_context(|| format!("starting /bin/sh for job {index}"))?;
            if !status.success() {
                bail!(
                    "job {index} of {} failed ({status}): {line}",
                    file.display()
                );
            }
            Ok(())
        }
    }
}
