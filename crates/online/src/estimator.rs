//! The estimation core, single-threaded: events in, an estimate at every grid time out.
//!
//! [`Estimator`] is what the estimation thread runs, and also what an offline check or a
//! benchmark can drive directly. Per chunk it crops events to the 240x240 region of interest,
//! hands them to the representation and applies at once those that belong to the next grid
//! time (`FeatureExtractor::push_and_prepare`); for every grid time that the chunk makes final
//! it advances the representation to that time, runs the MLP, and stamps the latency. Then,
//! before the next chunk, it does the work of the next grid time that is already known: the
//! window drops the events that will have left it, and a deferred accumulator (the combined
//! representation's, see `FeatureExtractor::deferring_accumulation`) takes them. Nothing on
//! this path allocates once the buffers have grown to the largest chunk seen.
//!
//! Two times come with every estimate. Its *latency* runs from the arrival of the chunk that
//! made it final to the end of the forward pass, so it includes any wait in a queue before the
//! estimator. Its *processing time* is the estimator's own work for it, and nothing else: every
//! moment spent in [`Estimator::process`] (and [`Estimator::finish`]) is charged to the next
//! estimate to come out, apart from handing estimates over (`emit`). That is the chunks'
//! cropping and representation updates since the previous estimate, the work done ahead of it
//! once the previous estimate was out, advancing to its time and the MLP. It is what a replay
//! as fast as possible can report, where the reader runs ahead and queueing is not latency.
//!
//! The MLP runs as a [`StreamingPredictor`]: its first layer is updated from the pooled cells
//! that changed since the previous estimate (a few dozen of 900 per millisecond), with the
//! same results as a full forward pass. Reading the whole first layer (0.9 MB) for every
//! estimate also pushed the representation's state out of the 1 MB L2 cache before the next
//! interval's events (combined at 3 M events/s in 1 ms packets: 70-74 -> 63-65 us median in
//! interleaved runs; at 300 k events/s the whole estimate's cost about halves,
//! `benches/latency.rs`).

use crate::frames::{FrameCapture, FrameSet};
use crate::latency::LatencyStats;
use crate::schedule::{self, Schedule};
use evtac_events::{Event, Resolution, Roi};
use evtac_filters::{Chain, Filter};
use evtac_learn::{Model, Predictor, StreamingPredictor};
use evtac_repr::{CROP, FeatureExtractor, Mask, ReprConfig, SensorTooSmall};
use std::time::{Duration, Instant};

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The sensor is smaller than the 240x240 region of interest.
    #[error(transparent)]
    SensorTooSmall(#[from] SensorTooSmall),
    /// The estimate interval is invalid.
    #[error(transparent)]
    Schedule(#[from] schedule::Error),
    /// The representation rejected its settings or its input (a bug in evtac when it happens
    /// mid-stream: events are cropped and put in time order before they reach it).
    #[error("representation: {0}")]
    Representation(#[from] evtac_repr::ReprError),
    /// Frames were asked for after events had been processed (the representation would have
    /// to start over).
    #[error("frames must be asked for before the first events are processed")]
    FramesTooLate,
    /// Frames were asked for from a model of a real-valued representation (time surface,
    /// histogram, voxel grid): the logged frames are binary images of the paper's kinds.
    #[error(
        "the model's {kind} representation is real-valued: its frames are not logged as binary \
         images (--mcap-frames takes static, dynamic, combined, stacked and late models; \
         `evtac represent --what frames` writes a {kind}'s frames)"
    )]
    FramesNotBinary {
        /// The representation's kind.
        kind: &'static str,
    },
}

/// One estimate of the contact angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The grid time the estimate is for: it reflects every event with `t <= t_us` and no other
    /// (`t < t_us` for the real-valued kinds, evaluated at tonic's slice ends as offline:
    /// `evtac_repr::dense`).
    pub t_us: i64,
    /// Pitch in degrees.
    pub pitch_deg: f32,
    /// Roll in degrees.
    pub roll_deg: f32,
    /// From the arrival of the chunk that made `t_us` final to the end of the forward pass (see
    /// `docs/online.md`).
    pub latency: Duration,
    /// The estimator's own work for this estimate: its time in [`Estimator::process`] since the
    /// previous estimate was handed over, up to the end of the forward pass (see the module
    /// docs). Never includes waiting.
    pub processing: Duration,
}

/// Counters kept by the estimator.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Events received (whole sensor).
    pub events: u64,
    /// Events inside the region of interest.
    pub events_in_roi: u64,
    /// Events skipped because they were older than one already received.
    pub events_out_of_order: u64,
    /// Events the filters removed ([`Estimator::filter_with`]).
    pub events_filtered: u64,
    /// Event time of the first and the latest event.
    pub span_us: Option<(i64, i64)>,
}

/// The single-threaded estimation core.
pub struct Estimator {
    extractor: FeatureExtractor,
    predictor: StreamingPredictor,
    roi: Roi,
    schedule: Schedule,
    /// Cropped events of the current chunk at its front (reused, never shrunk).
    crop: Vec<Event>,
    /// Events older than this are out of order: the latest event time, or one past the last
    /// estimate time (whichever is later).
    floor: i64,
    counters: Counters,
    stats: LatencyStats,
    processing: LatencyStats,
    /// Work done since the previous estimate was handed over, in calls that have returned.
    carried: Duration,
    /// The representation and mask, for [`Self::capture_frames`].
    representation: ReprConfig,
    mask: Option<Mask>,
    /// Frames taken at a lower rate than the estimates, when asked for.
    frames: Option<FrameCapture>,
    /// The event filters every event goes through before the crop, when the model's features
    /// were made from filtered events ([`Self::filter_with`]).
    filter: Option<Chain>,
}

impl std::fmt::Debug for Estimator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Estimator")
            .field("roi", &self.roi)
            .field("schedule", &self.schedule)
            .field("counters", &self.counters)
            .finish_non_exhaustive()
    }
}

impl Estimator {
    /// An estimator running `model` on a sensor of `sensor` pixels, estimating every
    /// `interval_us` microseconds of event time.
    pub fn for_model(model: &Model, sensor: Resolution, interval_us: i64) -> Result<Self, Error> {
        Self::new(
            &model.repr_config(),
            model.mask(),
            model.predictor.clone(),
            sensor,
            interval_us,
        )
    }

    /// An estimator for a sensor of `sensor` pixels, cropped to its centered 240x240 region,
    /// with the given representation, no-contact mask and predictor, estimating every
    /// `interval_us` microseconds of event time.
    pub fn new(
        representation: &ReprConfig,
        mask: Option<&Mask>,
        predictor: Predictor,
        sensor: Resolution,
        interval_us: i64,
    ) -> Result<Self, Error> {
        let roi = evtac_repr::centered_crop(sensor)?;
        // Where the representation allows it (the combined one), the accumulator takes events
        // as they leave the window, in the work done ahead of each estimate.
        let extractor = FeatureExtractor::new(std::slice::from_ref(representation), CROP, mask)?
            .deferring_accumulation();
        let schedule = Schedule::new(interval_us)?;
        let interval = Duration::from_micros(interval_us.unsigned_abs());
        Ok(Self {
            extractor,
            predictor: StreamingPredictor::new(predictor),
            roi,
            schedule,
            crop: Vec::new(),
            floor: i64::MIN,
            counters: Counters::default(),
            stats: LatencyStats::new(interval),
            processing: LatencyStats::new(interval),
            carried: Duration::ZERO,
            representation: *representation,
            mask: mask.cloned(),
            frames: None,
            filter: None,
        })
    }

    /// Also takes the representation's binary frames every `every_us` of event time, at the
    /// estimate times (see [`crate::frames`]); collected with [`Self::take_frames`]. The
    /// accumulator is then no longer deferred (its potentials are read for the static frame):
    /// the same estimates, a little more work per estimate. Before the first chunk only.
    pub fn capture_frames(&mut self, every_us: i64) -> Result<(), Error> {
        if self.counters.events > 0 {
            return Err(Error::FramesTooLate);
        }
        if self.representation.dense_part().is_some() {
            return Err(Error::FramesNotBinary {
                kind: self.representation.kind_name(),
            });
        }
        self.extractor = FeatureExtractor::new(
            std::slice::from_ref(&self.representation),
            CROP,
            self.mask.as_ref(),
        )?;
        self.frames = Some(FrameCapture::new(every_us));
        Ok(())
    }

    /// The frame sets taken since the last call (none unless [`Self::capture_frames`]).
    pub fn take_frames(&mut self) -> Vec<FrameSet> {
        self.frames
            .as_mut()
            .map(FrameCapture::take)
            .unwrap_or_default()
    }

    /// Puts the first estimate at `t_us` (then one every interval) instead of at the first
    /// multiple of the interval at or after the first event. No effect once the first event
    /// has been processed. Events before `t_us` are applied with no estimate for them.
    pub fn start_grid_at(&mut self, t_us: i64) {
        self.schedule.start_at(t_us);
    }

    /// The crop applied to incoming events.
    /// Sends every event through `filter` (on the full sensor, before the crop) first, as the
    /// model's training recordings went through it.
    pub fn filter_with(&mut self, filter: Chain) {
        self.filter = Some(filter);
    }

    pub fn roi(&self) -> Roi {
        self.roi
    }

    /// Latency statistics so far.
    pub fn stats(&self) -> &LatencyStats {
        &self.stats
    }

    /// Processing-time statistics so far (see [`Estimate::processing`]); *late* counts
    /// estimates whose processing alone took longer than the interval.
    pub fn processing_stats(&self) -> &LatencyStats {
        &self.processing
    }

    /// Event counters so far.
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// Takes one chunk of events (full-sensor coordinates, time order) that arrived at
    /// `arrival`, and emits every estimate it makes final. `horizon`, when the source knows it,
    /// says that every event with `t <= horizon` has been delivered.
    pub fn process(
        &mut self,
        events: &[Event],
        horizon: Option<i64>,
        arrival: Instant,
        emit: &mut impl FnMut(&Estimate),
    ) -> Result<(), Error> {
        let mut started = Instant::now();
        // Cropped without a branch per event (whether an event falls in the crop is as good as
        // random to the branch predictor): every accepted event is written at `kept`, which
        // only moves on for those inside. The buffer keeps its largest length, so no chunk
        // pays for clearing it.
        if self.crop.len() < events.len() {
            self.crop.resize(events.len(), Event::default());
        }
        let Roi { x0, y0, size } = self.roi;
        let mut kept = 0;
        let mut first = None;
        let mut latest = None;
        for &e in events {
            if e.t < self.floor {
                self.counters.events_out_of_order += 1;
                continue;
            }
            self.floor = e.t;
            first.get_or_insert(e.t);
            latest = Some(e.t);
            // A removed event still proves that time has moved on (the grid above), only the
            // representation does not see it.
            if let Some(filter) = &mut self.filter
                && !filter.keep(&e)
            {
                self.counters.events_filtered += 1;
                continue;
            }
            // Left of or above the crop wraps to past its size: the crop lies on a sensor of
            // at most 65535 columns and rows, so `x0 + width` stays below 65536.
            let (x, y) = (e.x.wrapping_sub(x0), e.y.wrapping_sub(y0));
            self.crop[kept] = Event { x, y, ..e };
            kept += usize::from((x < size.width) & (y < size.height));
        }
        let crop = &self.crop[..kept];
        self.counters.events += events.len() as u64;
        self.counters.events_in_roi += crop.len() as u64;
        if let (Some(first), Some(last)) = (first, latest) {
            // The first accepted event of the stream opens the grid.
            self.schedule.start(first);
            let first = self.counters.span_us.map_or(first, |(f, _)| f);
            self.counters.span_us = Some((first, last));
        }
        match self.schedule.next() {
            // Applies at once the events that belong to the next estimate (straight from the
            // crop buffer), so when a later chunk makes it final only that chunk's events are
            // left to do; the rest wait in the representation's queue.
            Some(next) => self.extractor.push_and_prepare(crop, next)?,
            None => self.extractor.push(crop)?,
        }
        // An event at `t` proves that every event before `t` has arrived; one at `t` itself
        // may still follow in the next chunk.
        let proven = latest.map_or(i64::MIN, |t| t.saturating_sub(1));
        let horizon = horizon.map_or(proven, |h| h.max(proven));
        self.estimate_until(horizon, arrival, &mut started, emit)?;
        if let Some(next) = self.schedule.next() {
            // Ahead of the next estimate, after this chunk's estimates are out: apply the
            // queued events that belong to it and let the windows drop what leaves them by
            // then (known now: the window reaches back past every event yet to come).
            self.extractor.prepare(next)?;
        }
        // The rest of this call is work for the next estimate.
        self.carried += started.elapsed();
        Ok(())
    }

    /// Ends the stream: emits the estimates up to the last event's time.
    pub fn finish(
        &mut self,
        arrival: Instant,
        emit: &mut impl FnMut(&Estimate),
    ) -> Result<(), Error> {
        let mut started = Instant::now();
        match self.counters.span_us {
            Some((_, last)) => self.estimate_until(last, arrival, &mut started, emit),
            None => Ok(()),
        }
    }

    /// Makes every estimate due by `horizon`. `started` is when the estimator's current stretch
    /// of work began: each estimate's processing time is the work carried over from earlier
    /// calls plus the time since then, and the next stretch starts once it is handed over.
    fn estimate_until(
        &mut self,
        horizon: i64,
        arrival: Instant,
        started: &mut Instant,
        emit: &mut impl FnMut(&Estimate),
    ) -> Result<(), Error> {
        while let Some(t) = self.schedule.pop_due(horizon) {
            self.extractor.advance_to(t)?;
            let [pitch_deg, roll_deg] = self.predictor.predict(self.extractor.features(0));
            let done = Instant::now();
            let latency = done.saturating_duration_since(arrival);
            let processing =
                std::mem::take(&mut self.carried) + done.saturating_duration_since(*started);
            self.stats.record(latency);
            self.processing.record(processing);
            // Later events must not reach back before an estimate already made.
            self.floor = self.floor.max(t.saturating_add(1));
            emit(&Estimate {
                t_us: t,
                pitch_deg,
                roll_deg,
                latency,
                processing,
            });
            if let Some(frames) = &mut self.frames {
                frames.at_estimate(t, &self.extractor, &self.representation, self.mask.as_ref());
            }
            // Handing the estimate over is not the estimator's work.
            *started = Instant::now();
        }
        Ok(())
    }
}
