//! Errors against the simulator's exact truth, beside the errors against the labels the models
//! were trained and tested on.
//!
//! A simulated trial keeps the pose the simulator actually gave the sensor (`truth/<trial>.csv`,
//! pitch and roll in the sensor's frame at 1 kHz). The labels are what the IMU pipeline makes of
//! the recording, as on a real rig, so they carry the labels' own error (the IMU's noise and
//! bias, the filter, and the sensor's seating turn, which labels on the commanded rolling axis
//! do not see). A model's MAE against the labels mixes its own error with theirs; against the
//! truth it does not. Where every trial of a set has a truth file (simulated data), the report
//! gives both; recordings have none, and then nothing is computed or claimed.

use crate::cache::{FeatureCache, LoadedSet};
use crate::dataset::{self, Dataset};
use crate::results::Mae;
use crate::splits::{Split, Splits};
use evtac_events::manifest::TrialMeta;
use evtac_labels::LabelSeries;

/// The truth (pitch, roll, degrees) at every sample of `set`, whose samples index `trials`
/// (as [`crate::cache::FeatureCache::load`] made it); `None` when a trial has no truth file.
pub fn rows(
    ds: &Dataset,
    trials: &[&TrialMeta],
    set: &LoadedSet,
) -> Result<Option<Vec<[f32; 2]>>, dataset::Error> {
    let mut series = Vec::with_capacity(trials.len());
    for meta in trials {
        let Some(file) = &meta.truth else {
            return Ok(None);
        };
        let path = ds.dir.join(file);
        let truth = LabelSeries::read_csv(&path).map_err(|e| dataset::Error::Labels {
            trial: meta.trial.clone(),
            message: format!("{}: {e}", path.display()),
        })?;
        if truth.is_empty() {
            return Err(dataset::Error::Labels {
                trial: meta.trial.clone(),
                message: format!("{}: no rows", path.display()),
            });
        }
        series.push(truth);
    }
    Ok(Some(
        set.samples
            .iter()
            .map(|s| {
                let (p, r) = series[s.trial].at(s.t_us);
                [p as f32, r as f32]
            })
            .collect(),
    ))
}

/// [`rows`] for a set loaded from `split` of `cache`'s dataset (as
/// [`crate::training::load_split`] loads it).
pub fn of_split(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    split: Split,
    set: &LoadedSet,
) -> Result<Option<Vec<[f32; 2]>>, dataset::Error> {
    let ds = cache.dataset();
    let trials = ds.trials(splits.get(split))?;
    rows(ds, &trials, set)
}

/// MAE of `pred` against `reference` over the samples of `set` whose phase `keep` accepts.
pub fn mae_against(
    set: &LoadedSet,
    pred: &[[f32; 2]],
    reference: &[[f32; 2]],
    keep: impl Fn(crate::sampling::Phase) -> bool,
) -> Mae {
    let (mut p, mut l) = (Vec::new(), Vec::new());
    for ((s, a), b) in set.samples.iter().zip(pred).zip(reference) {
        if keep(s.phase) {
            p.push(*a);
            l.push(*b);
        }
    }
    Mae::of(&p, &l)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cache::SampleMeta;
    use crate::sampling::Phase;

    #[test]
    fn the_mae_is_taken_against_the_reference_given_over_the_phases_kept() {
        let set = LoadedSet {
            samples: vec![
                SampleMeta {
                    trial: 0,
                    t_us: 0,
                    phase: Phase::Motion,
                },
                SampleMeta {
                    trial: 0,
                    t_us: 1000,
                    phase: Phase::Stop,
                },
            ],
            ..LoadedSet::default()
        };
        let pred = [[1.0, 2.0], [3.0, 4.0]];
        let truth = [[1.5, 2.0], [3.0, 3.0]];
        let all = mae_against(&set, &pred, &truth, |_| true);
        assert_eq!((all.pitch, all.roll), (0.25, 0.5));
        let motion = mae_against(&set, &pred, &truth, |p| p == Phase::Motion);
        assert_eq!((motion.pitch, motion.roll), (0.5, 0.0));
    }
}
