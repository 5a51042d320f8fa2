//! What a reproduction runs at each scale: the tuning grids, epochs, seeds and latency settings.
//!
//! `paper` does what the paper states (every combination of the grid, 100 epochs, ten runs) on
//! grid values that are evtac's choice (the paper names only some of the values it tried).
//! `small` and `tiny` keep its structure with fewer runs so that `evtac reproduce --scale small`
//! finishes within half an hour on a 2-core machine: `small` searches a full 4 x 4 grid per
//! representation with fewer epochs and seeds (about 9 minutes on 2 cores before the noise
//! study; by `stage.rs`'s cost model its two more noise datasets add about 4.5 minutes, and the
//! four more simulation seeds of the spread across datasets about 9). `tiny`, for tests, walks
//! a cross through the paper's chosen settings (one parameter varied while the other is fixed,
//! as the paper's tuning figure shows). The report states the plan it ran.

pub use crate::dense_grid::DenseGrids;
use evtac_repr::{DynamicConfig, ReprConfig, ReprKind, StaticConfig};
use evtac_sim::Scale;
use serde::{Deserialize, Serialize};

/// Which representation a grid search tunes (the plan has a grid for each).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Decay tau x threshold.
    Static,
    /// Window x threshold.
    Dynamic,
    /// Tau x threshold (0: continuous), [`DenseGrids`].
    TimeSurface,
    /// Window.
    Histogram,
    /// Window x bins.
    VoxelGrid,
}

impl Kind {
    /// Every kind with a grid: the paper's two, then the real-valued kinds.
    pub const ALL: [Kind; 5] = [
        Kind::Static,
        Kind::Dynamic,
        Kind::TimeSurface,
        Kind::Histogram,
        Kind::VoxelGrid,
    ];

    /// The representation tuned.
    pub fn repr(self) -> ReprKind {
        match self {
            Kind::Static => ReprKind::Static,
            Kind::Dynamic => ReprKind::Dynamic,
            Kind::TimeSurface => ReprKind::TimeSurface,
            Kind::Histogram => ReprKind::Histogram,
            Kind::VoxelGrid => ReprKind::VoxelGrid,
        }
    }

    /// The kind that tunes `repr`, if any (the fusions and the OR are not tuned: they take the
    /// static and dynamic choices).
    pub fn of_repr(repr: ReprKind) -> Option<Kind> {
        Self::ALL.into_iter().find(|k| k.repr() == repr)
    }

    /// The name of the grid's first axis: `tau_ms` or `window_ms`.
    pub fn time_name(self) -> &'static str {
        match self {
            Kind::Static | Kind::TimeSurface => "tau_ms",
            Kind::Dynamic | Kind::Histogram | Kind::VoxelGrid => "window_ms",
        }
    }

    /// The name of the grid's second axis: `threshold` (0 for a continuous time surface; a
    /// histogram's is always 0) or a voxel grid's `bins`.
    pub fn threshold_name(self) -> &'static str {
        match self {
            Kind::VoxelGrid => "bins",
            Kind::Static | Kind::Dynamic | Kind::TimeSurface | Kind::Histogram => "threshold",
        }
    }

    /// `static` or `dynamic`.
    pub fn name(self) -> &'static str {
        self.repr().name()
    }
}

/// The settings of one reproduction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The scale: also how many trials the simulated datasets have.
    pub scale: Scale,
    /// Static decay constants tried, ms.
    pub static_taus_ms: Vec<f64>,
    /// Static thresholds tried, event contributions.
    pub static_thresholds: Vec<f32>,
    /// Dynamic windows tried, ms.
    pub dynamic_windows_ms: Vec<f64>,
    /// Dynamic thresholds tried, event counts.
    pub dynamic_thresholds: Vec<u32>,
    /// Every combination (`true`, the paper) or a cross through the centers (`false`).
    pub full_grid: bool,
    /// The static (tau, threshold) the cross passes through.
    pub static_center: (f64, f32),
    /// The dynamic (window, threshold) the cross passes through.
    pub dynamic_center: (f64, u32),
    /// Epochs of each tuning run.
    pub tuning_epochs: usize,
    /// Epochs of the final runs (Experiments 1 and 2).
    pub epochs: usize,
    /// Seeds per representation in Experiment 1.
    pub seeds: usize,
    /// Seeds per (setting, representation) in Experiment 2.
    pub exp2_seeds: usize,
    /// Test trials used by the latency study (at most).
    pub latency_trials: usize,
    /// Sampling intervals of the latency study, ms.
    pub latency_intervals_ms: Vec<u32>,
    /// Background-noise factors Experiment 1 is repeated at (leak, shot and hot pixels scaled
    /// together; 1 is Experiment 1 itself). Absent from older plans: none.
    #[serde(default)]
    pub noise_levels: Vec<f64>,
    /// Whether evtac's learned fusions (`Stacked`, `Late`) are trained and reported beside the
    /// paper's three representations (`evtac reproduce --no-fusions` leaves them out: the
    /// paper's own plan, about half the training). Absent from older plans: they were.
    #[serde(default = "fusions_by_default")]
    pub fusions: bool,
    /// Standard deviation (degrees) of the noise the label-noise ablation adds to Experiment
    /// 1's training labels ([`LABEL_NOISE_DEG`] by default), or `None` for no ablation
    /// (`evtac reproduce --label-noise-deg 0`). Absent from older plans: none.
    #[serde(default)]
    pub label_noise_deg: Option<f64>,
    /// Simulated datasets Experiment 1 is run on, its own included: each other one is
    /// simulated with the same parameters and another seed and trained with the settings tuned
    /// on Experiment 1's (`crate::dataset_seeds`), so the report can set the spread across
    /// datasets beside the spread across training seeds. 1: Experiment 1's alone (`evtac
    /// reproduce --datasets 1`). Absent from older plans: 1.
    #[serde(default = "one_dataset")]
    pub datasets: usize,
    /// Whether Experiment 1's paper representations are trained again on a split that keeps
    /// each condition's repeats on one side (`crate::repeat_split`), when the dataset has
    /// repeats (`evtac reproduce --no-repeat-split` leaves it out: the paper's own plan). Absent
    /// from older plans: it was.
    #[serde(default = "repeat_split_by_default")]
    pub repeat_split: bool,
    /// Which tuning grids the lists above are: the paper's, or evtac's extension of them past
    /// the edge where the paper's optimum sat. Absent from older plans: the paper's.
    #[serde(default)]
    pub grid: Grid,
    /// How many of each representation's best grid settings are trained again with
    /// [`Plan::recheck_seeds`] seeds, so the report can say whether the choice stands beyond
    /// the seeds' spread (`crate::tuning::recheck`). 0: none. Absent from older plans: none.
    #[serde(default)]
    pub recheck_top: usize,
    /// Training seeds per rechecked setting, the grid's own run included.
    #[serde(default)]
    pub recheck_seeds: usize,
    /// The filter of the capture-filter ablation (`crate::capture_filter`): Experiment 1's
    /// paper representations again on every recording through it ([`lab_capture_filter`] by
    /// default at `small`), or `None` for no ablation (`evtac reproduce --no-capture-filter`).
    /// Absent from older plans: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capture_filter: Option<evtac_filters::FilterSpec>,
    /// The grids of the real-valued kinds the paper did not choose (`evtac tune --repr
    /// time-surface`, `histogram`, `voxel-grid`). Absent from older plans: `small`'s.
    #[serde(default)]
    pub dense_grids: DenseGrids,
    /// Whether Experiment 1 also compares the representations the paper did not choose (time
    /// surface, histogram, voxel grid), each tuned on its grid ([`Plan::dense_grids`]) and
    /// trained with the plan's seeds on every dataset (`evtac reproduce --beyond`). They are
    /// not trained in Experiment 2, at other noise, or in the ablations. Absent from older
    /// plans: no.
    #[serde(default)]
    pub beyond: bool,
}

/// The NeuroTac lab's capture filter: its `NeuroTac` capture class passes every recording
/// through dv-processing's `BackgroundActivityNoiseFilter` with a 10 ms window before saving.
pub fn lab_capture_filter() -> evtac_filters::FilterSpec {
    evtac_filters::FilterSpec::BackgroundActivity {
        duration: evtac_filters::Micros::new(10_000).expect("10 ms is positive"),
    }
}

/// Which tuning grids a plan searches (`evtac reproduce --grid`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Grid {
    /// The grids that bracket the paper's stated values (every plan before `--grid` existed).
    #[default]
    Paper,
    /// The paper's grids and [`EXTRA_STATIC_TAUS_MS`]: at every scale the paper's static
    /// optimum sat on the largest decay tried with validation MAE still falling there.
    Extended,
}

impl std::str::FromStr for Grid {
    type Err = String;

    /// `paper` or `extended`.
    fn from_str(s: &str) -> Result<Grid, String> {
        match s.trim() {
            "paper" => Ok(Grid::Paper),
            "extended" => Ok(Grid::Extended),
            other => Err(format!("{other:?} is not a grid: paper or extended")),
        }
    }
}

impl Grid {
    /// The name on the command line and in the report: `paper`, `extended`.
    pub fn name(self) -> &'static str {
        match self {
            Grid::Paper => "paper",
            Grid::Extended => "extended",
        }
    }
}

/// The static decays [`Grid::Extended`] adds, ms. 10 s is far longer than a trial's motion
/// (at most 10 s at 2 deg/s): as near to no decay as a finite tau gets within one trial
/// (`StaticConfig` needs a finite tau > 0).
pub const EXTRA_STATIC_TAUS_MS: [f64; 3] = [3000.0, 5000.0, 10000.0];

/// Settings [`Plan::recheck_top`] retrains, and seeds each ([`Plan::recheck_seeds`]).
pub const RECHECK: (usize, usize) = (3, 5);

/// The label-noise ablation's standard deviation: the spread of the paper's label validation at
/// stops (-0.01 ± 0.04 deg).
pub const LABEL_NOISE_DEG: f64 = 0.04;

/// [`Plan::datasets`] of plans written before it existed.
fn one_dataset() -> usize {
    1
}

/// [`Plan::fusions`] of plans written before it existed.
fn fusions_by_default() -> bool {
    true
}

/// [`Plan::repeat_split`] of plans written before it existed.
fn repeat_split_by_default() -> bool {
    true
}

/// The background-noise factors of every scale (`evtac reproduce --noise-levels`): without
/// noise, the simulator's default, three times it.
pub const NOISE_LEVELS: [f64; 3] = [0.0, 1.0, 3.0];

impl Plan {
    /// The plan of a scale, with evtac's [`Grid::Extended`] and the recheck of the best
    /// settings ([`RECHECK`]). `evtac reproduce --grid paper` makes it [`Plan::with_grid`]'s.
    pub fn for_scale(scale: Scale) -> Plan {
        Plan {
            recheck_top: RECHECK.0,
            recheck_seeds: RECHECK.1,
            ..Plan::paper_grids(scale)
        }
        .with_grid(Grid::Extended)
    }

    /// This plan searching `grid`: the scale's paper lists, and [`EXTRA_STATIC_TAUS_MS`] for
    /// [`Grid::Extended`].
    pub fn with_grid(self, grid: Grid) -> Plan {
        let paper = Plan::paper_grids(self.scale);
        let mut static_taus_ms = paper.static_taus_ms;
        if grid == Grid::Extended {
            static_taus_ms.extend(EXTRA_STATIC_TAUS_MS);
        }
        Plan {
            grid,
            static_taus_ms,
            static_thresholds: paper.static_thresholds,
            dynamic_windows_ms: paper.dynamic_windows_ms,
            dynamic_thresholds: paper.dynamic_thresholds,
            ..self
        }
    }

    /// The plan of a scale with the paper's grids and no recheck. `small` and `tiny` take the
    /// rest (the cross's centers, the latency intervals, the noise levels) from `paper`.
    fn paper_grids(scale: Scale) -> Plan {
        match scale {
            Scale::Paper => Plan {
                scale,
                static_taus_ms: vec![100.0, 250.0, 500.0, 750.0, 1000.0, 1500.0, 2000.0],
                static_thresholds: vec![0.0, 1.0, 2.0, 3.0, 4.0],
                dynamic_windows_ms: vec![10.0, 20.0, 40.0, 80.0, 160.0, 320.0, 640.0, 1280.0],
                dynamic_thresholds: vec![0, 1, 2, 3, 4],
                full_grid: true,
                // The paper's chosen settings (tau 1000 ms, threshold 2; window 640 ms, 0).
                static_center: (1000.0, 2.0),
                dynamic_center: (640.0, 0),
                tuning_epochs: 100,
                epochs: 100,
                seeds: 10,
                exp2_seeds: 10,
                latency_trials: 150,
                latency_intervals_ms: vec![1, 2, 5, 10],
                noise_levels: NOISE_LEVELS.to_vec(),
                fusions: true,
                label_noise_deg: Some(LABEL_NOISE_DEG),
                // Three: the fewest that give the paper's scale a spread across datasets beside
                // the training seeds' (at `small` it exceeds theirs for some representations). Each more adds a
                // simulation and Experiment 1's runs, about a quarter of the plan's training.
                datasets: 3,
                // Runs only on a dataset with repeats (the paper's scale has two passes).
                repeat_split: true,
                grid: Grid::Paper,
                recheck_top: 0,
                recheck_seeds: 0,
                // The paper's plan is hours already; `small` runs the ablation by default.
                capture_filter: None,
                dense_grids: DenseGrids::for_scale(scale),
                beyond: false,
            },
            Scale::Small => Plan {
                scale,
                static_taus_ms: vec![100.0, 300.0, 1000.0, 2000.0],
                static_thresholds: vec![0.0, 1.0, 2.0, 4.0],
                dynamic_windows_ms: vec![40.0, 160.0, 640.0, 1280.0],
                dynamic_thresholds: vec![0, 1, 2, 4],
                full_grid: true,
                tuning_epochs: 30,
                epochs: 60,
                seeds: 5,
                exp2_seeds: 3,
                latency_trials: 20,
                // Five simulation seeds: the fewest that give the spread across datasets a
                // standard deviation worth comparing with the training seeds'.
                datasets: 5,
                capture_filter: Some(lab_capture_filter()),
                dense_grids: DenseGrids::for_scale(scale),
                ..Plan::paper_grids(Scale::Paper)
            },
            Scale::Tiny => Plan {
                scale,
                static_taus_ms: vec![100.0, 1000.0],
                static_thresholds: vec![0.0, 2.0],
                dynamic_windows_ms: vec![80.0, 640.0],
                dynamic_thresholds: vec![0, 2],
                full_grid: false,
                tuning_epochs: 2,
                epochs: 3,
                seeds: 2,
                exp2_seeds: 2,
                latency_trials: 2,
                // Two, so that every test of a tiny run goes through a second dataset.
                datasets: 2,
                dense_grids: DenseGrids::for_scale(scale),
                ..Plan::paper_grids(Scale::Paper)
            },
        }
    }

    /// The recheck of the best settings in words ("the 3 best settings of each trained again
    /// with 5 seeds"), or `None` when the plan has none: the report's and the choices' one text.
    pub fn recheck_text(&self) -> Option<String> {
        (self.recheck_top > 0).then(|| {
            format!(
                "the {} best settings of each trained again with {} seeds",
                self.recheck_top, self.recheck_seeds
            )
        })
    }

    /// The representations the paper did not choose that Experiment 1 compares: all three with
    /// [`Plan::beyond`], else none.
    pub fn beyond_kinds(&self) -> &'static [ReprKind] {
        if self.beyond { &ReprKind::BEYOND } else { &[] }
    }

    /// Representations trained per seed in Experiment 1 on every dataset: the paper's three,
    /// the two learned fusions unless left out, and the kinds beyond the paper when asked for.
    pub fn exp1_representations(&self) -> usize {
        self.representations() + self.beyond_kinds().len()
    }

    /// Representations trained per seed in Experiment 2 and the noise study: the
    /// paper's three, and the two learned fusions unless left out.
    pub fn representations(&self) -> usize {
        if self.fusions {
            ReprKind::PAPER.len() + ReprKind::FUSIONS.len()
        } else {
            ReprKind::PAPER.len()
        }
    }

    /// Each noise factor once, in the order given.
    pub fn unique_noise_levels(&self) -> Vec<f64> {
        let mut out: Vec<f64> = Vec::new();
        for &l in &self.noise_levels {
            if !out.contains(&l) {
                out.push(l);
            }
        }
        out
    }

    /// The noise factors that need their own dataset: every one but 1 (Experiment 1's), each
    /// once, in the order given.
    pub fn simulated_noise_levels(&self) -> Vec<f64> {
        let mut levels = self.unique_noise_levels();
        levels.retain(|&l| l != 1.0);
        levels
    }

    /// The static grid as (tau, threshold) pairs, in a fixed order.
    pub fn static_grid(&self) -> Vec<(f64, f32)> {
        grid(
            &self.static_taus_ms,
            &self.static_thresholds,
            self.full_grid,
            self.static_center,
        )
    }

    /// The dynamic grid as (window, threshold) pairs, in a fixed order.
    pub fn dynamic_grid(&self) -> Vec<(f64, u32)> {
        grid(
            &self.dynamic_windows_ms,
            &self.dynamic_thresholds,
            self.full_grid,
            self.dynamic_center,
        )
    }
}

fn grid<T: Copy + PartialEq>(
    times: &[f64],
    thresholds: &[T],
    full: bool,
    center: (f64, T),
) -> Vec<(f64, T)> {
    let mut out = Vec::new();
    for &t in times {
        for &th in thresholds {
            if full || th == center.1 || t == center.0 {
                out.push((t, th));
            }
        }
    }
    // A cross always contains its center, even when the lists do not.
    if !out.contains(&center) {
        out.push(center);
    }
    out
}

/// The static config with `tau_ms`, `threshold` and evtac's defaults for the settings the paper
/// does not state (`StaticConfig::default`: dv-processing's constructor defaults).
pub fn static_config(tau_ms: f64, threshold: f32) -> ReprConfig {
    ReprConfig::Static(StaticConfig {
        tau_ms,
        threshold,
        ..StaticConfig::default()
    })
}

/// The dynamic config with `window_ms` and `count_threshold`.
pub fn dynamic_config(window_ms: f64, count_threshold: u32) -> ReprConfig {
    ReprConfig::Dynamic(DynamicConfig {
        window_ms,
        count_threshold,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_and_small_grids_are_full_and_tiny_grid_is_a_cross() {
        let paper = Plan::for_scale(Scale::Paper).with_grid(Grid::Paper);
        assert_eq!(paper.static_grid().len(), 7 * 5);
        assert_eq!(paper.dynamic_grid().len(), 8 * 5);
        let small = Plan::for_scale(Scale::Small).with_grid(Grid::Paper);
        assert_eq!(small.static_grid().len(), 4 * 4);
        assert_eq!(small.dynamic_grid().len(), 4 * 4);
        let tiny = Plan::for_scale(Scale::Tiny).with_grid(Grid::Paper);
        let g = tiny.static_grid();
        // 2 taus at threshold 2, plus the other threshold at tau 1000.
        assert_eq!(g.len(), 2 + 1);
        assert!(g.contains(&(1000.0, 2.0)));
        assert!(g.iter().all(|&(t, th)| t == 1000.0 || th == 2.0));
    }

    #[test]
    fn the_default_grid_extends_the_static_decays_past_the_papers_edge() {
        for scale in [Scale::Tiny, Scale::Small, Scale::Paper] {
            let plan = Plan::for_scale(scale);
            assert_eq!(plan.grid, Grid::Extended);
            assert_eq!((plan.recheck_top, plan.recheck_seeds), RECHECK);
            let paper = plan.clone().with_grid(Grid::Paper);
            assert_eq!(paper.grid, Grid::Paper);
            let largest = |p: &Plan| p.static_taus_ms.iter().copied().fold(0.0, f64::max);
            assert_eq!(largest(&plan), 10000.0);
            assert!(largest(&paper) < EXTRA_STATIC_TAUS_MS[0]);
            // The same dynamic grid: its optimum was inside at every scale.
            assert_eq!(plan.dynamic_windows_ms, paper.dynamic_windows_ms);
            // Back and forth gives the same lists.
            assert_eq!(paper.with_grid(Grid::Extended), plan);
        }
        // A plan written before the grid existed reads as the paper's, with no recheck.
        let mut old = serde_json::to_value(Plan::for_scale(Scale::Small)).unwrap();
        for field in ["grid", "recheck_top", "recheck_seeds"] {
            old.as_object_mut().unwrap().remove(field);
        }
        let old: Plan = serde_json::from_value(old).unwrap();
        assert_eq!((old.grid, old.recheck_top), (Grid::Paper, 0));
    }
}
