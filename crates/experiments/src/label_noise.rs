//! The label-noise ablation: Experiment 1's three paper representations trained again, same
//! settings, seeds and initial weights, with Gaussian noise of [`Plan::label_noise_deg`]
//! degrees added to every training label, and tested on the same clean test labels. The paper
//! validates its IMU labels at stops to -0.01 ± 0.04 deg; on the simulator the labels are
//! nearly exact (about 0.001 deg RMS), so this asks what labels as noisy as the paper's
//! validation spread would cost.
//!
//! The models go under `models/label-noise/sd<sd>/exp1/`, so a run resumes, and the jobs are
//! listed with the other Experiment 1 jobs for an external scheduler
//! ([`crate::pipeline::export_jobs`]).

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::error::Error;
use crate::exp1;
use crate::job::TrainJob;
use crate::plan::Plan;
use crate::results::{Exp1Repr, LabelNoise};
use crate::splits::Splits;
use crate::stage::{FeatureSet, Stage};
use evtac_repr::{ReprConfig, ReprKind};
use std::path::{Path, PathBuf};

/// The folder of the ablation's models at `sd` under the run's models folder.
pub fn models_dir(models: &Path, sd: f64) -> PathBuf {
    models.join("label-noise").join(format!("sd{sd}"))
}

/// The paper's representations among `reprs`: the ones the ablation (and the grouped split's
/// measurement, `crate::repeat_split`) trains.
pub(crate) fn paper(reprs: &[ReprConfig]) -> Vec<ReprConfig> {
    reprs
        .iter()
        .filter(|c| ReprKind::PAPER.contains(&c.kind()))
        .copied()
        .collect()
}

/// The ablation's training jobs: Experiment 1's for the paper's representations among `reprs`,
/// with label noise `sd`, under [`models_dir`]. Empty when the plan has no ablation.
pub fn jobs(
    ds: &Dataset,
    reprs: &[ReprConfig],
    plan: &Plan,
    seed: u64,
    models: &Path,
) -> Vec<TrainJob> {
    let Some(sd) = plan.label_noise_deg.filter(|sd| *sd > 0.0) else {
        return Vec::new();
    };
    let paper = paper(reprs);
    let mut jobs = exp1::jobs(ds, &paper, plan, seed, &models_dir(models, sd));
    for job in &mut jobs {
        job.spec.label_noise_deg = sd;
    }
    jobs
}

/// Runs (or resumes) the ablation and tests its models; `clean` are Experiment 1's results.
/// `None` when the plan has no ablation.
pub fn run(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    reprs: &[ReprConfig],
    clean: &[Exp1Repr],
    run: &RunContext<'_>,
) -> Result<Option<LabelNoise>, Error> {
    let Some(sd) = run.plan.label_noise_deg.filter(|sd| *sd > 0.0) else {
        return Ok(None);
    };
    let jobs = jobs(cache.dataset(), reprs, run.plan, run.seed, run.models);
    let models = models_dir(run.models, sd);
    let at = RunContext {
        models: &models,
        ..*run
    };
    let paper = paper(reprs);
    let noisy = exp1::run_jobs(
        cache,
        splits,
        &paper,
        &at,
        (FeatureSet::Exp1, Stage::LabelNoiseTraining),
        &jobs,
    )?;
    Ok(Some(LabelNoise {
        sd_deg: sd,
        clean: clean
            .iter()
            .filter(|r| ReprKind::PAPER.contains(&r.name))
            .cloned()
            .collect(),
        noisy,
    }))
}
