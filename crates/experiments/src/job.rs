//! [`Job`]: one unit of a reproduction's work, as data. The local pipeline runs its training as
//! [`TrainJob`]s, `evtac reproduce --export-jobs` writes the ready ones to a jobs file, the Slurm
//! executor writes one jobs file per array, and `evtac jobs run FILE --index K` runs job `K` of a
//! file: all four share this type, so a job means the same thing wherever it runs, and no
//! library code spells a command line that clap would have to parse back.
//!
//! A job only describes its work; the module that owns the work runs it
//! ([`crate::simulation::run`], [`crate::training::run_job`], the pipeline from
//! [`ReproduceJob::plan`], [`crate::sensitivity::run_point`]), so this file imports none of them.
//!
//! A jobs file is JSON Lines: one job per line (line `K` is array task `K`), each object carrying
//! the file format's version and the job's kind:
//!
//! ```text
//! {"format":1,"job":"train","dataset":"data/exp1","inputs":{...},"splits_seed":0,"spec":{...},"out":"out/models/..."}
//! ```
//!
//! Files written before jobs were typed held shell command lines; reading one is an error that
//! says to export the jobs again.

use std::path::{Path, PathBuf};

use evtac_events::IoError;
use evtac_events::output::write_atomic;
use evtac_import::inputs::Inputs;
use evtac_repr::ReprConfig;
use evtac_sim::{Protocol, Scale};
use serde::{Deserialize, Serialize};

use crate::plan::{Grid, Plan};
use crate::results::Varied;
use crate::sampling::{Phase, Sampling};

/// The version of the jobs-file format this build writes and reads.
pub const FORMAT: u32 = 1;

/// One unit of work.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "job", rename_all = "kebab-case")]
pub enum Job {
    /// Simulate one dataset.
    Simulate(SimulateJob),
    /// Train one model.
    Train(TrainJob),
    /// A whole reproduction on one machine, resuming from every finished job (the Slurm
    /// executor's last task: evaluation, Experiment 3, latency and the report).
    Reproduce(ReproduceJob),
    /// One point of a sensitivity study (a Slurm task of `evtac sensitivity`).
    SensitivityPoint(SensitivityPointJob),
}

impl Job {
    /// The folder the job writes (finished when it holds a `done` marker).
    pub fn out(&self) -> &Path {
        match self {
            Job::Simulate(j) => &j.out,
            Job::Train(j) => &j.out,
            Job::Reproduce(j) => &j.out,
            Job::SensitivityPoint(j) => &j.out,
        }
    }
}

/// Simulating one dataset of a protocol with the simulator's defaults (what `evtac simulate`
/// does without `--params` or `--session`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulateJob {
    /// The protocol.
    pub protocol: Protocol,
    /// How many trials.
    pub scale: Scale,
    /// Master seed.
    pub seed: u64,
    /// The dataset folder to write.
    pub out: PathBuf,
    /// Passes over the conditions of Experiments 1 and 2 instead of the scale's, or `None`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repeats: Option<usize>,
}

impl SimulateJob {
    /// What the job simulates.
    pub fn config(&self) -> evtac_sim::DatasetConfig {
        evtac_sim::DatasetConfig {
            repeats: self.repeats,
            ..evtac_sim::DatasetConfig::new(self.protocol, self.scale, self.seed)
        }
    }

    /// How many trials the dataset has (for a progress bar).
    pub fn trials(&self) -> usize {
        self.config().trials().len()
    }
}

/// What one training job trains: the representation, seeds, epochs and samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainSpec {
    /// The representation.
    pub repr: ReprConfig,
    /// Seed of the initial weights and the shuffling.
    pub seed: u64,
    /// Epochs.
    pub epochs: usize,
    /// Sampling scheme of the dataset.
    pub sampling: Sampling,
    /// Phases of the samples to train and validate on.
    pub phases: Vec<Phase>,
    /// Standard deviation (degrees) of Gaussian noise added to every training label, pitch and
    /// roll alike, before training (the label-noise ablation); 0, the default, adds none.
    /// Validation and test labels are never changed.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub label_noise_deg: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// How a reproduction simulates its datasets: every protocol at one scale and master seed, with
/// `repeats` passes over Experiments 1 and 2's conditions instead of the scale's. One value, so
/// that the simulation, its cost estimate and its Slurm round cannot disagree on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Simulation {
    /// How many trials.
    pub scale: Scale,
    /// Passes over the conditions of Experiments 1 and 2 instead of the scale's, or `None`.
    pub repeats: Option<usize>,
    /// Master seed.
    pub seed: u64,
}

impl Simulation {
    /// The job that simulates `protocol`'s dataset into its folder under `dir` (laid out as
    /// [`crate::pipeline::Datasets::in_dir`] reads them).
    pub fn job(&self, protocol: Protocol, dir: &Path) -> SimulateJob {
        SimulateJob {
            protocol,
            scale: self.scale,
            seed: self.seed,
            out: dir.join(protocol.name()),
            repeats: self.repeats,
        }
    }
}

/// Training one model on a dataset's training split, selected on its validation split (what
/// `evtac train` does).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainJob {
    /// The dataset folder.
    pub dataset: PathBuf,
    /// Whether its calibration and mask are used or opted out of.
    pub inputs: Inputs,
    /// Seed of the train/validation/test split, used when `splits.json` is missing.
    pub splits_seed: u64,
    /// What to train.
    pub spec: TrainSpec,
    /// The model folder to write.
    pub out: PathBuf,
}

/// A reproduction's settings: those of the `evtac reproduce` it stands for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReproduceJob {
    /// How many trials (and which plan).
    pub scale: Scale,
    /// Master seed.
    pub seed: u64,
    /// Output folder.
    pub out: PathBuf,
    /// Existing datasets, or `None`: simulated into `out/data`.
    pub data: Option<PathBuf>,
    /// Where the datasets' calibration and mask come from.
    pub inputs: Inputs,
    /// The noise levels Experiment 1 is repeated at, or `None` for the plan's default.
    pub noise_levels: Option<Vec<f64>>,
    /// Whether the learned fusions are trained beside the paper's three.
    pub fusions: bool,
    /// The label-noise ablation's standard deviation (0: none), or `None` for the plan's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label_noise_deg: Option<f64>,
    /// Simulated datasets Experiment 1 runs on, its own included, or `None` for the plan's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub datasets: Option<usize>,
    /// Passes over the conditions of the simulated Experiments 1 and 2 instead of the scale's,
    /// or `None`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repeats: Option<usize>,
    /// Whether Experiment 1 is trained again with each condition's repeats kept on one side of
    /// the split (when the dataset has repeats). Absent from older jobs files: it was.
    #[serde(default = "yes", skip_serializing_if = "is_yes")]
    pub repeat_split: bool,
    /// The tuning grids (`--grid`), or `None` for the plan's ([`Grid::Extended`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<Grid>,
    /// Whether the best tuning settings are trained again with more seeds
    /// ([`Plan::recheck_top`]; `--no-recheck` leaves it out). Absent: it is.
    #[serde(default = "yes", skip_serializing_if = "is_yes")]
    pub recheck: bool,
    /// The capture-filter ablation's filter instead of the plan's (`--capture-filter`), or
    /// `None` for the plan's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capture_filter: Option<evtac_filters::FilterSpec>,
    /// Whether the capture-filter ablation runs when the plan has one (`--no-capture-filter`
    /// leaves it out). Absent from older jobs files: it does.
    #[serde(default = "yes", skip_serializing_if = "is_yes")]
    pub capture_ablation: bool,
    /// Whether Experiment 1 also compares the representations the paper did not choose
    /// (`--beyond`, [`Plan::beyond`]). Absent from older jobs files: no.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub beyond: bool,
}

impl ReproduceJob {
    /// How the job simulates its datasets when it is given none.
    pub fn simulation(&self) -> Simulation {
        Simulation {
            scale: self.scale,
            repeats: self.repeats,
            seed: self.seed,
        }
    }

    /// The plan the job runs: the scale's, with the job's settings in place of the plan's
    /// defaults. Built from the job itself, so that `evtac reproduce` and a Slurm task that runs
    /// the job mean the same reproduction. Refuses settings no reproduction can run, naming
    /// them by the flags of the `evtac reproduce` the job stands for.
    pub fn plan(&self) -> Result<Plan, PlanError> {
        let mut plan = Plan::for_scale(self.scale);
        if let Some(levels) = &self.noise_levels {
            if let Some(&level) = levels.iter().find(|l| !(l.is_finite() && **l >= 0.0)) {
                return Err(PlanError::NoiseLevel { level });
            }
            plan.noise_levels = levels.clone();
        }
        plan.fusions = self.fusions;
        plan.beyond = self.beyond;
        plan.repeat_split = self.repeat_split;
        if let Some(grid) = self.grid {
            plan = plan.with_grid(grid);
        }
        if !self.recheck {
            (plan.recheck_top, plan.recheck_seeds) = (0, 0);
        }
        if let Some(sd) = self.label_noise_deg {
            if !(sd.is_finite() && sd >= 0.0) {
                return Err(PlanError::LabelNoise { sd });
            }
            plan.label_noise_deg = (sd > 0.0).then_some(sd);
        }
        if let Some(n) = self.datasets {
            plan.datasets = n;
        }
        if let Some(spec) = &self.capture_filter {
            plan.capture_filter = Some(spec.clone());
        }
        if !self.capture_ablation {
            plan.capture_filter = None;
        }
        if self.repeats.is_some() && self.data.is_some() {
            return Err(PlanError::RepeatsOfGivenData);
        }
        Ok(plan)
    }
}

/// Why a [`ReproduceJob`] has no plan: settings no reproduction can run, named by the flags of
/// `evtac reproduce`, where a user gives them.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// A noise level is negative or not finite.
    #[error("--noise-levels: {level} is not a factor (finite and at least 0)")]
    NoiseLevel {
        /// The level.
        level: f64,
    },
    /// The label-noise standard deviation is negative or not finite.
    #[error(
        "--label-noise-deg {sd}: give a standard deviation in degrees, 0 (no ablation) or more"
    )]
    LabelNoise {
        /// The standard deviation given.
        sd: f64,
    },
    /// Repeats were asked of datasets that are given, not simulated.
    #[error(
        "--repeats sets how the datasets are simulated; the --data datasets are already made \
         (simulate them with `evtac simulate --repeats N`)"
    )]
    RepeatsOfGivenData,
}

/// The default of a flag that older jobs files do not carry.
fn yes() -> bool {
    true
}

/// Whether a flag is its default ([`yes`]), so it is left out of the jobs file.
fn is_yes(b: &bool) -> bool {
    *b
}

/// One point of a sensitivity study: Experiment 1, tuning included, on a dataset simulated with
/// one parameter scaled ([`crate::sensitivity::point`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensitivityPointJob {
    /// The study's scale.
    pub scale: Scale,
    /// The study's master seed.
    pub seed: u64,
    /// What the point varies.
    pub parameter: Varied,
    /// The factor on it.
    pub factor: f64,
    /// The point's folder ([`crate::sensitivity::point_dir`]).
    pub out: PathBuf,
    /// Keep the point's dataset and feature cache once it is finished (see
    /// [`crate::sensitivity::point`]).
    #[serde(default)]
    pub keep_data: bool,
}

/// Errors reading or writing a jobs file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FileError {
    /// The file could not be read or written.
    #[error(transparent)]
    Io(#[from] IoError),
    /// The file holds shell command lines, the format before jobs were typed.
    #[error(
        "{path}:{line}: this jobs file holds command lines, the format of an earlier evtac; \
         export the jobs again with this evtac (`evtac reproduce ... --export-jobs FILE`)"
    )]
    CommandLines {
        /// The file.
        path: PathBuf,
        /// The first such line (from 1).
        line: usize,
    },
    /// A line is not a job of this format.
    #[error("{path}:{line}: not a job: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The line (from 1).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A line was written by a newer evtac.
    #[error(
        "{path}:{line}: jobs file format {found}, but this evtac reads format {FORMAT}; run the \
         jobs with the evtac that wrote them, or export them again"
    )]
    Version {
        /// The file.
        path: PathBuf,
        /// The line (from 1).
        line: usize,
        /// The version found.
        found: u32,
    },
}

/// One line of a jobs file.
#[derive(Serialize, Deserialize)]
struct Line<J> {
    format: u32,
    #[serde(flatten)]
    job: J,
}

/// The version of a line, read before its job (so a newer job kind reports the version).
#[derive(Deserialize)]
struct Version {
    format: u32,
}

/// `jobs` as the text of a jobs file.
pub fn to_text(jobs: &[Job]) -> String {
    let mut text = String::new();
    for job in jobs {
        let line = Line {
            format: FORMAT,
            job,
        };
        // A job is plain data (paths, numbers, enums): it always serializes.
        let json =
            serde_json::to_string(&line).unwrap_or_else(|e| unreachable!("a job serializes: {e}"));
        text.push_str(&json);
        text.push('\n');
    }
    text
}

/// Writes `jobs` to the jobs file `path`, whole or not at all.
pub fn write(path: &Path, jobs: &[Job]) -> Result<(), FileError> {
    crate::jobs::create_parent(path)
        .and_then(|()| write_atomic(path, to_text(jobs).as_bytes()))
        .map_err(IoError::at(path))?;
    Ok(())
}

/// The jobs of a jobs file's `text` (blank lines are not jobs), `path` naming it in errors.
pub fn parse(path: &Path, text: &str) -> Result<Vec<Job>, FileError> {
    let mut jobs = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let (line, raw) = (i + 1, raw.trim());
        if raw.is_empty() {
            continue;
        }
        if !raw.starts_with('{') {
            return Err(FileError::CommandLines {
                path: path.to_path_buf(),
                line,
            });
        }
        let invalid = |e: serde_json::Error| FileError::Invalid {
            path: path.to_path_buf(),
            line,
            message: e.to_string(),
        };
        let version: Version = serde_json::from_str(raw).map_err(invalid)?;
        if version.format != FORMAT {
            return Err(FileError::Version {
                path: path.to_path_buf(),
                line,
                found: version.format,
            });
        }
        let parsed: Line<Job> = serde_json::from_str(raw).map_err(invalid)?;
        jobs.push(parsed.job);
    }
    Ok(jobs)
}

/// Reads the jobs file `path`.
pub fn read(path: &Path) -> Result<Vec<Job>, FileError> {
    let text = std::fs::read_to_string(path).map_err(IoError::at(path))?;
    parse(path, &text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_repr::{DynamicConfig, ReprKind, StaticConfig};

    fn jobs() -> Vec<Job> {
        let spec = TrainSpec {
            repr: ReprKind::Late.config(StaticConfig::default(), DynamicConfig::default()),
            seed: 3,
            epochs: 7,
            sampling: Sampling::WITH_STOP,
            phases: vec![Phase::Motion, Phase::Stop],
            label_noise_deg: 0.04,
        };
        vec![
            Job::Simulate(SimulateJob {
                protocol: Protocol::Exp2,
                scale: Scale::Tiny,
                seed: 1,
                out: "data/exp2".into(),
                repeats: Some(2),
            }),
            Job::Train(TrainJob {
                dataset: "data with spaces/exp1".into(),
                inputs: Inputs::from_flags(true, false),
                splits_seed: 1,
                spec,
                out: "out/models/exp1/late/seed3".into(),
            }),
            Job::Reproduce(ReproduceJob {
                scale: Scale::Paper,
                seed: 0,
                out: "out".into(),
                data: None,
                inputs: Inputs::FROM_FILES,
                noise_levels: Some(vec![0.0, 2.5]),
                fusions: false,
                label_noise_deg: Some(0.0),
                datasets: Some(3),
                repeats: Some(2),
                repeat_split: false,
                grid: Some(Grid::Paper),
                recheck: false,
                capture_filter: Some("k-noise=2ms".parse().unwrap()),
                capture_ablation: true,
                beyond: true,
            }),
            Job::SensitivityPoint(SensitivityPointJob {
                scale: Scale::Small,
                seed: 2,
                parameter: Varied::from("cutoff"),
                factor: 0.5,
                out: "study/points/cutoff/x0.5".into(),
                keep_data: true,
            }),
        ]
    }

    #[test]
    fn a_jobs_file_reads_back_the_jobs_it_was_written_from() {
        let jobs = jobs();
        let text = to_text(&jobs);
        assert_eq!(text.lines().count(), jobs.len());
        assert!(
            text.lines().all(|l| l.starts_with("{\"format\":1,")),
            "{text}"
        );
        assert_eq!(parse(Path::new("x.jobs"), &text).expect("reads"), jobs);
        // Blank lines are not jobs.
        let spaced = text.replace('\n', "\n\n");
        assert_eq!(parse(Path::new("x.jobs"), &spaced).expect("reads"), jobs);
    }

    #[test]
    fn older_and_newer_files_and_broken_lines_are_named() {
        let path = Path::new("tuning.jobs");
        let old = "evtac train data/exp1 --repr static --out m --quiet\n";
        let err = parse(path, old).expect_err("command lines");
        assert!(
            err.to_string()
                .starts_with("tuning.jobs:1: this jobs file holds command lines")
                && err.to_string().contains("--export-jobs"),
            "{err}"
        );
        let newer = "{\"format\":2,\"job\":\"teleport\"}\n";
        let err = parse(path, newer).expect_err("newer");
        assert!(err.to_string().contains("format 2"), "{err}");
        let text = to_text(&jobs()).replace("\"splits_seed\":1", "\"splits_seed\":\"one\"");
        let err = parse(path, &text).expect_err("wrong type");
        assert!(
            err.to_string().starts_with("tuning.jobs:2: not a job"),
            "{err}"
        );
    }
}
