//! Experiment 1's hyperparameter search: one training run per (decay tau x threshold) for the
//! static representation and per (window x threshold) for the dynamic one, each selected at its
//! best validation epoch; the setting with the lowest validation MAE is chosen.

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::job::TrainJob;
use crate::plan::{self, Plan};
use crate::results::{Mae, Tuning, TuningRun};
use crate::sampling::{Phase, Sampling};
use crate::splits::{Split, Splits};
use crate::stage::{FeatureSet, Stage};
use crate::training::{Error, TrainSpec};
use evtac_learn::ModelBundle;
use evtac_repr::ReprConfig;
use std::path::{Path, PathBuf};

pub use crate::plan::Kind;

/// One grid point: its (time, threshold) and config.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPoint {
    /// Tau or window, ms.
    pub time_ms: f64,
    /// Threshold.
    pub threshold: f64,
    /// The config.
    pub config: ReprConfig,
}

/// The grid of `kind` under `plan`.
pub fn grid(plan: &Plan, kind: Kind) -> Vec<GridPoint> {
    match kind {
        Kind::Static => plan
            .static_grid()
            .into_iter()
            .map(|(t, th)| GridPoint {
                time_ms: t,
                threshold: f64::from(th),
                config: plan::static_config(t, th),
            })
            .collect(),
        Kind::Dynamic => plan
            .dynamic_grid()
            .into_iter()
            .map(|(t, th)| GridPoint {
                time_ms: t,
                threshold: f64::from(th),
                config: plan::dynamic_config(t, th),
            })
            .collect(),
    }
}

/// The folder of one tuning run.
pub fn run_dir(out: &Path, kind: Kind, config: &ReprConfig) -> PathBuf {
    out.join("tuning")
        .join(kind.name())
        .join(config.cache_key())
}

/// The training job of one grid point of `kind` on `ds` (splits and weights from `seed`), in
/// its folder under the models folder `out`.
pub fn job(
    ds: &Dataset,
    kind: Kind,
    config: ReprConfig,
    plan: &Plan,
    seed: u64,
    out: &Path,
) -> TrainJob {
    TrainJob {
        dataset: ds.dir.clone(),
        inputs: ds.inputs,
        splits_seed: seed,
        spec: TrainSpec {
            repr: config,
            seed,
            epochs: plan.tuning_epochs,
            sampling: Sampling::MOTION,
            phases: vec![Phase::Motion],
            label_noise_deg: 0.0,
        },
        out: run_dir(out, kind, &config),
    }
}

/// Runs (or resumes) the grid search of `kind` and picks the setting with the lowest validation
/// MAE. Runs go in parallel; finished runs (with `done`) are read back, not redone.
pub fn tune(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    kind: Kind,
    run: &RunContext<'_>,
) -> Result<Tuning, Error> {
    let (plan, seed, out, progress) = (run.plan, run.seed, run.models, run.progress);
    let points = grid(plan, kind);
    let ds = cache.dataset();
    let trials = ds.trials(&[splits.get(Split::Train), splits.get(Split::Val)].concat())?;
    let configs: Vec<ReprConfig> = points.iter().map(|p| p.config).collect();
    progress.stage(
        Stage::Features(FeatureSet::Tuning(kind)),
        trials.len() as u64,
    );
    cache.ensure(&trials, &configs, Sampling::MOTION, &|reused| {
        progress.finished(reused)
    })?;
    progress.stage(Stage::Tuning(kind), points.len() as u64);
    let jobs: Vec<TrainJob> = points
        .iter()
        .map(|p| job(ds, kind, p.config, plan, seed, out))
        .collect();
    crate::exp1::train_all(cache, splits, &jobs, progress)?;
    let mut runs = Vec::new();
    for p in &points {
        let bundle = ModelBundle::load(&run_dir(out, kind, &p.config))?;
        runs.push(TuningRun {
            time_ms: p.time_ms,
            threshold: p.threshold,
            val: Mae::from(bundle.config.metrics.validation),
        });
    }
    let best = runs
        .iter()
        .zip(&points)
        .min_by(|a, b| a.0.val.overall.total_cmp(&b.0.val.overall))
        .map(|(_, p)| p.clone())
        .unwrap_or_else(|| points[0].clone());
    Ok(Tuning {
        repr: kind.repr(),
        time_name: match kind {
            Kind::Static => "tau_ms".into(),
            Kind::Dynamic => "window_ms".into(),
        },
        runs,
        chosen_time_ms: best.time_ms,
        chosen_threshold: best.threshold,
        chosen_config: best.config,
        curve_time_ms: if plan.full_grid {
            best.time_ms
        } else {
            match kind {
                Kind::Static => plan.static_center.0,
                Kind::Dynamic => plan.dynamic_center.0,
            }
        },
        curve_threshold: if plan.full_grid {
            best.threshold
        } else {
            match kind {
                Kind::Static => f64::from(plan.static_center.1),
                Kind::Dynamic => f64::from(plan.dynamic_center.1),
            }
        },
    })
}
