//! The order training runs start in: the longest first.
//!
//! A stage's runs share the machine's cores (one run per core, [`crate::jobs::run_all`]), and
//! the stage ends when its last run does. Started in grid order, a dense run (the static grid
//! at count threshold 0 is 96 % non-zero and trains about twice as long as a sparse one) can
//! start last and leave the other cores idle while it finishes. Started longest first, the runs
//! left at the end are the short ones (the longest-processing-time rule).
//!
//! A run's time is predicted from its features: training skips zero inputs, so an epoch's time
//! grows with the non-zero features per sample. Each distinct configuration is probed once, on
//! the first trial of the training split (read from the feature cache, which the stage has
//! filled before training).

use crate::cache::FeatureCache;
use crate::job::TrainJob;
use crate::splits::{Split, Splits};
use crate::training::Error;

/// `jobs` ordered by their features' non-zero values per sample, the most first; ties (the
/// seeds of one configuration) keep their order. Finished jobs are not probed and go last.
pub fn longest_first<'j>(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    jobs: &'j [TrainJob],
) -> Result<Vec<&'j TrainJob>, Error> {
    let ds = cache.dataset();
    let probe = ds.trials(splits.get(Split::Train))?;
    let probe = &probe[..probe.len().min(1)];
    let mut known: Vec<(&TrainJob, f64)> = Vec::new();
    let mut keyed = Vec::with_capacity(jobs.len());
    for job in jobs {
        let non_zeros = if crate::jobs::is_done(&job.out) || probe.is_empty() {
            -1.0
        } else if let Some(&(_, n)) = known.iter().find(|(k, _)| same_features(k, job)) {
            n
        } else {
            let set = cache.load(probe, &job.spec.repr, job.spec.sampling, &job.spec.phases)?;
            let n = non_zeros_per_sample(&set.set);
            known.push((job, n));
            n
        };
        keyed.push((job, non_zeros));
    }
    // A stable sort: equal keys keep the caller's order.
    keyed.sort_by(|a, b| b.1.total_cmp(&a.1));
    Ok(keyed.into_iter().map(|(job, _)| job).collect())
}

/// Whether two jobs train on the same features.
fn same_features(a: &TrainJob, b: &TrainJob) -> bool {
    a.dataset == b.dataset && a.spec.repr == b.spec.repr && a.spec.sampling == b.spec.sampling
}

/// Mean non-zero features per sample of `set` (0 for an empty set).
fn non_zeros_per_sample(set: &evtac_learn::FeatureSet) -> f64 {
    let non_zero = set.features.iter().filter(|&&v| v != 0.0).count();
    non_zero as f64 / set.len().max(1) as f64
}
