//! What a condition's repeats on both sides of the split are worth: Experiment 1's paper
//! representations trained again, same settings and seeds, on a split that keeps every
//! condition's repeats on one side ([`Splits::make_grouped`]), beside Experiment 1 on the
//! paper's split, where a condition can train on one repeat and be tested on the other.
//!
//! The paper splits its trials with balanced marginals and says nothing of repeats; with two
//! repeats per condition, most test trials then have their twin in training. How much that
//! helps depends on how alike repeats are: on a rig that seats the sensor again between passes
//! (`evtac_sim::rig::Seating`) less than on one where repeats differ by sensor noise alone. The
//! two test sets are different trials of the same dataset, so a difference within the seeds'
//! spread is no evidence either way; the report says so.
//!
//! Runs only when some condition of Experiment 1's dataset has two or more trials (the paper's
//! scale, or `--repeats 2`) and the plan asks for it ([`crate::plan::Plan::repeat_split`]). Models go under `models/repeats-together/exp1/`, so a run resumes.

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::error::Error;
use crate::exp1;
use crate::results::{Exp1Repr, RepeatSplit};
use crate::splits::{Splits, Stratum};
use crate::stage::{FeatureSet, Stage};
use evtac_repr::{ReprConfig, ReprKind};
use std::path::{Path, PathBuf};

/// The folder of the grouped split's models under the run's models folder.
pub fn models_dir(models: &Path) -> PathBuf {
    models.join("repeats-together")
}

/// Trains and tests the paper's representations among `reprs` on the grouped split of
/// `cache`'s dataset (Experiment 1's); `paper_split` are Experiment 1's results. `None` when no
/// condition has two trials or the plan leaves the study out.
pub fn run(
    cache: &FeatureCache<'_>,
    reprs: &[ReprConfig],
    paper_split: &[Exp1Repr],
    run: &RunContext<'_>,
) -> Result<Option<RepeatSplit>, Error> {
    let strata = cache.dataset().strata();
    let repeats = Stratum::most_repeats(&strata);
    if repeats < 2 || !run.plan.repeat_split {
        return Ok(None);
    }
    let grouped = Splits::make_grouped(&strata, run.seed);
    let paper = crate::label_noise::paper(reprs);
    let models = models_dir(run.models);
    let at = RunContext {
        models: &models,
        ..*run
    };
    let together = exp1::run_as(
        cache,
        &grouped,
        &paper,
        &at,
        (FeatureSet::Exp1, Stage::RepeatSplitTraining),
    )?;
    Ok(Some(RepeatSplit {
        repeats,
        paper_split: paper_split
            .iter()
            .filter(|r| ReprKind::PAPER.contains(&r.name))
            .cloned()
            .collect(),
        together,
    }))
}
