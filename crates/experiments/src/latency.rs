//! The latency study: Experiment 1's test trials processed sequentially at sampling intervals of
//! 1, 2, 5 and 10 ms; the estimator's processing time for each estimate, at 50 uniformly spaced
//! steps per trial (so long trials do not dominate). Median, P99 and max per representation and
//! interval.
//!
//! Each step runs through [`evtac_online::Estimator`], the estimation core of `evtac online`, and
//! the time recorded is the one `evtac online` reports as the processing time of an estimate
//! ([`evtac_online::Estimate::processing`]): every moment the estimator spends on the way from
//! the step's events to its estimate, with nothing done before the timer starts. That is the
//! cropping and the representation update of the step's events, advancing the representation to
//! the step's time, pooling and the MLP, and also the work the estimator does ahead of the
//! estimate once the previous one is out (the window dropping the events that leave it by then,
//! and the combined representation's accumulator taking them), which live runs between
//! estimates. The events come at recorded pace: one chunk per step holding exactly the events of
//! its interval, stamped when it is handed over, with the step's time as the horizon, so no step
//! waits behind a backlog and queueing never counts. Steps follow each other without the idle
//! time between them (it would only add waiting). Events before motion onset go in as one
//! untimed chunk: the sensor is still then and an online system would have processed them as
//! they came (its estimate at onset primes the streaming first layer, as live; the work it
//! leaves for the next estimate is charged to that estimate). Runs on the calling thread, alone.

use crate::dataset::{self, Dataset};
use crate::results::LatencyCell;
use crate::sampling::{MOTION_POINTS, equally_spaced_indices};
use evtac_events::manifest::TrialMeta;
use evtac_learn::Model;
use evtac_online::Estimator;
use evtac_repr::ReprKind;
use std::time::Instant;

/// Errors of the latency study.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A recording could not be read.
    #[error(transparent)]
    Dataset(#[from] dataset::Error),
    /// The estimator failed.
    #[error("trial `{trial}`: {source}")]
    Estimator {
        /// The trial.
        trial: String,
        /// The cause.
        source: evtac_online::EstimatorError,
    },
}

/// Measures `model` (of representation `name`) at `interval_ms` over `trials`.
pub fn measure(
    ds: &Dataset,
    trials: &[&TrialMeta],
    name: ReprKind,
    model: &Model,
    interval_ms: u32,
) -> Result<LatencyCell, Error> {
    evtac_learn::flush_denormals();
    let step = i64::from(interval_ms.max(1)) * 1000;
    let mut times_us = Vec::new();
    for meta in trials {
        let path = ds.dir.join(&meta.file);
        let (sensor, events) = dataset::read_full(&path)?;
        let failed = |source| Error::Estimator {
            trial: meta.trial.clone(),
            source,
        };
        let mut estimator = Estimator::for_model(model, sensor, step).map_err(failed)?;
        estimator.start_grid_at(meta.motion_start_us);
        let mut cursor = events.partition_point(|e| e.t <= meta.motion_start_us);
        let horizon = Some(meta.motion_start_us);
        estimator
            .process(&events[..cursor], horizon, Instant::now(), &mut |_| {})
            .map_err(failed)?;
        let mut trial_times = Vec::new();
        let mut t_k = meta.motion_start_us + step;
        while t_k <= meta.motion_end_us {
            let end = cursor + events[cursor..].partition_point(|e| e.t <= t_k);
            let mut record = |estimate: &evtac_online::Estimate| {
                std::hint::black_box(estimate);
                trial_times.push(estimate.processing.as_secs_f64() * 1e6);
            };
            estimator
                .process(&events[cursor..end], Some(t_k), Instant::now(), &mut record)
                .map_err(failed)?;
            cursor = end;
            t_k += step;
        }
        for i in equally_spaced_indices(trial_times.len(), MOTION_POINTS) {
            times_us.push(trial_times[i]);
        }
    }
    Ok(cell(name, interval_ms, times_us))
}

/// Summary statistics of measured times.
pub fn cell(name: ReprKind, interval_ms: u32, times_us: Vec<f64>) -> LatencyCell {
    let mut sorted = times_us.clone();
    sorted.sort_by(f64::total_cmp);
    let q = |p: f64| {
        if sorted.is_empty() {
            0.0
        } else {
            // Nearest-rank percentile.
            let rank = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
            sorted[rank - 1]
        }
    };
    let interval_us = f64::from(interval_ms) * 1000.0;
    LatencyCell {
        name,
        interval_ms,
        samples: sorted.len(),
        median_us: q(0.5),
        p99_us: q(0.99),
        max_us: sorted.last().copied().unwrap_or(0.0),
        over_interval: sorted.iter().filter(|&&t| t > interval_us).count(),
        over_10ms: sorted.iter().filter(|&&t| t > 10_000.0).count(),
        times_us,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_are_nearest_rank() {
        let c = cell(
            evtac_repr::ReprKind::Static,
            1,
            (1..=100).map(f64::from).collect(),
        );
        assert_eq!((c.median_us, c.p99_us, c.max_us), (50.0, 99.0, 100.0));
        assert_eq!(c.over_interval, 0);
        let c = cell(
            evtac_repr::ReprKind::Static,
            1,
            vec![500.0, 1500.0, 20_000.0],
        );
        assert_eq!((c.over_interval, c.over_10ms), (2, 1));
    }
}
