//! `evtac`: contact-angle estimation for event-based tactile sensors, from the command line.
//!
//! The binary only parses arguments and shows progress; the work is done by the library crates
//! (`evtac-events`, `evtac-repr`, `evtac-sim`, `evtac-labels`, `evtac-learn`,
//! `evtac-experiments`, `evtac-online`). Run `evtac --help` for the subcommands.

mod cluster;
mod commands;
mod filtering;
mod formats;
mod inputs;
mod kinds;
mod outputs;
mod progress;
mod rewrite;
mod scale_seed;
mod sensor;
mod streams;
mod trial_references;
mod workers;

/// mimalloc rather than glibc's malloc: chosen when training ran on burn, which allocated and
/// freed megabyte tensors at every step and paid page faults for each under glibc (3.1 ms a step
/// against 1.1 ms). The hand-written training allocates once per run; the allocator has not been
/// re-measured since, and changing it would need a benchmark of the readers and builders first.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use clap::{Parser, Subcommand};

/// Contact-angle estimation for event-based tactile sensors (NeuroTac-style domes imaged by an
/// event camera): read and convert recordings, simulate trials, build representations, label,
/// train, evaluate, reproduce the paper, and estimate online.
#[derive(Debug, Parser)]
#[command(name = "evtac", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Summarise an event recording (format, resolution, event and IMU counts, time span).
    Info(commands::info::Args),
    /// Convert an event recording to AEDAT4, CSV or NPY (chosen by the output's extension).
    Convert(commands::convert::Args),
    /// Filter an event recording (dv-processing's noise, polarity and region filters exactly, a
    /// refractory period, the dome's disc) into AEDAT4, CSV or NPY.
    Filter(commands::filter::Args),
    /// Simulate NeuroTac trials of one of the paper's experiments (with evtac's sensor model and
    /// timing) into a dataset folder.
    Simulate(commands::simulate::Args),
    /// Measure a recording's sensor noise at rest (background, hot pixels, IMU noise and bias),
    /// optionally as simulator parameters for `evtac simulate --params`.
    Stats(commands::stats::Args),
    /// Cut a recording session into a dataset folder (one AEDAT4 per motion of the robot's log,
    /// or without a log, per motion found in the gyroscope).
    Import(commands::import::Args),
    /// Validate a dataset before training: manifest, files, time spans, IMU rate, calibration,
    /// no-contact recording, Experiment 3 groups (exit status 1 when anything is wrong).
    Check(commands::check::Args),
    /// Derive contact-angle labels from each trial's IMU stream.
    Labels(commands::labels::Args),
    /// Build static, dynamic or combined frames, potentials or pooled features at sample times.
    Represent(commands::represent::Args),
    /// Render what the sensor and the network see (events, binary frames, pooled features, a
    /// model's estimates) as an animated GIF, an MP4 video or a PNG contact sheet.
    Render(commands::render::Args),
    /// Train the MLP regressor on a dataset's training split.
    Train(commands::train::Args),
    /// Evaluate a trained model on a dataset split (MAE overall, pitch, roll; per phase).
    Evaluate(commands::evaluate::Args),
    /// Predict (pitch, roll) from a features NPY with a trained model.
    Predict(commands::predict::Args),
    /// Grid-search a representation's hyperparameters on a dataset (Experiment 1's tuning).
    Tune(commands::tune::Args),
    /// Reproduce the paper end to end: simulate, label, tune, Experiments 1-3, latency, report.
    Reproduce(commands::reproduce::Args),
    /// Which of the paper's conclusions survive the simulator: Experiment 1 with each unmeasured
    /// simulator parameter at x0.5 and x1.5.
    Sensitivity(commands::sensitivity::Args),
    /// Run one job of a jobs file (a Slurm array task's work).
    Jobs(commands::jobs::Args),
    /// Estimate contact angles online from a live or replayed event stream.
    Online(commands::online::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info(args) => commands::info::run(args),
        Command::Convert(args) => commands::convert::run(args),
        Command::Filter(args) => commands::filter::run(args),
        Command::Simulate(args) => commands::simulate::run(args),
        Command::Stats(args) => commands::stats::run(args),
        Command::Import(args) => commands::import::run(args),
        Command::Check(args) => commands::check::run(args),
        Command::Labels(args) => commands::labels::run(args),
        Command::Represent(args) => commands::represent::run(args),
        Command::Render(args) => commands::render::run(args),
        Command::Train(args) => commands::train::run(args),
        Command::Evaluate(args) => commands::evaluate::run(args),
        Command::Predict(args) => commands::predict::run(args),
        Command::Tune(args) => commands::tune::run(args),
        Command::Reproduce(args) => commands::reproduce::run(args),
        Command::Sensitivity(args) => commands::sensitivity::run(args),
        Command::Jobs(args) => commands::jobs::run(args),
        Command::Online(args) => commands::online::run(args),
    };
    if let Err(err) = result {
        eprintln!("error: {}", report(&err));
        std::process::exit(1);
    }
}

/// The error and its causes, joined by `: ` as `{:#}` does, but leaving out a cause whose
/// message the text before it already holds: the library errors embed their inner error's
/// message (`model.safetensors: No such file or directory`) and some also keep it as their
/// `source()`, which `{:#}` would print a second time. A part that only names again what the
/// part before it ends with (`reading X: X: No such file`, two layers of errors that each name
/// the path) is said once.
fn report(err: &anyhow::Error) -> String {
    let mut text = err.to_string();
    for cause in err.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text.push_str(": ");
            text.push_str(&cause);
        }
    }
    let mut parts: Vec<&str> = Vec::new();
    for part in text.split(": ") {
        if let Some(before) = parts.last()
            && ends_with_name(before, part)
        {
            continue;
        }
        parts.push(part);
    }
    parts.join(": ")
}

/// Whether `text` ends with `name` as a whole word (after a space, or all of it).
fn ends_with_name(text: &str, name: &str) -> bool {
    !name.is_empty()
        && text
            .strip_suffix(name)
            .is_some_and(|before| before.is_empty() || before.ends_with(' '))
}

#[cfg(test)]
mod tests {
    use super::{Cli, Command};
    use clap::Parser;
    use evtac_experiments::job::{Job, ReproduceJob};

    /// A Slurm reproduction's last task runs the job itself, and `evtac jobs show` prints the
    /// command line the same job equals: both must mean the same run, every flag included.
    #[test]
    fn a_reproduce_jobs_command_line_parses_back_to_its_arguments() {
        // Fields in another order than the job's own tests list them: the same struct, any order.
        let job = ReproduceJob {
            beyond: true,
            capture_ablation: false,
            capture_filter: None,
            recheck: false,
            grid: Some(evtac_experiments::plan::Grid::Paper),
            repeat_split: false,
            repeats: Some(2),
            datasets: Some(3),
            label_noise_deg: Some(0.0),
            fusions: false,
            noise_levels: Some(vec![0.0, 2.5]),
            inputs: evtac_import::inputs::Inputs::from_flags(true, true).with_filters(vec![
                "polarity=on".parse().unwrap(),
                "hot-pixels=auto".parse().unwrap(),
            ]),
            data: Some("data sets".into()),
            out: "runs/out".into(),
            seed: 7,
            scale: evtac_sim::Scale::Tiny,
        };
        let line = crate::commands::jobs::equivalent_command("evtac", &Job::Reproduce(job.clone()));
        let Command::Reproduce(parsed) = Cli::try_parse_from(&line).unwrap().command else {
            panic!("{line:?} is not a reproduce command");
        };
        assert_eq!(parsed.job(), job);
        // The other way of setting the ablation: a filter of its own.
        let own = ReproduceJob {
            capture_filter: Some("k-noise=2ms".parse().unwrap()),
            capture_ablation: true,
            ..job.clone()
        };
        let own_line =
            crate::commands::jobs::equivalent_command("evtac", &Job::Reproduce(own.clone()));
        let Command::Reproduce(own_parsed) = Cli::try_parse_from(&own_line).unwrap().command else {
            panic!("{own_line:?} is not a reproduce command");
        };
        assert_eq!(own_parsed.job(), own);
        assert_eq!(parsed.workers.jobs, Some(1));
        assert_eq!(
            (
                parsed.executor.executor,
                parsed.export_jobs,
                parsed.executor.slurm_args
            ),
            (crate::cluster::Executor::Local, None, None)
        );
    }

    /// An error chain whose layers each name the path (as `evtac render` of a missing file
    /// had: `reading X: X: X: No such file`) says the path once, and its cause once; so does
    /// one error whose message names the path its inner error names again.
    #[test]
    fn a_path_named_by_every_layer_is_said_once() {
        use anyhow::Context;
        let missing = || std::io::Error::new(std::io::ErrorKind::NotFound, "No such file");
        // Each layer's message embeds the one below, as the library errors' do.
        let err = Err::<(), _>(missing())
            .context("a.aedat4: No such file")
            .context("a.aedat4: a.aedat4: No such file")
            .context("reading a.aedat4")
            .unwrap_err();
        assert_eq!(super::report(&err), "reading a.aedat4: No such file");
        // A cause that names something else than the text's end is kept whole.
        let err = Err::<(), _>(missing())
            .context("b.csv: No such file")
            .context("reading a.aedat4")
            .unwrap_err();
        assert_eq!(super::report(&err), "reading a.aedat4: b.csv: No such file");
        let err = anyhow::anyhow!("reading a.aedat4: a.aedat4: No such file");
        assert_eq!(super::report(&err), "reading a.aedat4: No such file");
    }
}
