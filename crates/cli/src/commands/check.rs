//! `evtac check`: validates a dataset (or the datasets of a `reproduce --data` folder) before
//! hours of training, and prints every problem as a table: file, line of `trials.csv`, field,
//! what is wrong, how to fix it. Exit status 1 when there is any problem, 0 and a short summary
//! when there is none. The checks are `evtac_import::check`'s.

use evtac_import::check::{self, CheckProgress, CheckReport, Problem};
use std::path::{Path, PathBuf};

/// Arguments of `evtac check`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The dataset folder (with `trials.csv`), or a folder of datasets as `reproduce --data`
    /// takes it (`exp1/`, `exp2/`, `exp3-speed/`, `exp3-depth/`).
    pub dir: PathBuf,
    /// Print the report as JSON on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Accept a missing calibration or no-contact recording, as the commands given the same
    /// flags would.
    #[command(flatten)]
    pub inputs: crate::inputs::InputArgs,
    /// Worker threads (the recordings are read in parallel).
    #[command(flatten)]
    pub workers: crate::workers::Workers,
}

/// Runs `evtac check`; exits with status 1 when the dataset has problems.
pub fn run(args: Args) -> anyhow::Result<()> {
    // The flag comes with the dataset inputs, but no check reads events through filters: it
    // is refused rather than accepted and ignored.
    if !args.inputs.filter.filters.is_empty() {
        anyhow::bail!(
            "check reads the dataset's files as they are, not through filters: give --filter to \
             the command that reads the events (train, tune, evaluate, render, reproduce)"
        );
    }
    let bar = crate::progress::bar(0, "reading");
    let report = args.workers.pool()?.install(|| {
        check::check(&args.dir, &args.inputs.inputs(), &|p| match p {
            CheckProgress::Recordings(n) => bar.inc_length(n),
            CheckProgress::Read => bar.inc(1),
        })
    });
    bar.finish_and_clear();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", render(&args.dir, &report));
    }
    if !report.problems.is_empty() {
        std::process::exit(1);
    }
    Ok(())
}

/// `path` relative to `dir` when it is inside it (shorter rows); `dir` itself (a folder that
/// is missing, unreadable or empty) as given, not as the empty path relative to itself.
fn short(dir: &Path, path: &Path) -> String {
    match path.strip_prefix(dir) {
        Ok(rel) if rel.as_os_str().is_empty() => dir.display().to_string(),
        Ok(rel) => rel.display().to_string(),
        Err(_) => path.display().to_string(),
    }
}

/// The table of problems, or the summary when there is none.
fn render(dir: &Path, report: &CheckReport) -> String {
    let trials: usize = report.datasets.iter().map(|d| d.1).sum();
    let checked = format!(
        "{} dataset{} ({trials} trials, {} recordings checked)",
        report.datasets.len(),
        if report.datasets.len() == 1 { "" } else { "s" },
        report.recordings
    );
    if report.problems.is_empty() {
        return format!("{}: no problems in {checked}\n", dir.display());
    }
    let header = ["file", "line", "field", "problem", "fix"].map(String::from);
    let rows: Vec<[String; 5]> = report
        .problems
        .iter()
        .map(|p: &Problem| {
            [
                short(dir, &p.file),
                p.line.map_or_else(|| "-".into(), |l| l.to_string()),
                p.field.clone().unwrap_or_else(|| "-".into()),
                p.problem.clone(),
                p.fix.clone(),
            ]
        })
        .collect();
    // Every column but the last padded to its widest cell.
    let mut widths = [0usize; 5];
    for row in std::iter::once(&header).chain(&rows) {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let mut out = String::new();
    for row in std::iter::once(&header).chain(&rows) {
        let mut line = String::new();
        for (i, cell) in row.iter().enumerate() {
            if i + 1 < row.len() {
                line.push_str(&format!("{cell:<w$}  ", w = widths[i]));
            } else {
                line.push_str(cell);
            }
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out.push_str(&format!(
        "{} problem{} in {checked}\n",
        report.problems.len(),
        if report.problems.len() == 1 { "" } else { "s" }
    ));
    out
}
