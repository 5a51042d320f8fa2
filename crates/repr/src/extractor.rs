//! [`FeatureExtractor`]: the streaming engine that turns events into binary frames and pooled
//! features at sample times, for several representation configs in one pass.
//!
//! # How it works
//! Events are pushed in time order (any chunking) and wait in a queue; `advance_to(t_k)` applies
//! those with `t <= t_k`. Each applied event updates, once each:
//! - every distinct accumulator (configs with equal accumulation settings share one), whose new
//!   potential is thresholded by every static *plane* on it (one per distinct threshold rule and
//!   mask);
//! - every distinct sliding window (one per window length), whose new count is thresholded by
//!   every dynamic plane on it (one per count threshold).
//!
//! Then each window drops the events that left `(t_k - window, t_k]`. A plane pixel that flips
//! updates the outputs built on it (static, dynamic, or the OR of a static and a dynamic plane)
//! and their [`Pool8`] features. A sample therefore costs the events since the previous sample
//! (entering and leaving), never a full frame, and allocates nothing once buffers have grown.
//! Synchronous-decay accumulators are the exception: dv-processing decays every pixel when a
//! frame is read, so their planes are recomputed in full (`O(width x height)`) per sample.
//!
//! One shortcut, exact: a static plane that only feeds combined outputs whose dynamic part sets
//! a pixel at its first event in the window (`count_threshold` 0, the paper's setting) is not
//! thresholded per event. Every event enters the window, so right after it the output pixel is
//! set whatever the static bit; the static bit only shows once the pixel's last event has left
//! the window, and since the potential (lazy decay) has not changed since that event, it is
//! computed then, from the potential, when the dynamic pixel clears.
//!
//! # Deferred accumulation
//! That shortcut goes one step further on request ([`FeatureExtractor::deferring_accumulation`],
//! what the online estimator uses). If every static plane of an accumulator is such a lazy plane
//! and they are all read by one window, the potential is only ever read when a pixel's last
//! event leaves that window, and all of the pixel's events have left it by then. So the
//! accumulator can take each event as it *leaves* the window instead of when it arrives: per
//! pixel it sees the same events in the same order and computes the same potentials, only later.
//! The outputs are identical; the accumulator's work (the exponential decay per event, the
//! costliest step) moves from the events that just arrived to those leaving, which a live
//! estimator handles in [`FeatureExtractor::prepare`] ahead of the next sample. The potentials
//! themselves then lag by the window, so [`FeatureExtractor::potentials`] withholds them.
//!
//! # Edge cases, documented
//! - Before the first event, or for an empty stream, every output is the initial state:
//!   potentials at the neutral potential, counts 0, thresholded as usual (all zero with the
//!   defaults). Sample times before the first event are therefore valid.
//! - Sample times must be non-decreasing ([`ReprError::SampleTimeBackwards`]); equal times are
//!   allowed and give the same output.
//! - Events must be inside the frame ([`ReprError::EventOutOfFrame`]) and in non-decreasing time
//!   order across all pushes ([`ReprError::EventOutOfOrder`]); a rejected chunk is not applied
//!   at all.
//! - An event pushed after a sample time it precedes (`t <= t_k` already sampled) cannot change
//!   that sample: it is applied at the next `advance_to`. Push every event up to `t_k` before
//!   calling `advance_to(t_k)` for exact results; output is then the same for any chunking.
//!
//! # The real-valued kinds
//! Time surfaces, histograms and voxel grids ([`crate::dense`]) share nothing with the binary
//! planes: each such config gets its own [`DenseExtractor`], fed the same events and advanced
//! at the same sample times, with tonic's slice-end semantics (a sample at `t_k` sees the events
//! before it; see [`crate::dense`]). Their frames are real-valued and several channels deep, so
//! they are read with [`FeatureExtractor::frame_values_into`], not [`FeatureExtractor::frame`].

use crate::ReprError;
use crate::accumulator::{BATCH, StaticAccumulator};
use crate::combine::StaticThreshold;
use crate::config::{AccumulatorParams, ReprConfig};
use crate::dense::DenseExtractor;
use crate::mask::Mask;
use crate::pool::Pool8;
use crate::window::SlidingWindow;
use evtac_events::{Event, Resolution, Roi};
use std::collections::VecDeque;

struct AccSlot {
    params: AccumulatorParams,
    acc: StaticAccumulator,
    planes: Vec<usize>,
    /// Fed from its window as events leave it, not as they arrive (see "Deferred
    /// accumulation" in the module docs).
    deferred: bool,
}

struct WindowSlot {
    window: SlidingWindow,
    planes: Vec<usize>,
    /// The deferred accumulators this window feeds.
    deferred: Vec<usize>,
}

struct StaticPlane {
    acc: usize,
    rule: StaticThreshold,
    mask: Option<usize>,
    bits: Vec<u8>,
    outputs: Vec<usize>,
    /// Only feeds combined outputs whose dynamic part sets a pixel at its first event: an
    /// event then sets the output whatever the static bit, so the bit is not kept per event
    /// but computed from the potential when the dynamic pixel clears (see the module docs).
    lazy: bool,
}

impl StaticPlane {
    /// Whether pixel `p` of potential `v` is set in this plane: above the threshold and not
    /// masked.
    #[inline]
    fn is_on(&self, v: f32, p: usize, masks: &[Mask]) -> bool {
        self.rule.is_set(v) && !self.mask.is_some_and(|m| masks[m].is_masked(p))
    }
}

struct DynamicPlane {
    window: usize,
    count_threshold: u32,
    bits: Vec<u8>,
    outputs: Vec<usize>,
}

#[derive(Clone, Copy)]
enum Kind {
    Static(usize),
    Dynamic(usize),
    Combined(usize, usize),
    /// Both planes side by side (`Stacked` and `Late` configs): one [`Pool8`] over a frame twice
    /// as high, the static plane in the top half and the dynamic one below, so the pooled
    /// features are the static part's cells then the dynamic part's, in one slice.
    Stacked(usize, usize),
}

struct Output {
    kind: Kind,
    pool: Pool8,
}

/// Where config `i`'s output lives: among the binary outputs, or the real-valued extractors.
#[derive(Clone, Copy)]
enum Route {
    Binary(usize),
    Dense(usize),
}

/// Streaming representations at sample times, for one or more [`ReprConfig`]s at once.
///
/// ```
/// use evtac_events::{Event, Resolution};
/// use evtac_repr::{FeatureExtractor, ReprConfig};
///
/// let mut fx = FeatureExtractor::new(&[ReprConfig::default()], Resolution::new(240, 240), None)?;
/// let events: Vec<Event> = (0..100)
///     .map(|i| Event { t: i * 10, x: 5, y: 7, polarity: true })
///     .collect();
/// fx.push(&events)?;
/// fx.advance_to(500)?; // applies the events with t <= 500
/// assert_eq!(fx.features(0).len(), 900);
/// assert_eq!(fx.frame(0)[7 * 240 + 5], 1);
/// assert_eq!(fx.features(0)[0], 1.0 / 64.0);
/// # Ok::<(), evtac_repr::ReprError>(())
/// ```
pub struct FeatureExtractor {
    configs: Vec<ReprConfig>,
    resolution: Resolution,
    accs: Vec<AccSlot>,
    windows: Vec<WindowSlot>,
    splanes: Vec<StaticPlane>,
    dplanes: Vec<DynamicPlane>,
    outputs: Vec<Output>,
    denses: Vec<DenseExtractor>,
    /// One per config, in the configs' order.
    routes: Vec<Route>,
    masks: Vec<Mask>,
    pending: VecDeque<Event>,
    last_pushed: Option<i64>,
    sample_time: Option<i64>,
    /// The latest time given to [`Self::prepare`] or [`Self::advance_to`]: events up to it
    /// are applied, so no later sample may come before it.
    prepared: Option<i64>,
}

impl std::fmt::Debug for FeatureExtractor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FeatureExtractor")
            .field("configs", &self.configs)
            .field("resolution", &self.resolution)
            .field("accumulators", &self.accs.len())
            .field("windows", &self.windows.len())
            .field("pending", &self.pending.len())
            .field("sample_time", &self.sample_time)
            .finish()
    }
}

fn index_or_push<T>(
    items: &mut Vec<T>,
    same: impl Fn(&T) -> bool,
    make: impl FnOnce() -> T,
) -> usize {
    if let Some(i) = items.iter().position(same) {
        i
    } else {
        items.push(make());
        items.len() - 1
    }
}

impl FeatureExtractor {
    /// An extractor for `configs` over a `frame`-sized crop (sides multiples of 8), with an
    /// optional no-contact `mask` applied to the static part of every config.
    pub fn new(
        configs: &[ReprConfig],
        frame: Resolution,
        mask: Option<&Mask>,
    ) -> Result<Self, ReprError> {
        let masks = vec![mask; configs.len()];
        Self::new_with_masks(configs, frame, &masks)
    }

    /// As [`Self::new`] with one mask per config (e.g. a mask built with each config's own
    /// accumulator settings, evtac's choice for a tau grid: the paper does not say which settings
    /// its no-contact frame used).
    pub fn new_with_masks(
        configs: &[ReprConfig],
        frame: Resolution,
        masks: &[Option<&Mask>],
    ) -> Result<Self, ReprError> {
        if configs.is_empty() {
            return Err(ReprError::NoConfig);
        }
        if masks.len() != configs.len() {
            return Err(ReprError::MaskCount {
                masks: masks.len(),
                configs: configs.len(),
            });
        }
        // Validates the frame size for every output.
        Pool8::new(frame)?;
        let mut fx = Self {
            configs: configs.to_vec(),
            resolution: frame,
            accs: Vec::new(),
            windows: Vec::new(),
            splanes: Vec::new(),
            dplanes: Vec::new(),
            outputs: Vec::new(),
            denses: Vec::new(),
            routes: Vec::new(),
            masks: Vec::new(),
            pending: VecDeque::new(),
            last_pushed: None,
            sample_time: None,
            prepared: None,
        };
        let n = frame.pixels();
        for (config, mask) in configs.iter().zip(masks) {
            config.validate()?;
            if let Some(dense) = config.dense_part() {
                // The mask is the static part's; a real-valued kind has none.
                fx.routes.push(Route::Dense(fx.denses.len()));
                fx.denses.push(DenseExtractor::new(dense, frame)?);
                continue;
            }
            let i = fx.outputs.len();
            fx.routes.push(Route::Binary(i));
            let mask = match mask {
                Some(m) => {
                    if m.resolution() != frame {
                        return Err(ReprError::MaskSize {
                            mask_width: m.resolution().width,
                            mask_height: m.resolution().height,
                            width: frame.width,
                            height: frame.height,
                        });
                    }
                    Some(index_or_push(&mut fx.masks, |x| x == *m, || (*m).clone()))
                }
                None => None,
            };
            let splane = config.static_part().map(|s| {
                let params = s.accumulator_params();
                let acc = index_or_push(
                    &mut fx.accs,
                    |a| a.params == params,
                    || AccSlot {
                        params,
                        acc: StaticAccumulator::with_params(frame, params),
                        planes: Vec::new(),
                        deferred: false,
                    },
                );
                let rule = StaticThreshold::new(s);
                let plane = index_or_push(
                    &mut fx.splanes,
                    |p| p.acc == acc && p.rule == rule && p.mask == mask,
                    || StaticPlane {
                        acc,
                        rule,
                        mask,
                        bits: vec![0; n],
                        outputs: Vec::new(),
                        lazy: false,
                    },
                );
                if !fx.accs[acc].planes.contains(&plane) {
                    fx.accs[acc].planes.push(plane);
                }
                fx.splanes[plane].outputs.push(i);
                plane
            });
            let dplane = config.dynamic_part().map(|d| {
                let window_us = d.window_us();
                let window = index_or_push(
                    &mut fx.windows,
                    |w| w.window.window_us() == window_us,
                    || WindowSlot {
                        window: SlidingWindow::new(frame, window_us),
                        planes: Vec::new(),
                        deferred: Vec::new(),
                    },
                );
                let plane = index_or_push(
                    &mut fx.dplanes,
                    |p| p.window == window && p.count_threshold == d.count_threshold,
                    || DynamicPlane {
                        window,
                        count_threshold: d.count_threshold,
                        bits: vec![0; n],
                        outputs: Vec::new(),
                    },
                );
                if !fx.windows[window].planes.contains(&plane) {
                    fx.windows[window].planes.push(plane);
                }
                fx.dplanes[plane].outputs.push(i);
                plane
            });
            let kind = match (splane, dplane) {
                (Some(s), Some(d)) if config.frames() == 2 => Kind::Stacked(s, d),
                (Some(s), Some(d)) => Kind::Combined(s, d),
                (Some(s), None) => Kind::Static(s),
                (None, Some(d)) => Kind::Dynamic(d),
                (None, None) => unreachable!("a binary ReprConfig has a static or a dynamic part"),
            };
            let pooled = match kind {
                Kind::Stacked(..) => stacked_frame(frame)?,
                Kind::Static(_) | Kind::Dynamic(_) | Kind::Combined(..) => frame,
            };
            fx.outputs.push(Output {
                kind,
                pool: Pool8::new(pooled)?,
            });
        }
        for plane in &mut fx.splanes {
            plane.lazy = !fx.accs[plane.acc].params.synchronous_decay
                && plane.outputs.iter().all(|&o| match fx.outputs[o].kind {
                    Kind::Combined(_, d) => fx.dplanes[d].count_threshold == 0,
                    Kind::Static(_) | Kind::Dynamic(_) | Kind::Stacked(..) => false,
                });
        }
        fx.refresh_static_planes(false);
        Ok(fx)
    }

    /// The configs, in the order outputs are indexed.
    pub fn configs(&self) -> &[ReprConfig] {
        &self.configs
    }

    /// Number of configs (outputs).
    pub fn len(&self) -> usize {
        self.configs.len()
    }

    /// Always `false`: an extractor has at least one config.
    pub fn is_empty(&self) -> bool {
        self.configs.is_empty()
    }

    /// The frame size.
    pub fn resolution(&self) -> Resolution {
        self.resolution
    }

    /// Number of features of output `i`: `(width / 8) * (height / 8)` per pooled frame (900
    /// for 240x240), times [`ReprConfig::frames`] (1800 for stacked and late configs).
    ///
    /// # Panics
    /// When `i >= self.len()`.
    pub fn feature_len(&self, i: usize) -> usize {
        self.features(i).len()
    }

    /// The latest sample time given to [`Self::advance_to`], if any.
    pub fn sample_time(&self) -> Option<i64> {
        self.sample_time
    }

    /// Number of pushed events not yet applied (later than the latest sample time; at or after
    /// it for an extractor of real-valued kinds only, whose samples see the events before them).
    pub fn pending(&self) -> usize {
        match (self.binary(), self.denses.first()) {
            (false, Some(dense)) => dense.pending(),
            _ => self.pending.len(),
        }
    }

    /// Whether any output is binary. Without one, events go to the real-valued kinds'
    /// extractors alone, which check and queue them themselves: the binary queue would only be
    /// a copy of every event, drained unread.
    fn binary(&self) -> bool {
        !self.outputs.is_empty()
    }

    /// Queues events in crop coordinates, in time order (also after earlier pushes). The whole
    /// chunk is checked first: on error nothing is queued.
    pub fn push(&mut self, events: &[Event]) -> Result<(), ReprError> {
        if self.binary() {
            let (pending, last) = (&mut self.pending, &mut self.last_pushed);
            crate::check::queue_events(pending, last, self.resolution, events, None)?;
        }
        for dense in &mut self.denses {
            dense.push(events)?;
        }
        Ok(())
    }

    /// Queues events in full-sensor coordinates, cropping them with `roi` on the way (events
    /// outside it are dropped). `roi.size` must be the frame size.
    pub fn push_with_roi(&mut self, events: &[Event], roi: &Roi) -> Result<(), ReprError> {
        if self.binary() {
            let (pending, last) = (&mut self.pending, &mut self.last_pushed);
            crate::check::queue_events(pending, last, self.resolution, events, Some(roi))?;
        }
        for dense in &mut self.denses {
            dense.push_with_roi(events, roi)?;
        }
        Ok(())
    }

    /// Applies every queued event with `t <= t_k`, moves the windows to end at `t_k`, and
    /// updates every output. `t_k` must not be before the previous sample time (nor before a
    /// time given to [`Self::prepare`]).
    pub fn advance_to(&mut self, t_k: i64) -> Result<(), ReprError> {
        self.prepare(t_k)?;
        for dense in &mut self.denses {
            dense.advance_to(t_k)?;
        }
        self.refresh_static_planes(true);
        self.sample_time = Some(t_k);
        Ok(())
    }

    /// Does ahead of time the work that [`Self::advance_to`]`(t_next)` will do with the events
    /// queued so far: applies those with `t <= t_next` and lets the windows drop what leaves
    /// them by `t_next`. A live estimator calls it as events arrive, so that when `t_next`
    /// becomes final only the latest events are left to apply. The sample that follows is the
    /// same as without it (the end state does not depend on how the work was split); until
    /// then, [`Self::features`] and [`Self::frame`] show the partly advanced state. `t_next`
    /// must not be before the previous sample time or prepared time, and the next sample time
    /// must not be before `t_next`.
    ///
    /// ```
    /// use evtac_events::{Event, Resolution};
    /// use evtac_repr::{FeatureExtractor, ReprConfig};
    ///
    /// let frame = Resolution::new(240, 240);
    /// let events: Vec<Event> = (0..300)
    ///     .map(|i| Event { t: i * 5, x: (i % 240) as u16, y: 7, polarity: true })
    ///     .collect();
    /// let (mut eager, mut lazy) = (
    ///     FeatureExtractor::new(&[ReprConfig::default()], frame, None)?,
    ///     FeatureExtractor::new(&[ReprConfig::default()], frame, None)?,
    /// );
    /// for chunk in events.chunks(50) {
    ///     eager.push(chunk)?;
    ///     eager.prepare(1_000)?; // applies what has arrived, up to the next sample
    ///     lazy.push(chunk)?;
    /// }
    /// eager.advance_to(1_000)?;
    /// lazy.advance_to(1_000)?;
    /// assert_eq!(eager.features(0), lazy.features(0));
    /// # Ok::<(), evtac_repr::ReprError>(())
    /// ```
    pub fn prepare(&mut self, t_next: i64) -> Result<(), ReprError> {
        self.check_prepared(t_next)?;
        self.apply_through(&[], t_next);
        Ok(())
    }

    /// [`Self::push`] then [`Self::prepare`]`(t_next)`, with the same result and errors, but
    /// the events of `events` that `t_next` takes are applied straight from the slice when
    /// nothing earlier is queued, rather than copied into the queue first: what a live
    /// estimator calls per chunk.
    ///
    /// ```
    /// use evtac_events::{Event, Resolution};
    /// use evtac_repr::{FeatureExtractor, ReprConfig};
    ///
    /// let frame = Resolution::new(240, 240);
    /// let mut fx = FeatureExtractor::new(&[ReprConfig::default()], frame, None)?;
    /// let e = |t| Event { t, x: 1, y: 2, polarity: true };
    /// fx.push_and_prepare(&[e(500), e(1_000), e(1_500)], 1_000)?;
    /// assert_eq!(fx.pending(), 1); // the event after 1 000 waits for its sample
    /// # Ok::<(), evtac_repr::ReprError>(())
    /// ```
    pub fn push_and_prepare(&mut self, events: &[Event], t_next: i64) -> Result<(), ReprError> {
        if !self.binary() {
            self.push(events)?;
            return self.prepare(t_next);
        }
        self.last_pushed =
            crate::check::check_events(events, Some(self.resolution), self.last_pushed)?;
        for dense in &mut self.denses {
            dense.push(events)?;
        }
        if let Err(err) = self.check_prepared(t_next) {
            // As `push` then a failing `prepare`: the events stay queued.
            self.pending.extend(events);
            return Err(err);
        }
        self.apply_through(events, t_next);
        Ok(())
    }

    /// Accepts `t_k` as the latest prepared time unless it is before the previous one.
    fn check_prepared(&mut self, t_k: i64) -> Result<(), ReprError> {
        if let Some(previous) = self.prepared
            && t_k < previous
        {
            return Err(ReprError::SampleTimeBackwards { t: t_k, previous });
        }
        self.prepared = Some(t_k);
        Ok(())
    }

    /// Applies the queued events with `t <= t_k`, then those of `incoming` (checked, and after
    /// everything queued), queueing the rest, and moves the windows to end at `t_k`.
    fn apply_through(&mut self, incoming: &[Event], t_k: i64) {
        let n = self.pending.partition_point(|e| e.t <= t_k);
        let width = u32::from(self.resolution.width);
        let Self {
            accs,
            windows,
            splanes,
            dplanes,
            outputs,
            masks,
            pending,
            ..
        } = self;
        let (front, back) = pending.as_slices();
        let in_front = n.min(front.len());
        // Incoming events go straight in when nothing queued comes before them.
        let m = if n == pending.len() {
            incoming.partition_point(|e| e.t <= t_k)
        } else {
            0
        };
        for events in [&front[..in_front], &back[..n - in_front], &incoming[..m]] {
            for batch in events.chunks(BATCH) {
                apply_batch(
                    batch, width, accs, windows, splanes, dplanes, outputs, masks,
                );
            }
        }
        pending.drain(..n);
        pending.extend(&incoming[m..]);
        for slot in windows.iter_mut() {
            let WindowSlot {
                window,
                planes,
                deferred,
            } = slot;
            if deferred.is_empty() {
                window.expire_through(t_k, |pixel, count| {
                    clear_expired(planes, pixel, count, accs, splanes, dplanes, outputs, masks);
                });
                continue;
            }
            window.expire_batches_through::<BATCH>(t_k, |batch| {
                // The deferred accumulators take the events first: a pixel that clears has
                // then had all of its events applied (none of its events is left in the window,
                // so none follows in the batch).
                let mut pixels = [0u32; BATCH];
                let mut events = [Event::default(); BATCH];
                for ((p, e), x) in pixels.iter_mut().zip(&mut events).zip(batch) {
                    *p = x.entry.pixel;
                    e.t = x.entry.t;
                    e.polarity = x.entry.polarity;
                }
                let mut values = [0f32; BATCH];
                for &a in deferred.iter() {
                    let n = batch.len();
                    accs[a]
                        .acc
                        .update_batch(&pixels[..n], &events[..n], &mut values);
                }
                for x in batch {
                    let (pixel, count) = (x.entry.pixel, x.count);
                    clear_expired(planes, pixel, count, accs, splanes, dplanes, outputs, masks);
                }
            });
        }
    }

    /// Defers accumulation where the outputs allow it, for live use, and resets the extractor
    /// to its initial state. An accumulator whose static planes are only read when a pixel's
    /// last event leaves a window (combined outputs with `count_threshold` 0, one window
    /// length) then takes each event when it leaves that window instead of when it arrives:
    /// outputs and features are the same, but the work moves from [`Self::advance_to`] to
    /// [`Self::prepare`] calls that run ahead of the next sample. [`Self::potentials`] returns
    /// `None` for such outputs (their potentials lag by the window). See "Deferred
    /// accumulation" in the module docs.
    ///
    /// ```
    /// use evtac_events::{Event, Resolution};
    /// use evtac_repr::{FeatureExtractor, ReprConfig};
    ///
    /// // The paper's combined representation.
    /// let frame = Resolution::new(240, 240);
    /// let mut fx =
    ///     FeatureExtractor::new(&[ReprConfig::default()], frame, None)?.deferring_accumulation();
    /// assert_eq!(fx.deferred_accumulators(), 1);
    /// let e = |t| Event { t, x: 3, y: 4, polarity: true };
    /// fx.push(&[e(1_000), e(2_000), e(3_000)])?;
    /// fx.advance_to(3_000)?;
    /// assert!(fx.potentials(0).is_none());
    /// fx.advance_to(700_000)?; // all three left the 640 ms window: the static part holds
    /// assert_eq!(fx.frame(0)[4 * 240 + 3], 1);
    /// # Ok::<(), evtac_repr::ReprError>(())
    /// ```
    pub fn deferring_accumulation(mut self) -> Self {
        self.reset();
        let Self {
            accs,
            windows,
            splanes,
            dplanes,
            outputs,
            ..
        } = &mut self;
        for (a, slot) in accs.iter_mut().enumerate() {
            // The windows whose clearing reads the accumulator's planes; `lazy` planes only
            // feed combined outputs.
            let mut feeding = Vec::new();
            let mut all_lazy = true;
            for &sp in &slot.planes {
                all_lazy &= splanes[sp].lazy;
                for &o in &splanes[sp].outputs {
                    if let Kind::Combined(_, d) = outputs[o].kind
                        && !feeding.contains(&dplanes[d].window)
                    {
                        feeding.push(dplanes[d].window);
                    }
                }
            }
            if let (&[w], true) = (&feeding[..], all_lazy) {
                slot.deferred = true;
                windows[w].deferred.push(a);
            }
        }
        self
    }

    /// How many accumulators take their events as they leave a window (see
    /// [`Self::deferring_accumulation`]).
    pub fn deferred_accumulators(&self) -> usize {
        self.accs.iter().filter(|a| a.deferred).count()
    }

    /// Recomputes static planes in full from their accumulators: all of them (`sync_only`
    /// false, at construction and reset) or those on synchronous-decay accumulators, after
    /// their synchronous decay.
    fn refresh_static_planes(&mut self, sync_only: bool) {
        let Self {
            accs,
            splanes,
            dplanes,
            outputs,
            masks,
            ..
        } = self;
        for slot in accs.iter_mut() {
            if sync_only && !slot.params.synchronous_decay {
                continue;
            }
            slot.acc.synchronize();
            for &sp in &slot.planes {
                for (p, &v) in slot.acc.potentials().iter().enumerate() {
                    let on = splanes[sp].is_on(v, p, masks);
                    let plane = &mut splanes[sp];
                    if (plane.bits[p] != 0) != on {
                        plane.bits[p] = u8::from(on);
                        propagate(outputs, &splanes[sp].outputs, splanes, dplanes, p);
                    }
                }
            }
        }
    }

    /// The pooled features of output `i` at the latest sample time: `(width / 8) * (height / 8)`
    /// values, row-major over 8x8 cells, each the fraction of set pixels in its cell; for
    /// stacked and late configs ([`ReprConfig::frames`] 2) the static part's cells followed by
    /// the dynamic part's, twice as many.
    ///
    /// # Panics
    /// When `i >= self.len()`.
    ///
    /// For the real-valued kinds, their channels side by side (each channel's cells, channel
    /// after channel: [`DenseExtractor::features`]).
    pub fn features(&self, i: usize) -> &[f32] {
        match self.routes[i] {
            Route::Binary(o) => self.outputs[o].pool.features(),
            Route::Dense(d) => self.denses[d].features(),
        }
    }

    /// The binary frame (0/1 per pixel, row-major) of output `i` at the latest sample time; for
    /// stacked and late configs the static part's frame above the dynamic part's (twice the
    /// height).
    ///
    /// # Panics
    /// When `i >= self.len()`, or when output `i` is of a real-valued kind (time surface,
    /// histogram, voxel grid: [`ReprConfig::dense_part`]), whose frames are not binary: read
    /// those with [`Self::frame_values_into`].
    pub fn frame(&self, i: usize) -> &[u8] {
        match self.routes[i] {
            Route::Binary(o) => self.outputs[o].pool.frame(),
            Route::Dense(_) => panic!(
                "FeatureExtractor::frame: output {i} is a real-valued {} frame; read it with \
                 frame_values_into",
                self.configs[i].kind()
            ),
        }
    }

    /// The frame of output `i` as `f32` values into `out`, resized to
    /// [`Self::frame_values_len`]: a binary frame as 0 and 1, a real-valued kind's channels
    /// (`channels x height x width`, tonic's layout and values) otherwise.
    ///
    /// # Panics
    /// When `i >= self.len()`.
    pub fn frame_values_into(&self, i: usize, out: &mut Vec<f32>) {
        out.resize(self.frame_values_len(i), 0.0);
        match self.routes[i] {
            Route::Binary(o) => {
                for (v, &b) in out.iter_mut().zip(self.outputs[o].pool.frame()) {
                    *v = f32::from(b);
                }
            }
            Route::Dense(d) => {
                // The buffer has the length the extractor checks for.
                if let Err(err) = self.denses[d].frame_into(out) {
                    unreachable!("frame buffer sized by frame_values_len: {err}");
                }
            }
        }
    }

    /// The number of values [`Self::frame_values_into`] writes for output `i`: the pixels of
    /// its frame (twice the crop for stacked and late), times the channels of a real-valued
    /// kind.
    ///
    /// # Panics
    /// When `i >= self.len()`.
    pub fn frame_values_len(&self, i: usize) -> usize {
        match self.routes[i] {
            Route::Binary(o) => self.outputs[o].pool.frame().len(),
            Route::Dense(d) => self.denses[d].channels() * self.resolution.pixels(),
        }
    }

    /// The potential surface behind output `i` (static and combined configs), row-major;
    /// `None` for dynamic configs and for deferred accumulators
    /// ([`Self::deferring_accumulation`]).
    ///
    /// # Panics
    /// When `i >= self.len()`.
    pub fn potentials(&self, i: usize) -> Option<&[f32]> {
        let Route::Binary(o) = self.routes[i] else {
            return None;
        };
        match self.outputs[o].kind {
            Kind::Static(s) | Kind::Combined(s, _) | Kind::Stacked(s, _) => {
                let slot = &self.accs[self.splanes[s].acc];
                (!slot.deferred).then(|| slot.acc.potentials())
            }
            Kind::Dynamic(_) => None,
        }
    }

    /// The window counts behind output `i` (dynamic and combined configs), row-major.
    ///
    /// # Panics
    /// When `i >= self.len()`.
    pub fn counts(&self, i: usize) -> Option<&[u32]> {
        let Route::Binary(o) = self.routes[i] else {
            return None;
        };
        match self.outputs[o].kind {
            Kind::Dynamic(d) | Kind::Combined(_, d) | Kind::Stacked(_, d) => {
                Some(self.windows[self.dplanes[d].window].window.counts())
            }
            Kind::Static(_) => None,
        }
    }

    /// Back to the initial state (as just constructed), keeping every buffer's capacity: for
    /// reusing one extractor across trials.
    pub fn reset(&mut self) {
        for slot in &mut self.accs {
            slot.acc.reset();
        }
        for slot in &mut self.windows {
            slot.window.clear();
        }
        for plane in &mut self.splanes {
            plane.bits.fill(0);
        }
        for plane in &mut self.dplanes {
            plane.bits.fill(0);
        }
        for out in &mut self.outputs {
            out.pool.clear();
        }
        for dense in &mut self.denses {
            dense.reset();
        }
        self.pending.clear();
        self.last_pushed = None;
        self.sample_time = None;
        self.prepared = None;
        self.refresh_static_planes(false);
    }

    /// Feeds `events` (crop coordinates, time order) and visits the extractor at each of the
    /// non-decreasing `samples`, after `advance_to(t_k)`: `visit(k, &self)`. Events are pushed
    /// per sample, so nothing is copied in bulk.
    pub fn run(
        &mut self,
        events: &[Event],
        samples: &[i64],
        mut visit: impl FnMut(usize, &Self),
    ) -> Result<(), ReprError> {
        let mut cursor = 0;
        for (k, &t_k) in samples.iter().enumerate() {
            let end = cursor + events[cursor..].partition_point(|e| e.t <= t_k);
            self.push(&events[cursor..end])
                .map_err(|err| shift_index(err, cursor))?;
            cursor = end;
            self.advance_to(t_k)?;
            visit(k, self);
        }
        // Out-of-order events after the last sample are still an error.
        self.push(&events[cursor..])
            .map_err(|err| shift_index(err, cursor))
    }
}

/// Features of every config at every sample time: one `samples.len() x feature_len(i)`
/// row-major buffer per config. A convenience over [`FeatureExtractor::run`].
pub fn extract_features(
    configs: &[ReprConfig],
    frame: Resolution,
    mask: Option<&Mask>,
    events: &[Event],
    samples: &[i64],
) -> Result<Vec<Vec<f32>>, ReprError> {
    let mut fx = FeatureExtractor::new(configs, frame, mask)?;
    let mut out: Vec<Vec<f32>> = (0..configs.len())
        .map(|i| Vec::with_capacity(samples.len() * fx.feature_len(i)))
        .collect();
    fx.run(events, samples, |_, fx| {
        for (i, o) in out.iter_mut().enumerate() {
            o.extend_from_slice(fx.features(i));
        }
    })?;
    Ok(out)
}

fn shift_index(err: ReprError, offset: usize) -> ReprError {
    match err {
        ReprError::EventOutOfFrame {
            index,
            t,
            x,
            y,
            width,
            height,
        } => ReprError::EventOutOfFrame {
            index: index + offset,
            t,
            x,
            y,
            width,
            height,
        },
        ReprError::EventOutOfOrder { index, t, previous } => ReprError::EventOutOfOrder {
            index: index + offset,
            t,
            previous,
        },
        other => other,
    }
}

/// Applies a batch of at most [`BATCH`] events (time order, inside the frame) to every
/// accumulator and window, flipping plane pixels and their outputs. Within the batch all
/// accumulators go first and the windows after: the outputs only depend on the planes' final
/// bits, so the end state is the same as event by event.
#[allow(clippy::too_many_arguments)]
#[inline]
fn apply_batch(
    batch: &[Event],
    width: u32,
    accs: &mut [AccSlot],
    windows: &mut [WindowSlot],
    splanes: &mut [StaticPlane],
    dplanes: &mut [DynamicPlane],
    outputs: &mut [Output],
    masks: &[Mask],
) {
    let mut pixels = [0u32; BATCH];
    let pixels = &mut pixels[..batch.len()];
    for (p, e) in pixels.iter_mut().zip(batch) {
        *p = u32::from(e.y) * width + u32::from(e.x);
        // The whole batch's state is requested at once: the loads overlap.
        for slot in accs.iter().filter(|a| !a.deferred) {
            slot.acc.prefetch(*p as usize);
        }
        for slot in windows.iter() {
            slot.window.prefetch(*p as usize);
        }
    }
    let mut values = [0f32; BATCH];
    for slot in accs.iter_mut().filter(|a| !a.deferred) {
        slot.acc.update_batch(pixels, batch, &mut values);
        if slot.params.synchronous_decay {
            // Recomputed in full after the synchronous decay in `advance_to`.
            continue;
        }
        for &sp in &slot.planes {
            if splanes[sp].lazy {
                continue;
            }
            // First every event's new bit (no branches on data), then the flips. The rule and
            // mask are taken out of the plane once ([`StaticPlane::is_on`] per event measured
            // slower here).
            let (rule, mask) = (splanes[sp].rule, splanes[sp].mask.map(|m| &masks[m]));
            let mut bits = [false; BATCH];
            for ((on, &p), &v) in bits.iter_mut().zip(pixels.iter()).zip(&values) {
                *on = rule.is_set(v) && !mask.is_some_and(|m| m.is_masked(p as usize));
            }
            for (&p, &on) in pixels.iter().zip(&bits) {
                let p = p as usize;
                let plane = &mut splanes[sp];
                if (plane.bits[p] != 0) != on {
                    plane.bits[p] = u8::from(on);
                    propagate(outputs, &splanes[sp].outputs, splanes, dplanes, p);
                }
            }
        }
    }
    for slot in windows.iter_mut() {
        let mut counts = [0u32; BATCH];
        slot.window.add_batch(batch, pixels, &mut counts);
        for (&p, &count) in pixels.iter().zip(&counts) {
            let p = p as usize;
            for &dp in &slot.planes {
                // A plane pixel is `count > threshold`: one more event sets it exactly when
                // the count passes the threshold (no need to read the bit).
                if count - 1 == dplanes[dp].count_threshold {
                    dplanes[dp].bits[p] = 1;
                    propagate(outputs, &dplanes[dp].outputs, splanes, dplanes, p);
                }
            }
        }
    }
}

/// After an event at pixel `pixel` left a window, leaving `count` there: clears the pixel in
/// the window's dynamic `planes` whose threshold it fell to, and updates their outputs.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn clear_expired(
    planes: &[usize],
    pixel: u32,
    count: u32,
    accs: &[AccSlot],
    splanes: &mut [StaticPlane],
    dplanes: &mut [DynamicPlane],
    outputs: &mut [Output],
    masks: &[Mask],
) {
    let p = pixel as usize;
    for &dp in planes {
        // One event fewer clears the pixel exactly when the count falls to the threshold.
        if count == dplanes[dp].count_threshold {
            dplanes[dp].bits[p] = 0;
            let targets = &dplanes[dp].outputs;
            settle_lazy_static_bits(targets, outputs, splanes, accs, masks, p);
            propagate(outputs, targets, splanes, dplanes, p);
        }
    }
}

/// Before a dynamic pixel clears: gives the lazy static planes of the combined outputs in
/// `targets` their bit at pixel `p`, from the potential, which has not changed since the
/// pixel's last event (see the module docs).
fn settle_lazy_static_bits(
    targets: &[usize],
    outputs: &[Output],
    splanes: &mut [StaticPlane],
    accs: &[AccSlot],
    masks: &[Mask],
    p: usize,
) {
    for &o in targets {
        if let Kind::Combined(sp, _) = outputs[o].kind
            && splanes[sp].lazy
        {
            let v = accs[splanes[sp].acc].acc.potentials()[p];
            let on = splanes[sp].is_on(v, p, masks);
            splanes[sp].bits[p] = u8::from(on);
        }
    }
}

/// Recomputes pixel `p` of every output in `targets` from its planes after a plane flip.
#[inline]
fn propagate(
    outputs: &mut [Output],
    targets: &[usize],
    splanes: &[StaticPlane],
    dplanes: &[DynamicPlane],
    p: usize,
) {
    for &o in targets {
        let out = &mut outputs[o];
        match out.kind {
            // The output is the plane: it flipped too.
            Kind::Static(s) => out.pool.flip(p, splanes[s].bits[p] != 0),
            Kind::Dynamic(d) => out.pool.flip(p, dplanes[d].bits[p] != 0),
            Kind::Combined(s, d) => {
                out.pool
                    .set(p, splanes[s].bits[p] != 0 || dplanes[d].bits[p] != 0);
            }
            // Either plane may have flipped; `set` leaves the other half as it is.
            Kind::Stacked(s, d) => {
                let below = out.pool.frame().len() / 2;
                out.pool.set(p, splanes[s].bits[p] != 0);
                out.pool.set(below + p, dplanes[d].bits[p] != 0);
            }
        }
    }
}

/// The frame a stacked output pools: the crop twice as high (the static part above the
/// dynamic part), so that 8x8 cells never straddle the two.
fn stacked_frame(frame: Resolution) -> Result<Resolution, ReprError> {
    let height = frame
        .height
        .checked_mul(2)
        .ok_or(ReprError::FrameNotPoolable {
            width: frame.width,
            height: frame.height,
        })?;
    Ok(Resolution::new(frame.width, height))
}
