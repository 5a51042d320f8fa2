//! What the NeuroTac lab's capture filter does to the three representations: Experiment 1's
//! paper representations trained and tested again, same settings, seeds and initial weights,
//! with every recording of the dataset (trials and no-contact recording) through
//! [`Plan::capture_filter`] (`background-activity=10ms` by default at small scale: the lab's
//! `NeuroTac` capture class passes every recording through dv-processing's
//! `BackgroundActivityNoiseFilter` with a 10 ms window before saving it), beside Experiment 1
//! on the unfiltered events. The report compares them paired by seed.
//!
//! The filtered dataset is the same folder opened with the filter among its inputs
//! ([`evtac_import::inputs::Inputs::filters`]), so the same splits and labels, its features
//! cached apart. The models go under `models/capture-filter/exp1/`, so a run resumes, and the
//! jobs are listed with Experiment 1's for an external scheduler
//! ([`crate::pipeline::export_jobs`]).

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::error::Error;
use crate::exp1;
use crate::job::TrainJob;
use crate::plan::Plan;
use crate::results::{CaptureFilter, Exp1Repr};
use crate::splits::Splits;
use crate::stage::{FeatureSet, Stage};
use evtac_filters::FilterSpec;
use evtac_repr::{ReprConfig, ReprKind};
use std::path::{Path, PathBuf};

/// The folder of the ablation's models under the run's models folder.
pub fn models_dir(models: &Path) -> PathBuf {
    models.join("capture-filter")
}

/// `ds` (Experiment 1's dataset, unfiltered) opened again with `spec` after its own filters.
fn filtered(ds: &Dataset, spec: &FilterSpec) -> Result<Dataset, Error> {
    let mut filters = ds.inputs.filters.clone();
    filters.push(spec.clone());
    Ok(Dataset::open(
        &ds.dir,
        ds.inputs.clone().with_filters(filters),
    )?)
}

/// The ablation's training jobs: Experiment 1's (on `ds` with its tuned `reprs`) for the
/// paper's representations on the filtered dataset, under [`models_dir`]. Empty when the plan
/// has no capture filter.
pub fn jobs(
    (ds, reprs): (&Dataset, &[ReprConfig]),
    plan: &Plan,
    seed: u64,
    models: &Path,
) -> Result<Vec<TrainJob>, Error> {
    let Some(spec) = &plan.capture_filter else {
        return Ok(Vec::new());
    };
    let paper = crate::label_noise::paper(reprs);
    Ok(exp1::jobs(
        &filtered(ds, spec)?,
        &paper,
        plan,
        seed,
        &models_dir(models),
    ))
}

/// Runs (or resumes) the ablation on `ds` (Experiment 1's dataset, split by `splits`) and tests
/// its models on the filtered test trials; `unfiltered` are Experiment 1's results. `None` when
/// the plan has no capture filter.
pub fn run(
    ds: &Dataset,
    splits: &Splits,
    reprs: &[ReprConfig],
    unfiltered: &[Exp1Repr],
    run: &RunContext<'_>,
) -> Result<Option<CaptureFilter>, Error> {
    let Some(spec) = &run.plan.capture_filter else {
        return Ok(None);
    };
    let ds_filtered = filtered(ds, spec)?;
    let cache = FeatureCache::new(&ds_filtered)?;
    let jobs = jobs((ds, reprs), run.plan, run.seed, run.models)?;
    let models = models_dir(run.models);
    let at = RunContext {
        models: &models,
        ..*run
    };
    let paper = crate::label_noise::paper(reprs);
    let filtered = exp1::run_jobs(
        &cache,
        splits,
        &paper,
        &at,
        (FeatureSet::CaptureFilter, Stage::CaptureFilterTraining),
        &jobs,
    )?;
    Ok(Some(CaptureFilter {
        spec: spec.to_string(),
        unfiltered: unfiltered
            .iter()
            .filter(|r| ReprKind::PAPER.contains(&r.name))
            .cloned()
            .collect(),
        filtered,
    }))
}
