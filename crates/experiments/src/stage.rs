//! The stages of a reproduction, and what each is expected to cost.
//!
//! The library reports its progress stage by stage ([`crate::progress::Progress`]); a front end
//! shows a bar per stage and, with [`CostModel`], an overall bar whose ETA covers the whole run.
//! The costs are reference figures from the 2-core development machine: they only weigh the
//! stages against each other, so the ETA follows the actual machine's pace.

use crate::job::Simulation;
use crate::plan::{Kind, Plan};
use crate::splits::Stratum;
use evtac_events::manifest::Manifest;
use evtac_repr::ReprKind;
use evtac_sim::Protocol;
use std::path::Path;

/// A timed stage of a reproduction: a row of `stage-times.csv` and of the report's table of
/// stage times. Its own type beside [`Stage`] (the progress bars' finer stages), so that the
/// pipeline, the command that simulates and writes the report, and the log name a stage the
/// same way; the files keep its [`Timed::name`], and read back whatever names they hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Timed {
    /// Simulating the datasets.
    Simulation,
    /// Tuning static.
    TuningStatic,
    /// Tuning dynamic.
    TuningDynamic,
    /// Tuning the representations the paper did not choose ([`crate::plan::Plan::beyond`]).
    TuningBeyond,
    /// Experiment 1.
    Exp1,
    /// Experiment 1 at other background noise.
    Exp1OtherNoise,
    /// Experiment 1 on datasets simulated with other seeds.
    Exp1OtherDatasets,
    /// Experiment 1 with each condition's repeats kept on one side of the split.
    RepeatsTogether,
    /// Experiment 1 trained on noisy labels.
    LabelNoise,
    /// Experiment 1 on events through the lab's capture filter.
    CaptureFilter,
    /// Experiment 2.
    Exp2,
    /// Experiment 3.
    Exp3,
    /// The latency study.
    Latency,
    /// Writing the report.
    Report,
}

impl Timed {
    /// The stage's name, as `stage-times.csv` and the report write it.
    pub fn name(self) -> &'static str {
        match self {
            Timed::Simulation => "simulation",
            Timed::TuningStatic => "tuning (static)",
            Timed::TuningDynamic => "tuning (dynamic)",
            Timed::TuningBeyond => "tuning (beyond the paper)",
            Timed::Exp1 => "experiment 1",
            Timed::Exp1OtherNoise => "experiment 1 at other noise",
            Timed::Exp1OtherDatasets => "experiment 1 on other datasets",
            Timed::RepeatsTogether => "repeats kept together",
            Timed::LabelNoise => "label-noise ablation",
            Timed::CaptureFilter => "capture-filter ablation",
            Timed::Exp2 => "experiment 2",
            Timed::Exp3 => "experiment 3",
            Timed::Latency => "latency",
            Timed::Report => "report",
        }
    }
}

impl std::fmt::Display for Timed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The simulated protocols of a reproduction, in the order they are simulated.
pub const PROTOCOLS: [Protocol; 4] = [
    Protocol::Exp1,
    Protocol::Exp2,
    Protocol::Exp3Speed,
    Protocol::Exp3Depth,
];

/// The datasets features are computed for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeatureSet {
    /// Experiment 1's train and validation trials, for tuning one representation.
    Tuning(Kind),
    /// Experiment 1.
    Exp1,
    /// Experiment 2.
    Exp2,
    /// Experiment 3's speed levels.
    Exp3Speed,
    /// Experiment 3's depth levels.
    Exp3Depth,
    /// Experiment 1 at a scaled background noise.
    Noise,
    /// Experiment 1 on a dataset simulated with another seed.
    DatasetSeed,
    /// Experiment 1 on events through the lab's capture filter.
    CaptureFilter,
}

/// One stage of a reproduction; its units of work are given with it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Simulating a protocol's dataset (units: trials).
    Simulating(Protocol),
    /// Computing and caching features (units: trials).
    Features(FeatureSet),
    /// Training one run per grid point of a representation (units: runs).
    Tuning(Kind),
    /// Experiment 1's training runs (units: runs).
    Exp1Training,
    /// Experiment 2's training runs (units: runs).
    Exp2Training,
    /// The latency study (units: representation x interval).
    Latency,
    /// Tasks of a Slurm job array, run by the cluster (units: tasks).
    SlurmTasks,
    /// Simulating Experiment 1's dataset at a scaled background noise (units: trials).
    NoiseSimulating,
    /// Experiment 1's training runs at a scaled background noise (units: runs).
    NoiseTraining,
    /// The label-noise ablation's training runs (units: runs).
    LabelNoiseTraining,
    /// Simulating Experiment 1's dataset with another seed (units: trials).
    DatasetSeedSimulating,
    /// Experiment 1's training runs on a dataset simulated with another seed (units: runs).
    DatasetSeedTraining,
    /// Experiment 1's paper representations on the split that keeps each condition's repeats
    /// on one side (units: runs).
    RepeatSplitTraining,
    /// Experiment 1's paper representations on events through the capture filter (units: runs).
    CaptureFilterTraining,
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stage::Simulating(p) => write!(f, "simulating {p}"),
            Stage::Features(FeatureSet::Tuning(k)) => write!(f, "features ({} tuning)", k.name()),
            Stage::Features(FeatureSet::Exp1) => f.write_str("features (experiment 1)"),
            Stage::Features(FeatureSet::Exp2) => f.write_str("features (experiment 2)"),
            Stage::Features(FeatureSet::Exp3Speed) => f.write_str("features (experiment 3, speed)"),
            Stage::Features(FeatureSet::Exp3Depth) => f.write_str("features (experiment 3, depth)"),
            Stage::Tuning(k) => write!(f, "tuning {}", k.name()),
            Stage::Exp1Training => f.write_str("experiment 1 training"),
            Stage::Exp2Training => f.write_str("experiment 2 training"),
            Stage::Features(FeatureSet::Noise) => f.write_str("features (noise)"),
            Stage::Latency => f.write_str("latency"),
            Stage::SlurmTasks => f.write_str("Slurm tasks"),
            Stage::NoiseSimulating => f.write_str("simulating exp1 at other noise"),
            Stage::NoiseTraining => f.write_str("noise training"),
            Stage::LabelNoiseTraining => f.write_str("label-noise training"),
            Stage::Features(FeatureSet::DatasetSeed) => f.write_str("features (other datasets)"),
            Stage::DatasetSeedSimulating => f.write_str("simulating exp1 with other seeds"),
            Stage::DatasetSeedTraining => f.write_str("other datasets' training"),
            Stage::RepeatSplitTraining => f.write_str("repeats-together training"),
            Stage::Features(FeatureSet::CaptureFilter) => f.write_str("features (capture filter)"),
            Stage::CaptureFilterTraining => f.write_str("capture-filter training"),
        }
    }
}

/// Reference costs in seconds on the 2-core development machine, measured in `evtac reproduce
/// --scale small` (7.7 min).
mod cost {
    /// Simulating one trial (52 s for 448 trials).
    pub const SIMULATE_TRIAL: f64 = 0.116;
    /// Features of one trial for every configuration of one pass.
    pub const FEATURES_TRIAL: f64 = 0.03;
    /// One training epoch of one run: a fixed part (validation, the checkpoint, the epoch's
    /// shuffle and batching) and a part per training trial (its 50 samples). Fitted to two
    /// measurements on 2 cores running two runs side by side: the small scale (88 training
    /// trials, 0.06 s per epoch per run and core) and the paper's (700 trials, 0.10-0.16 s,
    /// `docs/performance.md`). One figure per trial alone, fitted to the small scale, made the
    /// paper scale's training 3-4 times too expensive and its ETA hours too long.
    pub const EPOCH_FIXED: f64 = 0.05;
    /// See [`EPOCH_FIXED`].
    pub const EPOCH_TRAIN_TRIAL: f64 = 0.000115;
    /// One latency measurement (representation x interval) per test trial.
    pub const LATENCY_TRIAL: f64 = 0.033;
    /// Share of a dataset's trials in its training split.
    pub const TRAIN_SHARE: f64 = 0.7;
    /// Share of Experiment 1's trials that tuning computes features for (train + validation).
    pub const TUNING_SHARE: f64 = 0.85;
}

/// Trial counts of the datasets a reproduction runs on.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TrialCounts {
    /// Experiment 1's trials.
    pub exp1: usize,
    /// Experiment 2's trials (0 when there is no Experiment 2 dataset).
    pub exp2: usize,
    /// Experiment 3's trials, both axes.
    pub exp3: usize,
    /// Trials still to simulate.
    pub simulate: usize,
    /// Whether some condition of Experiment 1 has two or more trials (then the report measures
    /// the grouped split, `crate::repeat_split`).
    pub exp1_repeated: bool,
}

impl TrialCounts {
    /// The counts of the datasets in `data` (their manifests; a missing one counts 0).
    pub fn of_datasets(data: &Path) -> Self {
        let mut counts = Self::count(|protocol| {
            let n = Manifest::read(data.join(protocol.name())).map_or(0, |m| m.trials.len());
            (n, 0)
        });
        counts.exp1_repeated = Manifest::read(data.join(Protocol::Exp1.name()))
            .is_ok_and(|m| Stratum::most_repeats(&Stratum::of_manifest(&m)) >= 2);
        counts
    }

    /// The counts of the datasets [`crate::pipeline::simulate_all`] writes into `dir` (the
    /// simulation plans; datasets already simulated there count as done).
    pub fn of_simulation(dir: &Path, simulation: &Simulation) -> Self {
        let exp1_repeated = simulation
            .repeats
            .unwrap_or(simulation.scale.design().repeats)
            >= 2;
        let counts = Self::count(|protocol| {
            let job = simulation.job(protocol, dir);
            let n = job.trials();
            let done = crate::jobs::is_done(&job.out);
            (n, if done { 0 } else { n })
        });
        Self {
            exp1_repeated,
            ..counts
        }
    }

    fn count(mut trials: impl FnMut(Protocol) -> (usize, usize)) -> Self {
        let mut counts = Self::default();
        for protocol in PROTOCOLS {
            let (n, to_simulate) = trials(protocol);
            counts.simulate += to_simulate;
            match protocol {
                Protocol::Exp1 => counts.exp1 = n,
                Protocol::Exp2 => counts.exp2 = n,
                _ => counts.exp3 += n,
            }
        }
        counts
    }
}

/// Expected seconds of each stage of one reproduction.
#[derive(Debug, Clone)]
pub struct CostModel {
    plan: Plan,
    counts: TrialCounts,
}

impl CostModel {
    /// The model of a reproduction running `plan` on datasets of `counts` trials.
    pub fn new(plan: &Plan, counts: TrialCounts) -> Self {
        Self {
            plan: plan.clone(),
            counts,
        }
    }

    /// Expected seconds of `stage` when it starts with `units` units of work.
    pub fn seconds(&self, stage: Stage, units: u64) -> f64 {
        let (plan, counts) = (&self.plan, &self.counts);
        let units = units as f64;
        let train =
            |n: usize| cost::EPOCH_FIXED + n as f64 * cost::TRAIN_SHARE * cost::EPOCH_TRAIN_TRIAL;
        match stage {
            Stage::Simulating(_) | Stage::NoiseSimulating | Stage::DatasetSeedSimulating => {
                units * cost::SIMULATE_TRIAL
            }
            Stage::Features(_) => units * cost::FEATURES_TRIAL,
            Stage::Tuning(_) => units * plan.tuning_epochs as f64 * train(counts.exp1),
            Stage::Exp1Training
            | Stage::NoiseTraining
            | Stage::LabelNoiseTraining
            | Stage::DatasetSeedTraining
            | Stage::RepeatSplitTraining
            | Stage::CaptureFilterTraining => units * plan.epochs as f64 * train(counts.exp1),
            Stage::Exp2Training => units * plan.epochs as f64 * train(counts.exp2),
            Stage::Latency => {
                let trials = plan.latency_trials.min(counts.exp1.div_ceil(6).max(1));
                units * trials as f64 * cost::LATENCY_TRIAL
            }
            // The cluster's pace is its own: the local ETA does not cover it.
            Stage::SlurmTasks => 0.0,
        }
    }

    /// Expected seconds of the whole reproduction: every stage it will report.
    ///
    /// The latency stage's end-to-end replay runs on the wall clock, as long as the events it
    /// replays (`crate::paced_extent::extent`).
    pub fn total_seconds(&self) -> f64 {
        let (plan, counts) = (&self.plan, &self.counts);
        let reprs = plan.representations();
        // Experiment 1 (and the studies on its models: latency, other datasets) also trains the
        // kinds beyond the paper when the plan compares them.
        let exp1_reprs = plan.exp1_representations();
        let beyond_grid: usize = plan
            .beyond_kinds()
            .iter()
            .map(|&kind| plan.dense_grids.points(kind).len())
            .sum();
        let c = |stage: Stage, units: usize| self.seconds(stage, units as u64);
        let tuning_trials = (counts.exp1 as f64 * cost::TUNING_SHARE).round() as usize;
        let mut sum = c(Stage::Simulating(Protocol::Exp1), counts.simulate)
            + c(
                Stage::Features(FeatureSet::Exp1),
                (2 + plan.beyond_kinds().len()) * tuning_trials
                    + counts.exp1
                    + counts.exp2
                    + counts.exp3,
            )
            + c(
                Stage::Tuning(Kind::Static),
                plan.static_grid().len()
                    + plan.dynamic_grid().len()
                    + beyond_grid
                    + (2 + plan.beyond_kinds().len())
                        * plan.recheck_top
                        * plan.recheck_seeds.saturating_sub(1),
            )
            + c(Stage::Exp1Training, exp1_reprs * plan.seeds)
            + c(Stage::Latency, exp1_reprs * plan.latency_intervals_ms.len())
            + paced_replay_seconds(plan, exp1_reprs);
        if counts.exp2 > 0 {
            sum += c(
                Stage::Exp2Training,
                crate::results::Exp2Setting::ALL.len() * reprs * plan.exp2_seeds,
            );
        }
        // Every noise level but Experiment 1's own: a dataset, its features and the runs.
        let levels = plan.simulated_noise_levels().len();
        sum += levels as f64
            * (c(Stage::NoiseSimulating, counts.exp1)
                + c(Stage::Features(FeatureSet::Noise), counts.exp1)
                + c(Stage::NoiseTraining, reprs * plan.seeds));
        // Every dataset but Experiment 1's own: the same, with another simulation seed.
        let others = plan.datasets.saturating_sub(1);
        sum += others as f64
            * (c(Stage::DatasetSeedSimulating, counts.exp1)
                + c(Stage::Features(FeatureSet::DatasetSeed), counts.exp1)
                + c(Stage::DatasetSeedTraining, exp1_reprs * plan.seeds));
        if counts.exp1_repeated && plan.repeat_split {
            sum += c(
                Stage::RepeatSplitTraining,
                ReprKind::PAPER.len() * plan.seeds,
            );
        }
        if plan.label_noise_deg.is_some_and(|sd| sd > 0.0) {
            sum += c(
                Stage::LabelNoiseTraining,
                ReprKind::PAPER.len() * plan.seeds,
            );
        }
        if plan.capture_filter.is_some() {
            sum += c(Stage::Features(FeatureSet::CaptureFilter), counts.exp1)
                + c(
                    Stage::CaptureFilterTraining,
                    ReprKind::PAPER.len() * plan.seeds,
                );
        }
        sum
    }
}

/// Wall time of the latency stage's replay at recorded pace (`crate::paced_latency`): it runs
/// as long as the events it replays, whatever the machine.
fn paced_replay_seconds(plan: &Plan, reprs: usize) -> f64 {
    let extent = crate::paced_extent::extent(plan.scale);
    let cells = reprs * crate::paced_extent::INTERVALS_MS.len() * crate::results::Load::ALL.len();
    cells as f64 * extent.trials as f64 * extent.motion_ms as f64 / 1000.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_sim::Scale;

    #[test]
    fn stage_names_read_as_the_bars_show_them() {
        assert_eq!(
            Stage::Simulating(Protocol::Exp3Speed).to_string(),
            format!("simulating {}", Protocol::Exp3Speed)
        );
        assert_eq!(
            Stage::Features(FeatureSet::Tuning(Kind::Dynamic)).to_string(),
            "features (dynamic tuning)"
        );
        assert_eq!(Stage::Tuning(Kind::Static).to_string(), "tuning static");
    }

    #[test]
    fn the_total_is_the_sum_of_the_stages_a_run_reports() {
        let plan = Plan::for_scale(Scale::Tiny);
        let counts = TrialCounts {
            exp1: 60,
            exp2: 0,
            exp3: 20,
            simulate: 80,
            exp1_repeated: false,
        };
        let model = CostModel::new(&plan, counts);
        let reprs = plan.representations();
        let training = model.seconds(Stage::Exp1Training, (reprs * plan.seeds) as u64);
        assert!(training > 0.0);
        let with_exp2 = CostModel::new(&plan, TrialCounts { exp2: 30, ..counts });
        // Repeats in Experiment 1: the paper's three trained again on the grouped split.
        let repeated = CostModel::new(
            &plan,
            TrialCounts {
                exp1_repeated: true,
                ..counts
            },
        );
        let grouped = model.seconds(Stage::RepeatSplitTraining, (3 * plan.seeds) as u64);
        assert!((repeated.total_seconds() - model.total_seconds() - grouped).abs() < 1e-9);
        // ... unless the plan leaves the study out (`--no-repeat-split`).
        let unsplit = Plan {
            repeat_split: false,
            ..plan.clone()
        };
        let left_out = CostModel::new(
            &unsplit,
            TrialCounts {
                exp1_repeated: true,
                ..counts
            },
        );
        assert!((left_out.total_seconds() - model.total_seconds()).abs() < 1e-9);
        assert!(with_exp2.total_seconds() > model.total_seconds());
        assert_eq!(model.seconds(Stage::Exp2Training, 0), 0.0);
        let quiet = Plan {
            noise_levels: vec![1.0],
            ..plan.clone()
        };
        let without_noise = CostModel::new(&quiet, counts).total_seconds();
        let noise = model.total_seconds() - without_noise;
        let per_level = model.seconds(Stage::NoiseSimulating, 60)
            + model.seconds(Stage::Features(FeatureSet::Noise), 60)
            + model.seconds(Stage::NoiseTraining, (reprs * plan.seeds) as u64);
        assert!(
            (noise - 2.0 * per_level).abs() < 1e-9,
            "{noise} vs 2 x {per_level}"
        );
        // One dataset instead of the tiny plan's two: one simulation, its features and runs.
        let one = Plan {
            datasets: 1,
            ..plan.clone()
        };
        let per_dataset = model.seconds(Stage::DatasetSeedSimulating, 60)
            + model.seconds(Stage::Features(FeatureSet::DatasetSeed), 60)
            + model.seconds(Stage::DatasetSeedTraining, (reprs * plan.seeds) as u64);
        let dropped = model.total_seconds() - CostModel::new(&one, counts).total_seconds();
        assert_eq!(plan.datasets, 2);
        assert!(
            (dropped - per_dataset).abs() < 1e-9,
            "{dropped} vs {per_dataset}"
        );
        // Without the learned fusions: three representations' runs instead of five.
        let paper_only = Plan {
            fusions: false,
            ..plan.clone()
        };
        assert_eq!(
            (plan.representations(), paper_only.representations()),
            (5, 3)
        );
        let fewer = CostModel::new(&paper_only, counts).total_seconds();
        let per_repr = model.seconds(Stage::Exp1Training, plan.seeds as u64)
            + model.seconds(Stage::Latency, plan.latency_intervals_ms.len() as u64)
            + paced_replay_seconds(&plan, 1)
            + 2.0 * model.seconds(Stage::NoiseTraining, plan.seeds as u64)
            + (plan.datasets - 1) as f64
                * model.seconds(Stage::DatasetSeedTraining, plan.seeds as u64);
        let saved = model.total_seconds() - fewer;
        assert!(
            (saved - 2.0 * per_repr).abs() < 1e-6,
            "{saved} vs 2 x {per_repr}"
        );
    }
}
