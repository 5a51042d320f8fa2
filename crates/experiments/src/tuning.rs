//! Experiment 1's hyperparameter search: one training run per (decay tau x threshold) for the
//! static representation and per (window x threshold) for the dynamic one, each selected at its
//! best validation epoch; the setting with the lowest validation MAE is chosen.
//!
//! A grid point is one run, so two settings a seed's spread apart are ranked by chance. When
//! the plan asks for it ([`Plan::recheck_top`]), the best settings are trained again with more
//! seeds (the grid's run is the first; [`recheck_jobs`]), so the report can say whether the
//! choice stands beyond the seeds' spread. The choice itself stays the grid's, as the paper's
//! protocol makes it.

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::job::TrainJob;
use crate::plan::{self, Plan};
use crate::results::{Mae, MaeStats, Recheck, Tuning, TuningRun};
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
    /// Threshold ([`Kind::threshold_name`]: a voxel grid's bins).
    pub threshold: f64,
    /// The config.
    pub config: ReprConfig,
}

/// The tunings of the representations the paper did not choose that `plan` compares
/// ([`Plan::beyond_kinds`]), in report order, each run (or resumed) by [`tune`].
pub fn tune_beyond(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    run: &RunContext<'_>,
) -> Result<Vec<Tuning>, Error> {
    run.plan
        .beyond_kinds()
        .iter()
        .filter_map(|&repr| Kind::of_repr(repr))
        .map(|kind| tune(cache, splits, kind, run))
        .collect()
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
        Kind::TimeSurface | Kind::Histogram | Kind::VoxelGrid => plan
            .dense_grids
            .points(kind.repr())
            .into_iter()
            .map(|(time_ms, threshold, config)| GridPoint {
                time_ms,
                threshold,
                config,
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
        inputs: ds.inputs.clone(),
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

/// The folder of one recheck run: `config` trained with `seed`.
pub fn recheck_dir(out: &Path, kind: Kind, config: &ReprConfig, seed: u64) -> PathBuf {
    out.join("tuning-recheck")
        .join(kind.name())
        .join(config.cache_key())
        .join(format!("seed-{seed}"))
}

/// The [`Plan::recheck_top`] best of `ranked` (each grid point with its validation MAE), best
/// first; ties keep the grid's order.
pub fn top(ranked: &[(f64, GridPoint)], plan: &Plan) -> Vec<GridPoint> {
    let mut sorted: Vec<&(f64, GridPoint)> = ranked.iter().collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    sorted
        .into_iter()
        .take(plan.recheck_top)
        .map(|(_, p)| p.clone())
        .collect()
}

/// The seeds a rechecked setting is trained with: the grid's own run's first.
pub fn recheck_seeds(plan: &Plan, seed: u64) -> Vec<u64> {
    crate::exp1::seeds(seed, plan.recheck_seeds.max(1))
}

/// The training jobs of the recheck of `points` (from [`top`]): every seed but the grid's own,
/// whose run is already there.
pub fn recheck_jobs(
    ds: &Dataset,
    kind: Kind,
    points: &[GridPoint],
    plan: &Plan,
    seed: u64,
    out: &Path,
) -> Vec<TrainJob> {
    let mut jobs = Vec::new();
    for p in points {
        for &s in recheck_seeds(plan, seed).iter().skip(1) {
            let mut job = job(ds, kind, p.config, plan, seed, out);
            job.spec.seed = s;
            job.out = recheck_dir(out, kind, &p.config, s);
            jobs.push(job);
        }
    }
    jobs
}

/// Trains (or resumes) the recheck of the best `ranked` settings and reads back each one's
/// validation MAE per seed.
fn recheck(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    kind: Kind,
    run: &RunContext<'_>,
    ranked: &[(f64, GridPoint)],
) -> Result<Vec<Recheck>, Error> {
    let (plan, seed, out, progress) = (run.plan, run.seed, run.models, run.progress);
    let points = top(ranked, plan);
    let jobs = recheck_jobs(cache.dataset(), kind, &points, plan, seed, out);
    if points.is_empty() {
        return Ok(Vec::new());
    }
    progress.stage(Stage::Tuning(kind), jobs.len() as u64);
    crate::exp1::train_all(cache, splits, &jobs, progress)?;
    let mut out_list = Vec::new();
    for p in &points {
        let seeds = recheck_seeds(plan, seed);
        let mut val_runs = Vec::new();
        for (k, &s) in seeds.iter().enumerate() {
            let dir = if k == 0 {
                run_dir(out, kind, &p.config)
            } else {
                recheck_dir(out, kind, &p.config, s)
            };
            val_runs.push(Mae::from(
                ModelBundle::load(&dir)?.config.metrics.validation,
            ));
        }
        out_list.push(Recheck {
            time_ms: p.time_ms,
            threshold: p.threshold,
            seeds,
            val: MaeStats::of(&val_runs),
            val_runs,
        });
    }
    Ok(out_list)
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
    let ranked: Vec<(f64, GridPoint)> = runs
        .iter()
        .zip(&points)
        .map(|(r, p)| (r.val.overall, p.clone()))
        .collect();
    let recheck = recheck(cache, splits, kind, run, &ranked)?;
    Ok(Tuning {
        recheck,
        repr: kind.repr(),
        time_name: kind.time_name().into(),
        runs,
        chosen_time_ms: best.time_ms,
        chosen_threshold: best.threshold,
        chosen_config: best.config,
        // A cross's curves pass through its center; full grids (the real-valued kinds' always
        // are) through the best point.
        curve_time_ms: match kind {
            Kind::Static if !plan.full_grid => plan.static_center.0,
            Kind::Dynamic if !plan.full_grid => plan.dynamic_center.0,
            _ => best.time_ms,
        },
        curve_threshold: match kind {
            Kind::Static if !plan.full_grid => f64::from(plan.static_center.1),
            Kind::Dynamic if !plan.full_grid => f64::from(plan.dynamic_center.1),
            _ => best.threshold,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_sim::Scale;

    #[test]
    fn the_recheck_takes_the_best_settings_and_adds_seeds_after_the_grids_own() {
        let plan = Plan::for_scale(Scale::Small);
        let points = grid(&plan, Kind::Static);
        let ranked: Vec<(f64, GridPoint)> = points
            .iter()
            .enumerate()
            .map(|(i, p)| ((i as f64 - 5.0).abs(), p.clone()))
            .collect();
        let best = top(&ranked, &plan);
        assert_eq!(best.len(), plan.recheck_top);
        assert_eq!(best[0], points[5]);
        // Ties (4 and 6 are both 1 away) keep the grid's order.
        assert_eq!((&best[1], &best[2]), (&points[4], &points[6]));
        assert_eq!(recheck_seeds(&plan, 7), [7, 8, 9, 10, 11]);
        let out = std::path::Path::new("/models");
        let dirs: Vec<PathBuf> = best
            .iter()
            .flat_map(|p| {
                recheck_seeds(&plan, 7)
                    .into_iter()
                    .skip(1)
                    .map(|s| recheck_dir(out, Kind::Static, &p.config, s))
            })
            .collect();
        assert_eq!(dirs.len(), plan.recheck_top * (plan.recheck_seeds - 1));
        assert!(dirs[0].ends_with("seed-8"));
        let none = Plan {
            recheck_top: 0,
            ..plan
        };
        assert!(top(&ranked, &none).is_empty());
    }
}
