//! Latency as a robot sees it: a few of Experiment 1's test trials replayed at the pace they were
//! recorded, through the pipeline `evtac online --realtime` runs, idle and under load.
//!
//! The latency study ([`crate::latency`]) times the estimator's own work per estimate: it hands
//! over one step's events at a time and starts each step when the one before has finished, so no
//! step ever waits. A robot's estimates do wait: events come on the wall clock, and when a step
//! takes longer than the interval the steps after it queue behind it. This study measures that.
//!
//! What is timed, for every estimate of the replayed stretch (the first included):
//!
//! ```text
//! end to end = end of the estimate's forward pass  -  the instant its step's events were due
//! due(t_k)   = start + (t_k - t_0)
//! ```
//!
//! where `t_0` is the trial's motion onset, `t_k = t_0 + k * interval` its estimate times and
//! `start` the wall-clock instant the replay began. The events go through
//! [`evtac_online::input::Paced`] (one slice of the recording per interval, released when the
//! wall clock reaches its end, the *horizon* saying that the slice is complete) and
//! [`evtac_online::pipeline::run`] with its default settings (an ingestion and an estimation
//! thread, a bounded queue of 64 chunks between them, the estimation thread sleeping until a
//! chunk comes): the same code as `evtac online --realtime --slice-us <interval>`. So the figure
//! includes the estimator's processing, any wait in the queue behind earlier steps, the time the
//! operating system takes to wake each thread, and how late the replay's sleeping thread itself
//! woke to release the slice (what a live source's thread pays on a packet too). Measuring from
//! when the events were *due*, not from when the pipeline stamped them, is what makes every kind
//! of waiting count: a replay held up anywhere still owes its estimates by the recorded clock.
//! Excluded: transmission from the sensor to the host and decoding its packets (the events are
//! in memory), and handing the estimate to its consumer.
//!
//! The forward pass ends at `arrival + Estimate::latency`, where `arrival` is the pipeline's
//! stamp of the chunk that made the estimate final; the replay stamps each chunk as it hands it
//! to the pipeline, a few instructions before the pipeline's own stamp, and uses that. The
//! replay's `start` is stamped as its first read returns, just before [`Paced`] takes its own
//! origin, so if anything the figures here come out a fraction of a microsecond long.
//!
//! Each trial's events before motion onset go into the estimator first, untimed, as in the
//! latency study (the sensor is still then), with the estimate at `t_0`; the replay then starts
//! with one marker event at `t_0`, which the estimator drops (it is not after the estimate
//! already made) and which only pins the replay's clock to `t_0`. Paced slices end on multiples
//! of the interval, so the trial's times are shifted by less than an interval to put `t_0` on
//! one; every representation depends on time differences only.
//!
//! Only a few trials, and a bounded stretch of each motion phase, are replayed (see
//! [`extent`]): a replay at recorded pace takes as long as the events it replays, once per
//! (representation, interval, load). The trials replayed are the fastest-moving of those the
//! latency study uses (the busiest streams, and the shortest motions). The load
//! ([`Load::BusyThread`]) is one extra thread spinning on floating-point multiplies and adds,
//! started just before each trial's replay and stopped right after it (and in any case once the
//! replay has had [`LOAD_MARGIN`] more than the events' own duration).

use crate::dataset::{self, Dataset};
use crate::latency;
use crate::progress::Progress;
use evtac_events::Event;
use evtac_events::manifest::TrialMeta;
use evtac_learn::Model;
use evtac_online::input::{ChunkInfo, EventSource, MemorySource, Next, Paced};
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::{Estimator, Notice, Summary};
use evtac_repr::ReprKind;
use evtac_sim::Scale;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};
use std::time::{Duration, Instant};

/// How long the load may outlast the events it runs beside, at most: a bound on the load
/// thread should the replay fall far behind (it is normally stopped as the replay ends).
pub const LOAD_MARGIN: Duration = Duration::from_secs(10);

/// Events per chunk read from memory by the paced replay (it reads ahead; the slices it
/// releases are one interval each whatever this is).
const READ_CHUNK: usize = 4096;

pub use crate::paced_extent::{Extent, INTERVALS_MS, extent};
pub use crate::results::{Load, PacedLatencyCell};

/// Errors of the replay.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A recording could not be read, or the estimator could not be made or failed on the
    /// events before motion onset: the same failures as the processing-time study's.
    #[error(transparent)]
    Latency(#[from] latency::Error),
    /// The replay's pipeline failed.
    #[error("trial `{trial}`, replay at recorded pace: {source}")]
    Replay {
        /// The trial.
        trial: String,
        /// The cause (boxed: it is large, and rare).
        source: Box<pipeline::Error>,
    },
    /// The load thread could not be started.
    #[error("starting the load thread: {0}")]
    LoadThread(#[source] std::io::Error),
    /// An estimate came from no chunk the replay released (a bug in evtac).
    #[error("trial `{trial}`: the estimate at {t_us} us follows no released slice")]
    Unmatched {
        /// The trial.
        trial: String,
        /// The estimate's time.
        t_us: i64,
    },
}

/// The trials to replay: the `n` fastest-moving of `test`, in `test`'s order among equals.
pub fn chosen<'a>(test: &[&'a TrialMeta], n: usize) -> Vec<&'a TrialMeta> {
    let mut by_speed = test.to_vec();
    // Stable: equal speeds keep the split's order.
    by_speed.sort_by(|a, b| b.speed_deg_s.total_cmp(&a.speed_deg_s));
    by_speed.truncate(n);
    by_speed
}

/// Replays the [`chosen`] trials of `test` at recorded pace through each of `models`, at each of
/// [`INTERVALS_MS`], idle and under load; as much as [`extent`] says for `scale`.
pub fn measure(
    ds: &Dataset,
    test: &[&TrialMeta],
    models: &[(ReprKind, &Model)],
    scale: Scale,
    progress: &dyn Progress,
) -> Result<Vec<PacedLatencyCell>, Error> {
    // The events before onset are estimated on this thread.
    evtac_learn::flush_denormals();
    let extent = extent(scale);
    let trials = chosen(test, extent.trials);
    let mut recordings = Vec::with_capacity(trials.len());
    for meta in &trials {
        let (sensor, mut events) =
            dataset::read_full(&ds.dir.join(&meta.file)).map_err(latency::Error::Dataset)?;
        let end = meta
            .motion_end_us
            .min(meta.motion_start_us.saturating_add(extent.motion_ms * 1000));
        events.truncate(events.partition_point(|e| e.t <= end));
        recordings.push((*meta, sensor, events, end));
    }
    let cores = std::thread::available_parallelism().map_or(0, usize::from);
    let mut cells = Vec::new();
    for &(name, model) in models {
        for interval_ms in INTERVALS_MS {
            let step = i64::from(interval_ms) * 1000;
            for load in Load::ALL {
                progress.message(&format!(
                    "latency at recorded pace: {name}, {interval_ms} ms, {}",
                    load.name()
                ));
                let (mut times_us, mut replayed_us) = (Vec::new(), 0i64);
                for (meta, sensor, events, end) in &recordings {
                    let trial = || meta.trial.clone();
                    let t0 = meta.motion_start_us;
                    // Estimate times up to the end of the stretch.
                    let steps = (*end - t0).max(0) / step;
                    replayed_us += steps * step;
                    let shift = (step - t0.rem_euclid(step)) % step;
                    let (t0, last) = (t0 + shift, t0 + shift + steps * step);
                    let shifted = |e: &Event| Event {
                        t: e.t.saturating_add(shift),
                        ..*e
                    };
                    let onset = events.partition_point(|e| e.t + shift <= t0);
                    let before: Vec<Event> = events[..onset].iter().map(shifted).collect();
                    let motion: Vec<Event> = events[onset..]
                        .iter()
                        .map(shifted)
                        .take_while(|e| e.t <= last)
                        .collect();
                    let failed = |source| {
                        Error::Latency(latency::Error::Estimator {
                            trial: trial(),
                            source,
                        })
                    };
                    let mut estimator =
                        Estimator::for_model(model, *sensor, step).map_err(failed)?;
                    estimator.start_grid_at(t0);
                    estimator
                        .process(&before, Some(t0), Instant::now(), &mut |_| {})
                        .map_err(failed)?;
                    let span = Duration::from_micros(u64::try_from(last - t0).unwrap_or(0));
                    let rest = MemorySource::new(motion, READ_CHUNK);
                    let (times, _) = with_load(load, span + LOAD_MARGIN, || {
                        replay(rest, estimator, t0, step, steps as usize)
                    })?
                    .map_err(|e| match e {
                        ReplayError::Pipeline(source) => Error::Replay {
                            trial: trial(),
                            source,
                        },
                        ReplayError::Unmatched(t_us) => Error::Unmatched {
                            trial: trial(),
                            t_us,
                        },
                    })?;
                    times_us.extend(times);
                }
                let c = latency::cell(name, interval_ms, times_us);
                cells.push(PacedLatencyCell {
                    name,
                    interval_ms,
                    load,
                    trials: recordings.len(),
                    replayed_s: replayed_us as f64 * 1e-6,
                    cores,
                    samples: c.samples,
                    median_us: c.median_us,
                    p99_us: c.p99_us,
                    max_us: c.max_us,
                    late_share: if c.samples == 0 {
                        0.0
                    } else {
                        c.over_interval as f64 / c.samples as f64
                    },
                });
            }
        }
    }
    Ok(cells)
}

/// Why a replay failed.
#[derive(Debug)]
enum ReplayError {
    Pipeline(Box<pipeline::Error>),
    /// An estimate at this time came from no released slice.
    Unmatched(i64),
}

/// The replay's clock: when it started, and when each slice was handed to the pipeline.
#[derive(Debug, Default)]
struct Clock {
    origin: OnceLock<Instant>,
    /// (horizon, instant) per slice, in release order.
    released: Mutex<Vec<(i64, Instant)>>,
}

/// The recording as the paced replay reads it: the marker event at `t_0` alone (stamping the
/// replay's start as it is returned: [`Paced`] takes its origin right after this first read),
/// then `rest`.
struct Replay<S> {
    marker: Option<Event>,
    rest: S,
    clock: Arc<Clock>,
}

impl<S: EventSource> EventSource for Replay<S> {
    fn next_chunk(&mut self, out: &mut Vec<Event>, notify: &mut dyn FnMut(Notice)) -> Next {
        match self.marker.take() {
            Some(marker) => {
                out.clear();
                out.push(marker);
                let _ = self.clock.origin.set(Instant::now());
                Ok(Some(ChunkInfo::default()))
            }
            None => self.rest.next_chunk(out, notify),
        }
    }
}

/// Stamps each slice the paced replay releases, as it hands it to the pipeline.
struct Released<S> {
    paced: S,
    clock: Arc<Clock>,
}

impl<S: EventSource> EventSource for Released<S> {
    fn next_chunk(&mut self, out: &mut Vec<Event>, notify: &mut dyn FnMut(Notice)) -> Next {
        let next = self.paced.next_chunk(out, notify)?;
        if let Some(ChunkInfo {
            horizon: Some(horizon),
        }) = next
        {
            let at = Instant::now();
            self.clock
                .released
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .push((horizon, at));
        }
        Ok(next)
    }
}

/// Replays `rest` (the events after `t0`, shifted so that `t0` is a multiple of `step_us`) at
/// recorded pace through `estimator` (already fed up to `t0`, its estimate at `t0` made), in
/// slices of `step_us`; returns each estimate's end-to-end time in microseconds, in order, and
/// the pipeline's summary. `steps` sizes the buffers.
fn replay<S: EventSource + 'static>(
    rest: S,
    estimator: Estimator,
    t0: i64,
    step_us: i64,
    steps: usize,
) -> Result<(Vec<f64>, Summary), ReplayError> {
    let clock = Arc::new(Clock {
        origin: OnceLock::new(),
        released: Mutex::new(Vec::with_capacity(steps + 1)),
    });
    let marker = Event {
        t: t0,
        ..Event::default()
    };
    let source = Released {
        paced: Paced::new(
            Replay {
                marker: Some(marker),
                rest,
                clock: Arc::clone(&clock),
            },
            step_us,
        ),
        clock: Arc::clone(&clock),
    };
    let mut estimates = Vec::with_capacity(steps + 1);
    let summary = pipeline::run(source, estimator, &PipelineConfig::default(), |out| {
        if let Output::Estimate(e) = out {
            estimates.push((e.t_us, e.latency));
        }
        ControlFlow::Continue(())
    })
    .map_err(|e| ReplayError::Pipeline(Box::new(e)))?;
    let Some(&origin) = clock.origin.get() else {
        // Nothing was read, so nothing was estimated.
        return Ok((Vec::new(), summary));
    };
    let released = std::mem::take(
        &mut *clock
            .released
            .lock()
            .unwrap_or_else(PoisonError::into_inner),
    );
    let times = end_to_end_us(origin, t0, &released, &estimates).map_err(ReplayError::Unmatched)?;
    Ok((times, summary))
}

/// End-to-end times in microseconds of `estimates` (time, `Estimate::latency`) of a replay
/// that started at `origin` (event time `t0`) and released slices at `released` (horizon,
/// instant, in order): the forward pass ended `latency` after the release of the first slice
/// whose horizon reaches the estimate's time, and the estimate's events were due at
/// `origin + (t - t0)`. Err: the time of an estimate that no slice reaches.
fn end_to_end_us(
    origin: Instant,
    t0: i64,
    released: &[(i64, Instant)],
    estimates: &[(i64, Duration)],
) -> Result<Vec<f64>, i64> {
    estimates
        .iter()
        .map(|&(t, latency)| {
            let i = released.partition_point(|&(horizon, _)| horizon < t);
            let &(_, at) = released.get(i).ok_or(t)?;
            let due = origin + Duration::from_micros(u64::try_from(t - t0).unwrap_or(0));
            Ok((at + latency).saturating_duration_since(due).as_secs_f64() * 1e6)
        })
        .collect()
}

/// Runs `f` under `load`: for [`Load::BusyThread`] beside a thread spinning on floating-point
/// work, started first and stopped as `f` returns (or after `bound`, whichever comes first).
fn with_load<T>(load: Load, bound: Duration, f: impl FnOnce() -> T) -> Result<T, Error> {
    match load {
        Load::Idle => Ok(f()),
        Load::BusyThread => {
            let stop = AtomicBool::new(false);
            let deadline = Instant::now() + bound;
            std::thread::scope(|scope| {
                let spinner = std::thread::Builder::new()
                    .name("evtac-load".into())
                    .spawn_scoped(scope, || spin(&stop, deadline))
                    .map_err(Error::LoadThread)?;
                let out = f();
                stop.store(true, Ordering::Relaxed);
                // `spin` cannot panic; the join only waits for it to see the flag.
                let _ = spinner.join();
                Ok(out)
            })
        }
    }
}

/// Floating-point multiplies and adds until `stop` or `deadline`. The values converge to 1 and
/// stay normal (no denormal slow path, so the load is the same on every machine's FPU).
fn spin(stop: &AtomicBool, deadline: Instant) {
    let mut x = [1.5f64, 2.5, 3.5, 4.5];
    while !stop.load(Ordering::Relaxed) && Instant::now() < deadline {
        // A few microseconds of work between looks at the flag and the clock.
        for _ in 0..2048 {
            for v in &mut x {
                *v = *v * 0.999_999_9 + 1e-7;
            }
        }
        x = std::hint::black_box(x);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_events::Resolution;
    use evtac_learn::{Parameters, Predictor};
    use evtac_repr::ReprConfig;

    fn meta(trial: &str, speed_deg_s: f64) -> TrialMeta {
        TrialMeta {
            trial: trial.into(),
            file: format!("{trial}.aedat4").into(),
            truth: None,
            direction_deg: 0.0,
            speed_deg_s,
            depth_mm: 3.0,
            total_deg: 20.0,
            motion_start_us: 0,
            motion_end_us: 1_000_000,
            stop_start_us: None,
            stop_end_us: None,
            stop_deg: None,
            group: None,
        }
    }

    #[test]
    fn the_fastest_trials_are_chosen_in_split_order_among_equals() {
        let (a, b, c, d) = (
            meta("a", 4.0),
            meta("b", 10.0),
            meta("c", 6.0),
            meta("d", 10.0),
        );
        let test = [&a, &b, &c, &d];
        let names =
            |n| -> Vec<String> { chosen(&test, n).iter().map(|m| m.trial.clone()).collect() };
        assert_eq!(names(2), ["b", "d"]);
        assert_eq!(names(3), ["b", "d", "c"]);
        assert_eq!(names(9).len(), 4);
    }

    #[test]
    fn percentiles_are_nearest_rank_and_late_means_over_the_interval() {
        // The cell's statistics are the latency study's (`latency::cell`), nearest rank.
        let c = latency::cell(ReprKind::Static, 1, (1..=100).map(f64::from).collect());
        assert_eq!((c.median_us, c.p99_us, c.max_us), (50.0, 99.0, 100.0));
        let c = latency::cell(ReprKind::Static, 1, vec![500.0, 1000.0, 1500.0, 20_000.0]);
        assert_eq!(c.over_interval, 2, "exactly the interval is not late");
    }

    #[test]
    fn end_to_end_counts_the_wait_behind_a_slow_step() {
        // A replay releasing each 1 ms slice on time, and an estimator that needs 0.2 ms per
        // step but 3.5 ms for step 3: steps 4 to 6 queue behind it. `latency` (from release to
        // the forward pass) holds the queueing; end to end must hold it too.
        let origin = Instant::now();
        let ms = |x: f64| Duration::from_secs_f64(x * 1e-3);
        let (t0, step) = (5000i64, 1000i64);
        let released: Vec<(i64, Instant)> = (1..=8)
            .map(|k| (t0 + k * step, origin + ms(k as f64)))
            .collect();
        let mut done = origin;
        let mut estimates = Vec::new();
        for (k, &(t, at)) in (1..).zip(&released) {
            let cost = if k == 3 { 3.5 } else { 0.2 };
            done = done.max(at) + ms(cost);
            estimates.push((t, done - at));
        }
        let e2e = end_to_end_us(origin, t0, &released, &estimates).unwrap();
        let expected = [200.0, 200.0, 3500.0, 2700.0, 1900.0, 1100.0, 300.0, 200.0];
        for (got, want) in e2e.iter().zip(expected) {
            assert!((got - want).abs() < 0.01, "{e2e:?}");
        }
        // A slice released late counts from when it was due, not from its release.
        let late = [(t0 + step, origin + ms(4.0))];
        let e2e = end_to_end_us(origin, t0, &late, &[(t0 + step, ms(0.2))]).unwrap();
        assert!((e2e[0] - 3200.0).abs() < 0.01, "{e2e:?}");
        // An estimate that no slice reaches is a bug, reported as such.
        assert_eq!(
            end_to_end_us(origin, t0, &late, &[(t0 + 2 * step, ms(0.2))]),
            Err(t0 + 2000)
        );
    }

    /// A source handing out one step of events at a time, stalling before step `stall_at`.
    struct Steps {
        events: Vec<Event>,
        pos: usize,
        edge: i64,
        step: i64,
        stall_at: i64,
        stall: Duration,
    }

    impl EventSource for Steps {
        fn next_chunk(&mut self, out: &mut Vec<Event>, _notify: &mut dyn FnMut(Notice)) -> Next {
            out.clear();
            if self.pos == self.events.len() {
                return Ok(None);
            }
            self.edge += self.step;
            if self.edge == self.stall_at {
                std::thread::sleep(self.stall);
            }
            let n = self.events[self.pos..].partition_point(|e| e.t <= self.edge);
            out.extend_from_slice(&self.events[self.pos..self.pos + n]);
            self.pos += n;
            Ok(Some(ChunkInfo {
                horizon: Some(self.edge),
            }))
        }
    }

    #[test]
    fn a_stalled_step_delays_every_estimate_due_during_the_stall() {
        let (t0, step) = (7000i64, 1000i64);
        // 30 ms of events every 100 us over the crop, none on a step's edge.
        let events: Vec<Event> = (0..300i64)
            .map(|i| Event {
                t: t0 + 50 + i * 100,
                x: (i * 37 % 240) as u16,
                y: (i * 91 % 240) as u16,
                polarity: i % 2 == 0,
            })
            .collect();
        let predictor = Predictor::new(&Parameters::init(0)).unwrap();
        let repr = ReprConfig::Static(Default::default());
        let mut estimator =
            Estimator::new(&repr, None, predictor, Resolution::new(240, 240), step).unwrap();
        estimator.start_grid_at(t0);
        estimator
            .process(&[], Some(t0), Instant::now(), &mut |_| {})
            .unwrap();
        // The step ending at t0 + 5 ms reaches the replay 20 ms late.
        let stall = Duration::from_millis(20);
        let source = Steps {
            events,
            pos: 0,
            edge: t0,
            step,
            stall_at: t0 + 5 * step,
            stall,
        };
        let (e2e, summary) = replay(source, estimator, t0, step, 30)
            .map_err(|e| format!("{e:?}"))
            .unwrap();
        assert_eq!(e2e.len(), 30, "one estimate per step: {e2e:?}");
        assert_eq!(
            summary.events_out_of_order, 1,
            "the marker at t0 never reaches the representation"
        );
        // The stall began after step 4 was released (at or after it was due), so the
        // estimates of steps 5.. were out no earlier than 20 ms after step 4 was due. Lower
        // bounds only: a slower machine can only add to them.
        for k in 5..=23 {
            let bound = (20 - (k - 4)) as f64 * 1000.0;
            assert!(
                e2e[k - 1] >= bound,
                "step {k}: {} < {bound} ({e2e:?})",
                e2e[k - 1]
            );
        }
    }

    #[test]
    fn the_load_thread_stops_with_the_work_or_at_its_bound() {
        let ran = with_load(Load::BusyThread, Duration::from_secs(60), || 7).unwrap();
        assert_eq!(ran, 7);
        assert_eq!(with_load(Load::Idle, Duration::ZERO, || 8).unwrap(), 8);
        // Never told to stop: the deadline ends it.
        spin(
            &AtomicBool::new(false),
            Instant::now() + Duration::from_millis(5),
        );
    }

    #[test]
    fn cells_round_trip_and_results_without_them_write_none() {
        let cell = PacedLatencyCell {
            name: ReprKind::Combined,
            interval_ms: 1,
            load: Load::BusyThread,
            trials: 2,
            replayed_s: 4.0,
            cores: 2,
            samples: 4000,
            median_us: 80.0,
            p99_us: 400.0,
            max_us: 2500.0,
            late_share: 0.001,
        };
        let json = serde_json::to_string(&cell).unwrap();
        assert!(json.contains("\"load\":\"busy-thread\""), "{json}");
        assert_eq!(
            serde_json::from_str::<PacedLatencyCell>(&json).unwrap(),
            cell
        );
        let text = include_str!("../../../docs/report-example/results.json");
        let mut r: crate::results::Results = serde_json::from_str(text).unwrap();
        // Results without the replay (older runs) write no key for it.
        r.paced_latency.clear();
        assert!(!serde_json::to_string(&r).unwrap().contains("paced_latency"));
        r.paced_latency.push(cell);
        let again: crate::results::Results =
            serde_json::from_str(&serde_json::to_string(&r).unwrap()).unwrap();
        assert_eq!(again.paced_latency, r.paced_latency);
    }
}
