//! Experiment 3: the Experiment 1 models on the speed-wise and depth-wise datasets; MAE per
//! speed and per depth, with seen (training) and unseen (interpolated) values marked.

use crate::cache::FeatureCache;
use crate::progress::Progress;
use crate::results::{Exp3Point, MaeStats};
use crate::sampling::{Phase, Sampling};
use crate::stage::{FeatureSet, Stage};
use crate::training::{self, Error};
use evtac_events::manifest::TrialMeta;
use evtac_learn::Model;
use evtac_repr::ReprKind;
use std::collections::BTreeMap;

/// Which condition a dataset varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Speed, deg/s.
    Speed,
    /// Depth, mm.
    Depth,
}

impl Axis {
    fn value(self, t: &TrialMeta) -> f64 {
        match self {
            Axis::Speed => t.speed_deg_s,
            Axis::Depth => t.depth_mm,
        }
    }
}

/// Evaluates `models` (kind, Experiment 1 models) on every trial of `cache`'s dataset, grouped by
/// the value of `axis`. A value is seen when its trials say `group = seen` or, without groups,
/// when it is one of `training_values`.
pub fn run(
    cache: &FeatureCache<'_>,
    axis: Axis,
    models: &[(ReprKind, Vec<Model>)],
    training_values: &[f64],
    progress: &dyn Progress,
) -> Result<Vec<Exp3Point>, Error> {
    let trials: Vec<&TrialMeta> = cache.dataset().manifest.trials.iter().collect();
    let set = match axis {
        Axis::Speed => FeatureSet::Exp3Speed,
        Axis::Depth => FeatureSet::Exp3Depth,
    };
    by_level(cache, &trials, axis, models, training_values, set, progress)
}

/// [`run`] on `trials` of `cache`'s dataset only (the sensitivity study's Experiment 1 test
/// trials), their features reported to `progress` as `set`.
pub(crate) fn by_level(
    cache: &FeatureCache<'_>,
    trials: &[&TrialMeta],
    axis: Axis,
    models: &[(ReprKind, Vec<Model>)],
    training_values: &[f64],
    set: FeatureSet,
    progress: &dyn Progress,
) -> Result<Vec<Exp3Point>, Error> {
    let mut by_value: BTreeMap<i64, Vec<usize>> = BTreeMap::new();
    for (i, t) in trials.iter().enumerate() {
        // Keyed in thousandths so float values group exactly.
        by_value
            .entry((axis.value(t) * 1000.0).round() as i64)
            .or_default()
            .push(i);
    }
    let configs: Vec<_> = models
        .iter()
        .filter_map(|(_, m)| m.first().map(|m| m.repr_config()))
        .collect();
    progress.stage(Stage::Features(set), trials.len() as u64);
    cache.ensure(trials, &configs, Sampling::MOTION, &|reused| {
        progress.finished(reused)
    })?;
    let mut out = Vec::new();
    for (name, ms) in models {
        let Some(first) = ms.first() else { continue };
        let set = cache.load(
            trials,
            &first.repr_config(),
            Sampling::MOTION,
            &[Phase::Motion],
        )?;
        let preds: Vec<Vec<[f32; 2]>> = ms
            .iter()
            .map(|m| training::predict(m, &set))
            .collect::<Result<_, _>>()?;
        let labels = training::label_rows(&set);
        let truth = crate::truth::rows(cache.dataset(), trials, &set)?;
        for (&key, members) in &by_value {
            let value = key as f64 / 1000.0;
            let seen = match trials[members[0]].group.as_deref() {
                Some(g) => g == "seen",
                None => training_values.iter().any(|v| (v - value).abs() < 1e-6),
            };
            let rows: Vec<usize> = set
                .samples
                .iter()
                .enumerate()
                .filter(|(_, s)| members.contains(&s.trial))
                .map(|(i, _)| i)
                .collect();
            // Each model's MAE over this level's rows against `reference` (labels or truth).
            let runs_against = |reference: &[[f32; 2]]| -> Vec<crate::results::Mae> {
                preds
                    .iter()
                    .map(|p| {
                        let pp: Vec<[f32; 2]> = rows.iter().map(|&i| p[i]).collect();
                        let rr: Vec<[f32; 2]> = rows.iter().map(|&i| reference[i]).collect();
                        crate::results::Mae::of(&pp, &rr)
                    })
                    .collect()
            };
            let runs = runs_against(&labels);
            let truth_stats = truth.as_deref().map(|t| MaeStats::of(&runs_against(t)));
            out.push(Exp3Point {
                name: *name,
                value,
                seen,
                trials: members.len(),
                stats: MaeStats::of(&runs),
                runs,
                truth: truth_stats,
            });
        }
    }
    Ok(out)
}
