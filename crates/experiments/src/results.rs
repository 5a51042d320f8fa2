//! The numbers a reproduction produces, as one serde tree written to `OUT/results.json` and read
//! by the report and the figures, and those of the sensitivity study ([`Study`], its
//! `sensitivity.json`).
//!
//! Plain typed data at the bottom of the crate: this file imports nothing from the experiments
//! that fill it (only the [`Plan`] they ran, itself plain data), so the report reads it without
//! knowing how it was made. Representations are [`ReprKind`]s, written as their report names
//! (`"Static"`) as `results.json` always spelled them; older files still read.

use evtac_repr::{ReprConfig, ReprKind};
pub use evtac_sim::{Protocol, Scale};
use serde::{Deserialize, Serialize};

use crate::plan::Plan;

/// Mean absolute errors in degrees: overall (mean of pitch and roll), pitch and roll.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Mae {
    /// Mean of the pitch and roll MAE.
    pub overall: f64,
    /// Pitch MAE.
    pub pitch: f64,
    /// Roll MAE.
    pub roll: f64,
}

impl Mae {
    /// MAE of `pred` against `labels`, both rows of (pitch, roll); zeros when empty.
    pub fn of(pred: &[[f32; 2]], labels: &[[f32; 2]]) -> Mae {
        let n = pred.len().min(labels.len());
        if n == 0 {
            return Mae::default();
        }
        let (mut p, mut r) = (0.0f64, 0.0f64);
        for (a, b) in pred.iter().zip(labels) {
            p += (f64::from(a[0]) - f64::from(b[0])).abs();
            r += (f64::from(a[1]) - f64::from(b[1])).abs();
        }
        let (p, r) = (p / n as f64, r / n as f64);
        Mae {
            overall: (p + r) / 2.0,
            pitch: p,
            roll: r,
        }
    }
}

/// Mean and sample standard deviation over repeated runs.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MeanStd {
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation (n - 1; 0 for a single run).
    pub std: f64,
    /// Number of runs.
    pub n: usize,
}

impl MeanStd {
    /// Mean and sample standard deviation of `values`.
    pub fn of(values: &[f64]) -> MeanStd {
        let n = values.len();
        if n == 0 {
            return MeanStd::default();
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let var = if n > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64
        } else {
            0.0
        };
        MeanStd {
            mean,
            std: var.sqrt(),
            n,
        }
    }

    /// `0.160 ± 0.004`.
    pub fn display(&self) -> String {
        format!("{:.3} ± {:.3}", self.mean, self.std)
    }
}

/// [`MeanStd`] of the overall, pitch and roll MAE over runs.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MaeStats {
    /// Overall MAE.
    pub overall: MeanStd,
    /// Pitch MAE.
    pub pitch: MeanStd,
    /// Roll MAE.
    pub roll: MeanStd,
}

impl MaeStats {
    /// Statistics over `runs`.
    pub fn of(runs: &[Mae]) -> MaeStats {
        let col = |f: fn(&Mae) -> f64| MeanStd::of(&runs.iter().map(f).collect::<Vec<_>>());
        MaeStats {
            overall: col(|m| m.overall),
            pitch: col(|m| m.pitch),
            roll: col(|m| m.roll),
        }
    }
}

/// One training run of the grid search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TuningRun {
    /// Decay tau (static) or window (dynamic) in ms.
    pub time_ms: f64,
    /// Binarization threshold (event contributions or counts).
    pub threshold: f64,
    /// Best validation MAE of the run.
    pub val: Mae,
}

/// The grid search of one representation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tuning {
    /// `static` or `dynamic` (written as the CLI spells it).
    #[serde(with = "evtac_repr::kind_name")]
    pub repr: ReprKind,
    /// Name of the time parameter (`tau_ms` or `window_ms`).
    pub time_name: String,
    /// Every run of the grid.
    pub runs: Vec<TuningRun>,
    /// The chosen time parameter (lowest validation MAE).
    pub chosen_time_ms: f64,
    /// The chosen threshold.
    pub chosen_threshold: f64,
    /// The representation config chosen.
    pub chosen_config: ReprConfig,
    /// The time parameter fixed along the threshold curve of the figure.
    pub curve_time_ms: f64,
    /// The threshold fixed along the time curve of the figure.
    pub curve_threshold: f64,
    /// The best settings of the grid trained again with more seeds (`crate::tuning`), best
    /// first; empty when the plan has no recheck, and in older results.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub recheck: Vec<Recheck>,
}

/// One of a tuning's best settings trained with several seeds: whether its rank holds beyond
/// the seeds' spread.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recheck {
    /// Tau or window, ms.
    pub time_ms: f64,
    /// Threshold.
    pub threshold: f64,
    /// The seeds (the grid's own run is the first).
    pub seeds: Vec<u64>,
    /// Best validation MAE per seed.
    pub val_runs: Vec<Mae>,
    /// Statistics over the seeds.
    pub val: MaeStats,
}

/// Experiment 1 for one representation: ten seeds with the chosen settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Exp1Repr {
    /// The representation.
    pub name: ReprKind,
    /// The representation config.
    pub config: ReprConfig,
    /// Seeds trained.
    pub seeds: Vec<u64>,
    /// Test MAE per seed.
    pub runs: Vec<Mae>,
    /// Best validation MAE per seed.
    pub val_runs: Vec<Mae>,
    /// Test MAE statistics over seeds.
    pub test: MaeStats,
    /// Test MAE per seed against the simulator's exact truth instead of the labels
    /// (`crate::truth`); empty on recordings, which have none, and in older results.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub truth_runs: Vec<Mae>,
    /// Statistics of [`Exp1Repr::truth_runs`], where measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub test_truth: Option<MaeStats>,
    /// The test labels' own MAE against the truth on the same samples: how far the labels the
    /// models are scored on are from the pose, where measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub labels_truth: Option<Mae>,
}

/// The label-noise ablation: Experiment 1's paper representations trained with noisy labels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabelNoise {
    /// Standard deviation of the noise added to each training label, degrees.
    pub sd_deg: f64,
    /// Experiment 1's results for the same representations (clean labels).
    pub clean: Vec<Exp1Repr>,
    /// The same representations, settings and seeds trained on the noisy labels, tested on
    /// the clean test labels.
    pub noisy: Vec<Exp1Repr>,
}

/// The capture-filter ablation: Experiment 1's paper representations on events through the
/// lab's capture filter (`crate::capture_filter`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaptureFilter {
    /// The filter, as its SPEC (`background-activity=10ms`).
    pub spec: String,
    /// Experiment 1's results for the same representations (unfiltered events).
    pub unfiltered: Vec<Exp1Repr>,
    /// The same representations, settings and seeds trained and tested on the filtered events.
    pub filtered: Vec<Exp1Repr>,
}

/// Experiment 1 at one background-noise level, for one representation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoisePoint {
    /// The factor on the simulator's leak, shot and hot-pixel noise (1: Experiment 1 itself).
    pub level: f64,
    /// The representation.
    pub name: ReprKind,
    /// Events per second in the 240x240 crop of the dataset's no-contact recording: the
    /// background activity at this level.
    pub no_contact_events_per_s: f64,
    /// Test MAE per seed.
    pub runs: Vec<Mae>,
    /// Test MAE statistics over seeds.
    pub test: MaeStats,
    /// Test MAE statistics against the simulator's exact truth, where measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub test_truth: Option<MaeStats>,
}

/// Experiment 2's training settings, in the report's order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Exp2Setting {
    /// Experiment 1's models: trained on the continuous-motion dataset.
    ContinuousOnly,
    /// Trained on the pause dataset's motion samples.
    PauseMotion,
    /// Trained on the pause dataset's motion and stop samples.
    PauseMotionStop,
}

impl Exp2Setting {
    /// Every setting, in the report's order.
    pub const ALL: [Self; 3] = [
        Self::ContinuousOnly,
        Self::PauseMotion,
        Self::PauseMotionStop,
    ];

    /// The name in `results.json` and in model folders: `continuous-only`, `pause-motion`,
    /// `pause-motion-stop`.
    pub fn key(self) -> &'static str {
        match self {
            Self::ContinuousOnly => "continuous-only",
            Self::PauseMotion => "pause-motion",
            Self::PauseMotionStop => "pause-motion-stop",
        }
    }

    /// The label in the report's table and figure.
    pub fn label(self) -> &'static str {
        match self {
            Self::ContinuousOnly => "Continuous-only",
            Self::PauseMotion => "Pause-inclusive (motion only)",
            Self::PauseMotionStop => "Pause-inclusive (motion + stop)",
        }
    }
}

/// Experiment 2 for one (training setting, representation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Exp2Cell {
    /// The training setting.
    pub setting: Exp2Setting,
    /// The representation.
    pub name: ReprKind,
    /// Motion-phase test MAE per seed.
    pub motion_runs: Vec<Mae>,
    /// Stop-phase test MAE per seed.
    pub stop_runs: Vec<Mae>,
    /// Motion-phase statistics.
    pub motion: MaeStats,
    /// Stop-phase statistics.
    pub stop: MaeStats,
    /// Motion-phase statistics against the simulator's exact truth, where measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion_truth: Option<MaeStats>,
    /// Stop-phase statistics against the simulator's exact truth, where measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_truth: Option<MaeStats>,
}

/// Experiment 3: one condition value (a speed or a depth) for one representation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Exp3Point {
    /// The representation.
    pub name: ReprKind,
    /// Speed in deg/s or depth in mm.
    pub value: f64,
    /// Whether the value was in the training set (`seen`) or interpolated (`unseen`).
    pub seen: bool,
    /// Number of trials at this value.
    pub trials: usize,
    /// MAE per Experiment 1 model (seed).
    pub runs: Vec<Mae>,
    /// Statistics over the models.
    pub stats: MaeStats,
    /// Statistics over the models against the simulator's exact truth, where measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth: Option<MaeStats>,
}

/// What else runs on the machine during a replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Load {
    /// Nothing started by the measurement (the machine as it is).
    Idle,
    /// One extra thread spinning on floating-point multiplies and adds for the whole replay.
    BusyThread,
}

impl Load {
    /// Both, in the report's order.
    pub const ALL: [Load; 2] = [Load::Idle, Load::BusyThread];

    /// A short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Load::Idle => "idle",
            Load::BusyThread => "one busy thread",
        }
    }
}

/// End-to-end latency of one (representation, interval, load), queueing included.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PacedLatencyCell {
    /// The representation.
    pub name: ReprKind,
    /// Interval between estimates (and length of each released slice), ms.
    pub interval_ms: u32,
    /// What else ran.
    pub load: Load,
    /// Trials replayed.
    pub trials: usize,
    /// Event time replayed, summed over the trials, in seconds (as long on the wall clock).
    pub replayed_s: f64,
    /// Logical cores of the machine (`std::thread::available_parallelism`), 0 if unknown.
    pub cores: usize,
    /// Estimates measured.
    pub samples: usize,
    /// Median end-to-end time in microseconds (nearest rank, as `crate::latency::cell`).
    pub median_us: f64,
    /// 99th percentile in microseconds.
    pub p99_us: f64,
    /// Maximum in microseconds.
    pub max_us: f64,
    /// Share of estimates whose end-to-end time exceeded the interval, 0 to 1.
    pub late_share: f64,
}

/// Latency of one (representation, sampling interval).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LatencyCell {
    /// The representation.
    pub name: ReprKind,
    /// Sampling interval in ms.
    pub interval_ms: u32,
    /// Number of measured samples.
    pub samples: usize,
    /// Median processing time per estimate in microseconds (events in to estimate out).
    pub median_us: f64,
    /// 99th percentile in microseconds.
    pub p99_us: f64,
    /// Maximum in microseconds.
    pub max_us: f64,
    /// Samples above the sampling interval.
    pub over_interval: usize,
    /// Samples above the paper's 10 ms bound.
    pub over_10ms: usize,
    /// The measured times in microseconds (kept for the figure).
    pub times_us: Vec<f64>,
}

/// Where the reproduction's settings came from and how long it took.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// The scale (the plan's).
    pub scale: Scale,
    /// Master seed.
    pub seed: u64,
    /// The plan (grids, epochs, seeds) as run.
    pub plan: Plan,
    /// Wall time per stage in seconds, in order: this invocation's.
    pub stage_seconds: Vec<(String, f64)>,
    /// Every invocation's stages that worked on this output folder, the simulation included
    /// (`stage-times.csv`; absent in results written before it was kept).
    #[serde(default)]
    pub stage_history: Vec<StageRecord>,
    /// Trials per dataset, by the protocol it was made with (its folder's name).
    pub datasets: Vec<(Protocol, usize)>,
    /// Where every dataset's calibration and mask came from (absent in results written before
    /// this was recorded).
    #[serde(default)]
    pub inputs: Option<evtac_import::inputs::Inputs>,
}

/// Example curves of one pause trial (Experiment 2's figure).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ExampleTrial {
    /// Trial name.
    pub trial: String,
    /// Stop interval in seconds from motion onset, if any.
    pub stop_s: Option<(f64, f64)>,
    /// Sample times in seconds from motion onset.
    pub t_s: Vec<f64>,
    /// Ground-truth (pitch, roll) at the sample times.
    pub truth: Vec<[f32; 2]>,
    /// Predictions per representation.
    pub predictions: Vec<(ReprKind, Vec<[f32; 2]>)>,
}

/// Binary frames for the contour overlays: two conditions per panel.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Overlay {
    /// Panel title.
    pub title: String,
    /// Label of the first condition (red).
    pub first_label: String,
    /// Label of the second condition (orange).
    pub second_label: String,
    /// Frame width in pixels.
    pub width: usize,
    /// Frame height in pixels.
    pub height: usize,
    /// First binary frame (row-major, non-zero = set).
    pub first: Vec<u8>,
    /// Second binary frame.
    pub second: Vec<u8>,
}

/// The paper's Fig. 2 for one test sample.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ReprExample {
    /// Trial name.
    pub trial: String,
    /// The sample's time from motion onset, in ms.
    pub t_ms: f64,
    /// The dynamic window the event counts cover, `(t - window, t]`, in ms.
    pub window_ms: f64,
    /// Crop width in pixels.
    pub width: usize,
    /// Crop height in pixels.
    pub height: usize,
    /// ON events per pixel in the window (row-major).
    pub on: Vec<u32>,
    /// OFF events per pixel in the window.
    pub off: Vec<u32>,
    /// Static, dynamic and combined: frame and pooled features.
    pub panels: Vec<ReprPanel>,
}

/// One representation of [`ReprExample`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReprPanel {
    /// The representation.
    pub name: ReprKind,
    /// The binary frame (0/1, `width x height`, row-major).
    pub frame: Vec<u8>,
    /// The pooled features (`width / 8 x height / 8`, row-major, each the fraction of set
    /// pixels in its 8x8 cell).
    pub features: Vec<f32>,
}

/// What the sensor figure's images are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum SensorKind {
    /// The simulator's camera brightness (gamma 0.5).
    Simulated,
    /// Event counts per pixel of recordings (log-scaled): a real dataset has no frames.
    EventCounts,
}

/// The sensor figure's data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorView {
    /// What the images are.
    pub kind: SensorKind,
    /// The full sensor's size.
    pub resolution: evtac_events::Resolution,
    /// The images, in order (at rest first).
    pub panels: Vec<SensorPanel>,
}

/// One image of [`SensorView`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SensorPanel {
    /// Panel title.
    pub title: String,
    /// Display intensity per pixel in 0..=1 (row-major, full sensor).
    pub values: Vec<f32>,
}

/// One finished stage of one invocation (a row of `stage-times.csv`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageRecord {
    /// The invocation, numbered from 1 in the order they ran.
    pub invocation: u32,
    /// The stage's name as the report prints it.
    pub stage: String,
    /// Its wall time in seconds.
    pub seconds: f64,
}

/// One value evtac chose where the paper states none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Choice {
    /// What was chosen (also the row's key in tests).
    pub what: String,
    /// The value the run used.
    pub value: String,
    /// Why this value.
    pub why: String,
    /// The flag or file that changes it.
    pub change: String,
}

/// The label check over one dataset: Experiment 2's labels against the commanded stop angles
/// and the ground truth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LabelCheck {
    /// Mean labelled tilt over each stop minus the commanded stop angle, degrees (trials with
    /// a stop).
    pub stop_error_deg: Option<evtac_labels::Summary>,
    /// Per-trial RMS error of the labels against the ground truth over pitch and roll, degrees
    /// (trials with a truth file).
    pub truth_rms_deg: Option<evtac_labels::Summary>,
    /// Where the labels came from: the IMU, or the commanded motion (then no stop check: it
    /// would compare the command with itself). Absent from results written before the choice
    /// existed, which were all the IMU's.
    #[serde(default)]
    pub label_source: evtac_labels::LabelSource,
    /// Per-trial RMS error of the labels against the ground truth over each stop (trials with a
    /// stop and a truth file), degrees: the labels' own error where the paper checks them,
    /// without the robot's repeatability the stop check includes. Absent from older results.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth_stop_rms_deg: Option<evtac_labels::Summary>,
}

/// Experiment 1's paper representations on a split that keeps each condition's repeats on one
/// side, beside the paper's split ([`crate::repeat_split`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RepeatSplit {
    /// The most trials one condition has in Experiment 1's dataset.
    pub repeats: usize,
    /// Experiment 1's results (the paper's split: repeats may fall on both sides).
    pub paper_split: Vec<Exp1Repr>,
    /// The same representations, settings and seeds on the grouped split.
    pub together: Vec<Exp1Repr>,
}

/// Experiment 1 on one simulated dataset of the spread across datasets, for one
/// representation ([`crate::dataset_seeds`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetSeedPoint {
    /// The seed the dataset was simulated with (the first: Experiment 1's own).
    pub dataset_seed: u64,
    /// The representation.
    pub name: ReprKind,
    /// Test MAE per training seed.
    pub runs: Vec<Mae>,
    /// Test MAE statistics over training seeds.
    pub test: MaeStats,
    /// Test MAE statistics against the simulator's exact truth, where measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub test_truth: Option<MaeStats>,
}

// The sensitivity study's results (`crate::sensitivity`): what `evtac sensitivity` writes as
// `sensitivity.json`, a file of its own beside no reproduction's `results.json`.

/// Whether each of the paper's conclusions holds at one point (see [`crate::sensitivity`]); `None`
/// where the test trials have fewer than two levels to compare.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Conclusions {
    /// Static's test MAE is the lowest of the three.
    pub static_best: bool,
    /// Combined (OR) is not better than static.
    pub or_not_better: bool,
    /// Dynamic's rise at the slowest speed exceeds static's.
    pub dynamic_worse_slow: Option<bool>,
    /// Dynamic's rise at the shallowest depth exceeds static's.
    pub dynamic_worse_shallow: Option<bool>,
}

impl Conclusions {
    /// The conclusions' names, in the order of [`Conclusions::each`].
    pub const NAMES: [&'static str; 4] = [
        "static best",
        "OR not better than static",
        "dynamic worse at the slowest speed",
        "dynamic worse at the shallowest depth",
    ];

    /// The four, in [`Conclusions::NAMES`]' order (`None`: not measurable at this point).
    pub fn each(&self) -> [Option<bool>; 4] {
        [
            Some(self.static_best),
            Some(self.or_not_better),
            self.dynamic_worse_slow,
            self.dynamic_worse_shallow,
        ]
    }
}

/// How much a representation's error rises at one extreme level of the test trials: its MAE
/// there minus its mean over the other levels (both means over seeds).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rise {
    /// The extreme level (deg/s or mm).
    pub level: f64,
    /// How many levels the test trials have (fewer than 2: nothing to compare, rises 0).
    pub levels: usize,
    /// Static's rise, deg.
    pub static_deg: f64,
    /// Dynamic's rise, deg.
    pub dynamic_deg: f64,
}

/// What tuning chose for one representation at a point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tuned {
    /// Static's decay tau or dynamic's window, ms.
    pub time_ms: f64,
    /// The binarization threshold.
    pub threshold: f64,
}

/// One point of the study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// What the point varies.
    pub parameter: Varied,
    /// The factor on it (1 for the baseline).
    pub factor: f64,
    /// The settings tuning chose, static then dynamic.
    pub tuned: [Tuned; 2],
    /// Test MAE statistics over seeds: static, dynamic, combined.
    pub test: [MaeStats; 3],
    /// Dynamic minus static test MAE (means over seeds), deg.
    pub gap_deg: f64,
    /// The rise at the slowest speed.
    pub slow: Rise,
    /// The rise at the shallowest depth.
    pub shallow: Rise,
    /// What holds.
    pub conclusions: Conclusions,
}

/// The whole study: what `evtac sensitivity` writes as `sensitivity.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Study {
    /// The scale.
    pub scale: Scale,
    /// The master seed.
    pub seed: u64,
    /// The factors.
    pub factors: Vec<f64>,
    /// The defaults' point first, then each parameter at each factor.
    pub points: Vec<Point>,
}

impl Study {
    /// The baseline (the defaults), when the study has it.
    pub fn baseline(&self) -> Option<&Point> {
        self.points.iter().find(|p| p.parameter == Varied::Baseline)
    }

    /// For each conclusion, in [`Conclusions::NAMES`]' order, how many of the perturbed points
    /// (the baseline excluded) it holds at, and at how many it could be decided.
    pub fn shares(&self) -> [(usize, usize); 4] {
        let mut out = [(0, 0); 4];
        for p in self
            .points
            .iter()
            .filter(|p| p.parameter != Varied::Baseline)
        {
            for (o, holds) in out.iter_mut().zip(p.conclusions.each()) {
                if let Some(holds) = holds {
                    o.0 += usize::from(holds);
                    o.1 += 1;
                }
            }
        }
        out
    }
}

/// The baseline point's name, as files spell it.
pub const BASELINE: &str = "baseline";

/// What a point of the sensitivity study varies: nothing (the baseline, the simulator's
/// defaults) or one parameter, by its name. Written as that name (`"baseline"` for the
/// baseline), as `sensitivity.json`, `point.json` and jobs files always spelled it; a name that
/// is no parameter reads, and is refused when the point is run (naming the parameters there is).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(from = "String", into = "String")]
pub enum Varied {
    /// The simulator's defaults.
    Baseline,
    /// The parameter of this name, scaled.
    Parameter(String),
}

impl Varied {
    /// The name the point goes by: its parameter's, or [`BASELINE`].
    pub fn name(&self) -> &str {
        match self {
            Varied::Baseline => BASELINE,
            Varied::Parameter(name) => name,
        }
    }
}

impl From<String> for Varied {
    fn from(name: String) -> Self {
        if name == BASELINE {
            Varied::Baseline
        } else {
            Varied::Parameter(name)
        }
    }
}

impl From<&str> for Varied {
    fn from(name: &str) -> Self {
        Varied::from(name.to_string())
    }
}

impl From<Varied> for String {
    fn from(varied: Varied) -> Self {
        varied.name().to_string()
    }
}

impl std::fmt::Display for Varied {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Everything a reproduction measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// Settings and timings.
    pub run: RunInfo,
    /// Grid searches (static, dynamic).
    pub tuning: Vec<Tuning>,
    /// Experiment 1 per representation.
    pub exp1: Vec<Exp1Repr>,
    /// Experiment 2 per (setting, representation).
    pub exp2: Vec<Exp2Cell>,
    /// Experiment 3 per speed.
    pub exp3_speed: Vec<Exp3Point>,
    /// Experiment 3 per depth.
    pub exp3_depth: Vec<Exp3Point>,
    /// Latency per (representation, interval).
    pub latency: Vec<LatencyCell>,
    /// The Experiment 2 example trial.
    pub example: Option<ExampleTrial>,
    /// Experiment 1 per background-noise level and representation (absent from older results).
    #[serde(default)]
    pub noise: Vec<NoisePoint>,
    /// The values evtac chose where the paper states none (absent from older results).
    #[serde(default)]
    pub choices: Vec<Choice>,
    /// Experiment 2's labels against the commanded stop angles and the ground truth (absent
    /// without Experiment 2, and from older results).
    #[serde(default)]
    pub labels: Option<LabelCheck>,
    /// Contour overlays (static/dynamic x speed/depth); frames are not written to JSON.
    #[serde(skip)]
    pub overlays: Vec<Overlay>,
    /// The paper's Fig. 2 for one Experiment 1 test sample; not written to JSON.
    #[serde(skip)]
    pub repr_example: Option<ReprExample>,
    /// The sensor at rest and in contact; not written to JSON.
    #[serde(skip)]
    pub sensor: Option<SensorView>,
    /// The label-noise ablation (absent when the plan has none, and from older results).
    #[serde(default)]
    pub label_noise: Option<LabelNoise>,
    /// The capture-filter ablation (absent when the plan has none, and from older results).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capture_filter: Option<CaptureFilter>,
    /// What the sensor figure shows: its view is not in JSON but its kind is, so that the
    /// report's caption can be rebuilt from `results.json` alone. Absent from older results.
    #[serde(default)]
    pub sensor_kind: Option<SensorKind>,
    /// Experiment 1 per simulated dataset and representation, Experiment 1's own dataset
    /// first (empty when the plan has one dataset, and in older results).
    #[serde(default)]
    pub dataset_seeds: Vec<DatasetSeedPoint>,
    /// Experiment 1 with each condition's repeats kept on one side of the split (absent when
    /// no condition has two trials, and from older results).
    #[serde(default)]
    pub repeat_split: Option<RepeatSplit>,
    /// End-to-end latency, queueing included, of a few test trials replayed at recorded pace,
    /// idle and under load (`crate::paced_latency`); absent from older results, and not written
    /// when empty so that they re-serialize unchanged.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub paced_latency: Vec<PacedLatencyCell>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mae_and_stats() {
        let m = Mae::of(&[[1.0, 2.0], [3.0, 2.0]], &[[0.0, 0.0], [3.0, 4.0]]);
        assert_eq!(
            m,
            Mae {
                overall: 1.25,
                pitch: 0.5,
                roll: 2.0
            }
        );
        let s = MeanStd::of(&[1.0, 2.0, 3.0]);
        assert_eq!((s.mean, s.std, s.n), (2.0, 1.0, 3));
        assert_eq!(s.display(), "2.000 ± 1.000");
        assert_eq!(MeanStd::of(&[5.0]).std, 0.0);
    }
}
