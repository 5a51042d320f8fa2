//! Experiment 1: the static, dynamic and combined representations with the chosen settings, and
//! evtac's two learned fusions of the same parts (stacked, late), trained with several seeds on
//! the continuous-motion dataset; test MAE overall, pitch and roll as mean ± std over seeds.

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::jobs::{self, Progress};
use crate::plan::Plan;
use crate::results::{Exp1Repr, Mae, MaeStats};
use crate::sampling::{Phase, Sampling};
use crate::splits::{Split, Splits};
use crate::stage::{FeatureSet, Stage};
use crate::training::{self, Error, TrainSpec};
use evtac_learn::Model;
use evtac_learn::ModelBundle;
use evtac_repr::ReprConfig;
use std::path::{Path, PathBuf};

/// The display names of the representations compared, in report order: the paper's three, then
/// evtac's learned fusions.
pub const NAMES: [&str; 5] = ["Static", "Dynamic", "Combined", "Stacked", "Late"];
/// The learned fusions among [`NAMES`] (not in the paper).
pub const FUSIONS: [&str; 2] = ["Stacked", "Late"];

/// The representations of [`NAMES`] among `names` (results' names, in any order and repeated),
/// in report order: the columns and panels of a table or figure.
pub fn in_order<'a>(names: impl Iterator<Item = &'a str>) -> Vec<&'static str> {
    let names: Vec<&str> = names.collect();
    NAMES.into_iter().filter(|n| names.contains(n)).collect()
}

/// The paper's three representations, display name and config: static, dynamic and their
/// OR (what `evtac render` draws as frames).
pub fn paper_representations(
    static_cfg: ReprConfig,
    dynamic_cfg: ReprConfig,
) -> Vec<(&'static str, ReprConfig)> {
    let mut out = representations(static_cfg, dynamic_cfg);
    out.truncate(3);
    out
}

/// The representations a plan compares: [`representations`], less the learned fusions when
/// the plan leaves them out ([`Plan::fusions`]).
pub fn of_plan(
    plan: &Plan,
    static_cfg: ReprConfig,
    dynamic_cfg: ReprConfig,
) -> Vec<(&'static str, ReprConfig)> {
    if plan.fusions {
        representations(static_cfg, dynamic_cfg)
    } else {
        paper_representations(static_cfg, dynamic_cfg)
    }
}

/// The representations compared, display name and config: the paper's three (static,
/// dynamic, their OR) and the two learned fusions of the same tuned parts (`Stacked`: one dense
/// network over both frames; `Late`: a branch per frame joined before the head), which are not
/// tuned on their own: they take the settings chosen for static and dynamic.
pub fn representations(
    static_cfg: ReprConfig,
    dynamic_cfg: ReprConfig,
) -> Vec<(&'static str, ReprConfig)> {
    let [st, dy, combined, stacked, late] = NAMES;
    let mut out = vec![(st, static_cfg), (dy, dynamic_cfg)];
    if let (Some(&static_part), Some(&dynamic_part)) =
        (static_cfg.static_part(), dynamic_cfg.dynamic_part())
    {
        out.extend([
            (
                combined,
                ReprConfig::Combined {
                    static_part,
                    dynamic_part,
                },
            ),
            (
                stacked,
                ReprConfig::Stacked {
                    static_part,
                    dynamic_part,
                },
            ),
            (
                late,
                ReprConfig::Late {
                    static_part,
                    dynamic_part,
                },
            ),
        ]);
    }
    out
}

/// The seeds of `n` runs from the master `seed`.
pub fn seeds(seed: u64, n: usize) -> Vec<u64> {
    (0..n as u64).map(|k| seed.wrapping_add(k)).collect()
}

/// The folder of one Experiment 1 model.
pub fn model_dir(out: &Path, name: &str, seed: u64) -> PathBuf {
    out.join("exp1")
        .join(name.to_lowercase())
        .join(format!("seed{seed}"))
}

/// A job of a multi-seed experiment.
#[derive(Debug, Clone)]
pub struct SeedJob {
    /// Representation name.
    pub name: &'static str,
    /// The training job.
    pub spec: TrainSpec,
    /// Its folder.
    pub dir: PathBuf,
}

/// The training jobs of Experiment 1.
pub fn jobs(
    reprs: &[(&'static str, ReprConfig)],
    plan: &Plan,
    seed: u64,
    out: &Path,
) -> Vec<SeedJob> {
    let seeds = seeds(seed, plan.seeds);
    let train = (plan.epochs, Sampling::MOTION, [Phase::Motion].as_slice());
    seed_jobs(reprs, &seeds, train, |name, s| model_dir(out, name, s))
}

/// One job per (representation, seed), in that order, each training for `epochs` on `sampling`'s
/// points of `phases`, in the folder `dir` gives (Experiments 1 and 2 differ only in those).
pub(crate) fn seed_jobs(
    reprs: &[(&'static str, ReprConfig)],
    seeds: &[u64],
    (epochs, sampling, phases): (usize, Sampling, &[Phase]),
    dir: impl Fn(&str, u64) -> PathBuf,
) -> Vec<SeedJob> {
    let mut v = Vec::new();
    for &(name, repr) in reprs {
        for &seed in seeds {
            v.push(SeedJob {
                name,
                spec: TrainSpec {
                    repr,
                    seed,
                    epochs,
                    sampling,
                    phases: phases.to_vec(),
                },
                dir: dir(name, seed),
            });
        }
    }
    v
}

/// Runs (or resumes) `jobs` on `cache`'s dataset, in parallel.
pub fn train_all(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    jobs: &[SeedJob],
    progress: &dyn Progress,
) -> Result<(), Error> {
    jobs::run_all(
        jobs,
        |j| j.dir.clone(),
        |j| training::train_job(cache, splits, &j.spec, &j.dir, |_| {}).map(|_| ()),
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
    reprs: &[(&'static str, ReprConfig)],
    sampling: Sampling,
    (features, training): (FeatureSet, Stage),
    jobs: &[SeedJob],
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
    let configs: Vec<ReprConfig> = reprs.iter().map(|r| r.1).collect();
    progress.stage(Stage::Features(features), all.len() as u64);
    cache.ensure(&all, &configs, sampling, &|reused| {
        progress.finished(reused)
    })?;
    progress.stage(training, jobs.len() as u64);
    train_all(cache, splits, jobs, progress)
}

/// Runs Experiment 1 and evaluates every model on the test split.
pub fn run(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    reprs: &[(&'static str, ReprConfig)],
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
    reprs: &[(&'static str, ReprConfig)],
    run: &RunContext<'_>,
    stages: (FeatureSet, Stage),
) -> Result<Vec<Exp1Repr>, Error> {
    let (plan, seed, out, progress) = (run.plan, run.seed, run.models, run.progress);
    let jobs = jobs(reprs, plan, seed, out);
    features_then_training(
        cache,
        splits,
        reprs,
        Sampling::MOTION,
        stages,
        &jobs,
        progress,
    )?;
    let mut results = Vec::new();
    for &(name, config) in reprs {
        let test = training::load_split(
            cache,
            splits,
            Split::Test,
            &config,
            Sampling::MOTION,
            &[Phase::Motion],
        )?;
        let mut runs = Vec::new();
        let mut val_runs = Vec::new();
        let seeds = seeds(seed, plan.seeds);
        for &s in &seeds {
            let model = training::load_model(&model_dir(out, name, s))?;
            let pred = training::predict(&model, &test)?;
            runs.push(training::mae_in(&test, &pred, None));
            val_runs.push(Mae::from(model.bundle.config.metrics.validation));
        }
        results.push(Exp1Repr {
            name: name.into(),
            config: serde_json::to_value(config).unwrap_or(serde_json::Value::Null),
            seeds,
            test: MaeStats::of(&runs),
            runs,
            val_runs,
        });
    }
    Ok(results)
}

/// Loads the Experiment 1 models of `name`.
pub fn models(out: &Path, name: &str, seed: u64, n: usize) -> Result<Vec<Model>, Error> {
    seeds(seed, n)
        .into_iter()
        .map(|s| training::load_model(&model_dir(out, name, s)))
        .collect()
}

/// Whether the bundle in `dir` is complete.
pub fn finished(dir: &Path) -> bool {
    jobs::is_done(dir) && ModelBundle::load(dir).is_ok()
}
