//! Experiment 1: the static, dynamic and combined representations with the chosen settings, and
//! evtac's two learned fusions of the same parts (stacked, late), trained with several seeds on
//! the continuous-motion dataset; test MAE overall, pitch and roll as mean ± std over seeds.

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::job::TrainJob;
use crate::jobs;
use crate::plan::Plan;
use crate::progress::Progress;
use crate::results::{Exp1Repr, Mae, MaeStats};
use crate::sampling::{Phase, Sampling};
use crate::splits::{Split, Splits};
use crate::stage::{FeatureSet, Stage};
use crate::training::{self, Error, TrainSpec};
use evtac_learn::Model;
use evtac_learn::ModelBundle;
use evtac_repr::{ReprConfig, ReprKind};
use std::path::{Path, PathBuf};

/// The paper's three representations: static, dynamic and their OR (what `evtac render` draws
/// as frames).
pub fn paper_representations(static_cfg: ReprConfig, dynamic_cfg: ReprConfig) -> Vec<ReprConfig> {
    let mut out = representations(static_cfg, dynamic_cfg);
    out.truncate(ReprKind::PAPER.len());
    out
}

/// The representations a plan compares: [`representations`], less the learned fusions when
/// the plan leaves them out ([`Plan::fusions`]).
pub fn of_plan(plan: &Plan, static_cfg: ReprConfig, dynamic_cfg: ReprConfig) -> Vec<ReprConfig> {
    if plan.fusions {
        representations(static_cfg, dynamic_cfg)
    } else {
        paper_representations(static_cfg, dynamic_cfg)
    }
}

/// The representations compared, in [`ReprKind::ALL`]'s order: the paper's three (static,
/// dynamic, their OR) and the two learned fusions of the same tuned parts (`Stacked`: one dense
/// network over both frames; `Late`: a branch per frame joined before the head), which are not
/// tuned on their own: they take the settings chosen for static and dynamic.
pub fn representations(static_cfg: ReprConfig, dynamic_cfg: ReprConfig) -> Vec<ReprConfig> {
    let mut out = vec![static_cfg, dynamic_cfg];
    if let (Some(&static_part), Some(&dynamic_part)) =
        (static_cfg.static_part(), dynamic_cfg.dynamic_part())
    {
        // Every kind built from both parts, in report order: a kind added to `ReprKind` is
        // compared without a change here.
        out.extend(
            ReprKind::ALL
                .into_iter()
                .filter(|kind| kind.parts() == (true, true))
                .map(|kind| kind.config(static_part, dynamic_part)),
        );
    }
    out
}

/// The seeds of `n` runs from the master `seed`.
pub fn seeds(seed: u64, n: usize) -> Vec<u64> {
    (0..n as u64).map(|k| seed.wrapping_add(k)).collect()
}

/// The folder of one Experiment 1 model.
pub fn model_dir(out: &Path, kind: ReprKind, seed: u64) -> PathBuf {
    out.join("exp1")
        .join(kind.name())
        .join(format!("seed{seed}"))
}

/// The training jobs of Experiment 1 on `ds`, its splits drawn with `seed`.
pub fn jobs(
    ds: &Dataset,
    reprs: &[ReprConfig],
    plan: &Plan,
    seed: u64,
    out: &Path,
) -> Vec<TrainJob> {
    let seeds = seeds(seed, plan.seeds);
    let train = (plan.epochs, Sampling::MOTION, [Phase::Motion].as_slice());
    seed_jobs((ds, seed), reprs, &seeds, train, |kind, s| {
        model_dir(out, kind, s)
    })
}

/// One job per (representation, seed), in that order, on the dataset `ds` (splits drawn with
/// `splits_seed`), each training for `epochs` on `sampling`'s points of `phases`, in the folder
/// `dir` gives (Experiments 1 and 2 differ only in those).
pub(crate) fn seed_jobs(
    (ds, splits_seed): (&Dataset, u64),
    reprs: &[ReprConfig],
    seeds: &[u64],
    (epochs, sampling, phases): (usize, Sampling, &[Phase]),
    dir: impl Fn(ReprKind, u64) -> PathBuf,
) -> Vec<TrainJob> {
    let mut v = Vec::new();
    for &repr in reprs {
        for &seed in seeds {
            v.push(TrainJob {
                dataset: ds.dir.clone(),
                inputs: ds.inputs.clone(),
                splits_seed,
                spec: TrainSpec {
                    repr,
                    seed,
                    epochs,
                    sampling,
                    phases: phases.to_vec(),
                    label_noise_deg: 0.0,
                },
                out: dir(repr.kind(), seed),
            });
        }
    }
    v
}

/// Runs (or resumes) `jobs` on `cache`'s dataset, in parallel, the longest first
/// (the crate's `schedule` module).
pub fn train_all(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    jobs: &[TrainJob],
    progress: &dyn Progress,
) -> Result<(), Error> {
    let ordered = crate::schedule::longest_first(cache, splits, jobs)?;
    jobs::run_all(
        &ordered,
        |j| j.out.clone(),
        |j| training::train_job(cache, splits, &j.spec, &j.out, |_| {}).map(|_| ()),
        |skipped| progress.finished(skipped),
    )
}

/// What Experiments 1 and 2 do before evaluating: the features of every trial of `cache`'s
/// dataset under each of `reprs` (sampled by `sampling`), then the training `jobs` (run or
/// resumed), each reported as its stage.
#[allow(clippy::too_many_arguments)]
pub fn features_then_training(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    reprs: &[ReprConfig],
    sampling: Sampling,
    (features, training): (FeatureSet, Stage),
    jobs: &[TrainJob],
    progress: &dyn Progress,
) -> Result<(), Error> {
    let all = cache.dataset().trials(
        &[
            splits.get(Split::Train),
            splits.get(Split::Val),
            splits.get(Split::Test),
        ]
        .concat(),
    )?;
    progress.stage(Stage::Features(features), all.len() as u64);
    cache.ensure(&all, reprs, sampling, &|reused| progress.finished(reused))?;
    progress.stage(training, jobs.len() as u64);
    train_all(cache, splits, jobs, progress)
}

/// Runs Experiment 1 and evaluates every model on the test split.
pub fn run(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    reprs: &[ReprConfig],
    run: &RunContext<'_>,
) -> Result<Vec<Exp1Repr>, Error> {
    run_as(
        cache,
        splits,
        reprs,
        run,
        (FeatureSet::Exp1, Stage::Exp1Training),
    )
}

/// [`run`] on another dataset of Experiment 1's protocol (e.g. at another background noise),
/// reporting its features and training as `stages`.
pub fn run_as(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    reprs: &[ReprConfig],
    run: &RunContext<'_>,
    stages: (FeatureSet, Stage),
) -> Result<Vec<Exp1Repr>, Error> {
    let jobs = jobs(cache.dataset(), reprs, run.plan, run.seed, run.models);
    run_jobs(cache, splits, reprs, run, stages, &jobs)
}

/// [`run_as`] with Experiment 1's `jobs` given (the label-noise ablation's differ from
/// [`jobs`] in their training labels only): features, training, then every model on the test
/// split.
pub(crate) fn run_jobs(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    reprs: &[ReprConfig],
    run: &RunContext<'_>,
    stages: (FeatureSet, Stage),
    jobs: &[TrainJob],
) -> Result<Vec<Exp1Repr>, Error> {
    let (plan, seed, out, progress) = (run.plan, run.seed, run.models, run.progress);
    features_then_training(
        cache,
        splits,
        reprs,
        Sampling::MOTION,
        stages,
        jobs,
        progress,
    )?;
    let mut results = Vec::new();
    let mut truth_memo = None;
    for &config in reprs {
        let kind = config.kind();
        let test = training::load_split(
            cache,
            splits,
            Split::Test,
            &config,
            Sampling::MOTION,
            &[Phase::Motion],
        )?;
        // The test samples are the same trials at the same times for every representation:
        // their truth is read once.
        if truth_memo.is_none() {
            truth_memo = Some(crate::truth::of_split(cache, splits, Split::Test, &test)?);
        }
        let truth = truth_memo.as_ref().and_then(Option::as_ref);
        let mut runs = Vec::new();
        let mut truth_runs = Vec::new();
        let mut val_runs = Vec::new();
        let seeds = seeds(seed, plan.seeds);
        for &s in &seeds {
            let model = training::load_model(&model_dir(out, kind, s))?;
            let pred = training::predict(&model, &test)?;
            runs.push(training::mae_in(&test, &pred, None));
            if let Some(truth) = &truth {
                truth_runs.push(crate::truth::mae_against(&test, &pred, truth, |_| true));
            }
            val_runs.push(Mae::from(model.bundle.config.metrics.validation));
        }
        let labels_truth = truth.as_ref().map(|truth| {
            crate::truth::mae_against(&test, &training::label_rows(&test), truth, |_| true)
        });
        results.push(Exp1Repr {
            name: kind,
            config,
            seeds,
            test: MaeStats::of(&runs),
            test_truth: truth.as_ref().map(|_| MaeStats::of(&truth_runs)),
            truth_runs,
            labels_truth,
            runs,
            val_runs,
        });
    }
    Ok(results)
}

/// Loads the Experiment 1 models of `kind`.
pub fn models(out: &Path, kind: ReprKind, seed: u64, n: usize) -> Result<Vec<Model>, Error> {
    seeds(seed, n)
        .into_iter()
        .map(|s| training::load_model(&model_dir(out, kind, s)))
        .collect()
}

/// Whether the bundle in `dir` is complete.
pub fn finished(dir: &Path) -> bool {
    jobs::is_done(dir) && ModelBundle::load(dir).is_ok()
}
