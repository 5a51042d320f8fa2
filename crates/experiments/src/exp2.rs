//! Experiment 2: motion interrupted by a stop. The chosen settings are trained on the pause
//! dataset under three settings and evaluated on its test trials per phase:
//! `continuous-only` (the Experiment 1 models, not retrained), `pause-motion` (trained on the
//! motion-phase samples of pause trials) and `pause-motion-stop` (motion and stop samples).

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::exp1;
use crate::job::TrainJob;
use crate::plan::Plan;
use crate::results::{Exp2Cell, Exp2Setting, MaeStats};
use crate::sampling::{Phase, Sampling};
use crate::splits::{Split, Splits};
use crate::stage::{FeatureSet, Stage};
use crate::training::{self, Error};
use evtac_learn::Model;
use evtac_repr::{ReprConfig, ReprKind};
use std::path::{Path, PathBuf};

/// The folder of one Experiment 2 model.
pub fn model_dir(out: &Path, setting: Exp2Setting, kind: ReprKind, seed: u64) -> PathBuf {
    out.join("exp2")
        .join(setting.key())
        .join(kind.name())
        .join(format!("seed{seed}"))
}

/// The training jobs of Experiment 2 on the pause dataset `ds` (the two pause-inclusive
/// settings), its splits drawn with `seed`.
pub fn jobs(
    ds: &Dataset,
    reprs: &[ReprConfig],
    plan: &Plan,
    seed: u64,
    out: &Path,
) -> Vec<TrainJob> {
    let seeds = exp1::seeds(seed, plan.exp2_seeds);
    let mut v = Vec::new();
    for (setting, phases) in [
        (Exp2Setting::PauseMotion, vec![Phase::Motion]),
        (
            Exp2Setting::PauseMotionStop,
            vec![Phase::Motion, Phase::Stop],
        ),
    ] {
        let train = (plan.epochs, Sampling::WITH_STOP, phases.as_slice());
        v.extend(exp1::seed_jobs(
            (ds, seed),
            reprs,
            &seeds,
            train,
            |name, s| model_dir(out, setting, name, s),
        ));
    }
    v
}

/// Runs Experiment 2 on the pause dataset `cache` with its `splits`; `out` holds the
/// Experiment 1 models.
pub fn run(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    reprs: &[ReprConfig],
    run: &RunContext<'_>,
) -> Result<Vec<Exp2Cell>, Error> {
    let (plan, seed, out, progress) = (run.plan, run.seed, run.models, run.progress);
    let jobs = jobs(cache.dataset(), reprs, plan, seed, out);
    let stages = (FeatureSet::Exp2, Stage::Exp2Training);
    let sampling = Sampling::WITH_STOP;
    exp1::features_then_training(cache, splits, reprs, sampling, stages, &jobs, progress)?;
    let mut cells = Vec::new();
    let mut truth_memo = None;
    for setting in Exp2Setting::ALL {
        for &config in reprs {
            let name = config.kind();
            let test = training::load_split(
                cache,
                splits,
                Split::Test,
                &config,
                Sampling::WITH_STOP,
                &[Phase::Motion, Phase::Stop],
            )?;
            let models: Vec<Model> = if setting == Exp2Setting::ContinuousOnly {
                exp1::models(out, name, seed, plan.seeds)?
            } else {
                exp1::seeds(seed, plan.exp2_seeds)
                    .into_iter()
                    .map(|s| training::load_model(&model_dir(out, setting, name, s)))
                    .collect::<Result<_, _>>()?
            };
            // The test samples are the same trials at the same times for every representation:
            // their truth is read once.
            if truth_memo.is_none() {
                truth_memo = Some(crate::truth::of_split(cache, splits, Split::Test, &test)?);
            }
            let truth = truth_memo.as_ref().and_then(Option::as_ref);
            let (mut motion, mut stop) = (Vec::new(), Vec::new());
            let (mut motion_truth, mut stop_truth) = (Vec::new(), Vec::new());
            for m in &models {
                let pred = training::predict(m, &test)?;
                motion.push(training::mae_in(&test, &pred, Some(Phase::Motion)));
                stop.push(training::mae_in(&test, &pred, Some(Phase::Stop)));
                if let Some(truth) = &truth {
                    let against =
                        |phase| crate::truth::mae_against(&test, &pred, truth, |p| p == phase);
                    motion_truth.push(against(Phase::Motion));
                    stop_truth.push(against(Phase::Stop));
                }
            }
            let measured = truth.is_some();
            cells.push(Exp2Cell {
                setting,
                name,
                motion: MaeStats::of(&motion),
                stop: MaeStats::of(&stop),
                motion_runs: motion,
                stop_runs: stop,
                motion_truth: measured.then(|| MaeStats::of(&motion_truth)),
                stop_truth: measured.then(|| MaeStats::of(&stop_truth)),
            });
        }
    }
    Ok(cells)
}
