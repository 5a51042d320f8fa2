//! [`StaticAccumulator`]: dv-processing's `dv::Accumulator`, reproduced bit for bit.
//!
//! Per pixel a float32 potential `V` (starting at the neutral potential) and the int64 time `T`
//! of its last event (starting at **0**, as in dv-processing). Per event, in float32:
//!
//! ```text
//! dt = t - T;  T = t
//! V  = (V - neutral) * expf(-(dt as f32) / tau_us) + neutral     (exponential)
//! V  = V >= neutral ? max(V - dt * rate, neutral) : min(V + dt * rate, neutral)   (linear)
//! V  = min(max(V + (ON or ignore ? eta : -eta), min), max)
//! ```
//!
//! Decay is lazy (a pixel decays only when it receives an event) unless synchronous decay is on,
//! in which case [`StaticAccumulator::synchronize`] (dv's `generateFrame`) decays every pixel to the
//! latest event's time. The exponential is glibc's `expf`, which is what dv-processing calls on
//! Linux, reproduced in [`crate::expf`] so that a batch of events computes its decay factors in
//! one vectorized loop ([`StaticAccumulator::accumulate`]); the differential tests in
//! `tests/dv_differential.rs` check the potentials bit for bit against dv-processing.

use crate::ReprError;
use crate::config::{AccumulatorParams, Decay, StaticConfig};
use crate::expf::{Flavor, expf, expf_slice};
use evtac_events::{Event, Resolution};

/// Events per batch of [`StaticAccumulator::update_batch`]: enough for the vectorized `expf`
/// and the prefetches to pay off, few enough that the batch's pixel state stays in L1.
pub(crate) const BATCH: usize = 64;

/// The exponential-decay (or linear / no-decay) potential accumulator of the static
/// representation, bit-for-bit equal to dv-processing 2.0.4's `dv::Accumulator`.
///
/// ```
/// use evtac_events::{Event, Resolution};
/// use evtac_repr::{StaticAccumulator, StaticConfig};
///
/// let mut acc = StaticAccumulator::new(Resolution::new(4, 4), &StaticConfig::default()).unwrap();
/// let e = |t| Event { t, x: 1, y: 2, polarity: true };
/// acc.accumulate(&[e(1_000), e(1_000)]).unwrap();
/// assert_eq!(acc.potential(1, 2), 0.3);
/// assert_eq!(acc.frame_value(acc.potential(1, 2)), 76); // rint(0.3 * 255) = 76
/// ```
#[derive(Debug, Clone)]
pub struct StaticAccumulator {
    resolution: Resolution,
    params: AccumulatorParams,
    potentials: Vec<f32>,
    times: Vec<i64>,
    highest_time: i64,
    map: FrameMap,
    flavor: Flavor,
}

/// dv-processing's float-to-8-bit mapping of `generateFrame` (OpenCV `convertTo(CV_8U, s, b)`):
/// `saturate(rint(v * s + b))` in float32 with ties to even, `s = 255 / (max - min)`,
/// `b = -min * s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameMap {
    scale: f32,
    offset: f32,
}

impl FrameMap {
    /// The mapping for potentials clamped to `[min, max]`.
    pub fn new(min: f32, max: f32) -> Self {
        // As dv calls OpenCV: range in float32, scale and offset in double, then handed to the
        // float32 conversion kernel.
        let scale = 255.0 / f64::from(max - min);
        let offset = -f64::from(min) * scale;
        Self {
            scale: scale as f32,
            offset: offset as f32,
        }
    }

    /// The 8-bit value of potential `v`.
    #[inline]
    pub fn value(&self, v: f32) -> u8 {
        // `as u8` saturates (and maps NaN to 0, which a finite potential never is).
        self.scaled(v).round_ties_even() as u8
    }

    /// `v * s + b` before rounding.
    #[inline]
    pub fn scaled(&self, v: f32) -> f32 {
        v * self.scale + self.offset
    }
}

impl StaticAccumulator {
    /// An accumulator over a `resolution` frame with the accumulation settings of `config`
    /// (its threshold fields are not used here).
    pub fn new(resolution: Resolution, config: &StaticConfig) -> Result<Self, ReprError> {
        config.validate()?;
        Ok(Self::with_params(resolution, config.accumulator_params()))
    }

    /// An accumulator with raw (already converted) parameters.
    pub fn with_params(resolution: Resolution, params: AccumulatorParams) -> Self {
        let n = resolution.pixels();
        Self {
            resolution,
            params,
            potentials: vec![params.neutral_potential; n],
            times: vec![0; n],
            highest_time: 0,
            map: FrameMap::new(params.min_potential, params.max_potential),
            flavor: Flavor::detect(),
        }
    }

    /// The frame size.
    pub fn resolution(&self) -> Resolution {
        self.resolution
    }

    /// The parameters in use.
    pub fn params(&self) -> &AccumulatorParams {
        &self.params
    }

    /// Adds events (coordinates inside the frame, times non-decreasing and not before earlier
    /// events). On error nothing of the slice is applied.
    pub fn accumulate(&mut self, events: &[Event]) -> Result<(), ReprError> {
        crate::check::check_events(events, Some(self.resolution), Some(self.highest_time))?;
        let width = u32::from(self.resolution.width);
        let mut pixels = [0u32; BATCH];
        let mut values = [0f32; BATCH];
        for batch in events.chunks(BATCH) {
            for (p, e) in pixels.iter_mut().zip(batch) {
                *p = u32::from(e.y) * width + u32::from(e.x);
            }
            self.update_batch(&pixels[..batch.len()], batch, &mut values);
        }
        Ok(())
    }

    /// Applies `events` (at most [`BATCH`], in time order, event `i` at pixel index
    /// `pixels[i]`) and writes each event's new potential into `values[i]`: the same as
    /// [`Self::update`] event by event, faster. Exponential decay runs in three passes: the
    /// decay exponents from the pixels' times, the decay factors in one vectorized `expf`
    /// ([`crate::expf`]), then the potentials; the result is the same as event by event, also
    /// when a pixel occurs twice in the batch (each pass keeps the events' order).
    ///
    /// # Panics
    /// When a pixel is outside the frame or the slices are shorter than `events`.
    #[inline]
    pub(crate) fn update_batch(&mut self, pixels: &[u32], events: &[Event], values: &mut [f32]) {
        let n = events.len();
        let (pixels, values) = (&pixels[..n], &mut values[..n]);
        if self.params.decay != Decay::Exponential {
            for ((&p, e), v) in pixels.iter().zip(events).zip(values.iter_mut()) {
                *v = self.update(p as usize, e.t, e.polarity);
            }
            return;
        }
        let p = self.params;
        let mut factors = [0f32; BATCH];
        let exponents = &mut factors[..n];
        for ((&pixel, e), x) in pixels.iter().zip(events).zip(exponents.iter_mut()) {
            let last = &mut self.times[pixel as usize];
            *x = -((e.t - *last) as f32) / p.decay_param;
            *last = e.t;
            // The potential is needed in the third pass.
            crate::prefetch::prefetch(&self.potentials, pixel as usize);
        }
        let mut decay = [0f32; BATCH];
        expf_slice(exponents, &mut decay, self.flavor);
        for (((&pixel, e), &f), out) in pixels.iter().zip(events).zip(&decay).zip(values) {
            let v = &mut self.potentials[pixel as usize];
            let n = p.neutral_potential;
            *v = clamp((*v - n) * f + n + contribution(&p, e.polarity), &p);
            *out = *v;
        }
        if let Some(last) = events.last() {
            self.highest_time = last.t;
        }
    }

    /// Applies one event at pixel index `pixel` (`y * width + x`) and returns the pixel's new
    /// potential. The caller guarantees time order; `pixel` must be inside the frame.
    ///
    /// # Panics
    /// When `pixel` is outside the frame.
    #[inline]
    pub fn update(&mut self, pixel: usize, t: i64, polarity: bool) -> f32 {
        let p = &self.params;
        let v = &mut self.potentials[pixel];
        let last = &mut self.times[pixel];
        *v = decay(p, *v, t - *last, self.flavor);
        *last = t;
        *v = clamp(*v + contribution(p, polarity), p);
        self.highest_time = t;
        *v
    }

    /// Hints the cache to load pixel `pixel`'s state (an event for it is coming).
    #[inline(always)]
    pub(crate) fn prefetch(&self, pixel: usize) {
        crate::prefetch::prefetch(&self.potentials, pixel);
        crate::prefetch::prefetch(&self.times, pixel);
    }

    /// Synchronous decay (what dv-processing's `generateFrame` does first): when synchronous
    /// decay is on, decays every pixel to the latest event's time and moves its `T` there; a
    /// no-op for lazy decay or [`Decay::None`].
    pub fn synchronize(&mut self) {
        if !self.params.synchronous_decay || self.params.decay == Decay::None {
            return;
        }
        let t = self.highest_time;
        let p = &self.params;
        for (v, last) in self.potentials.iter_mut().zip(self.times.iter_mut()) {
            *v = decay(p, *v, t - *last, self.flavor);
            *last = t;
        }
    }

    /// The time of the latest event applied (0 before any).
    pub fn highest_time(&self) -> i64 {
        self.highest_time
    }

    /// All potentials, row-major.
    pub fn potentials(&self) -> &[f32] {
        &self.potentials
    }

    /// The potential at `(x, y)`.
    ///
    /// # Panics
    /// When `(x, y)` is outside the frame.
    pub fn potential(&self, x: u16, y: u16) -> f32 {
        self.potentials[usize::from(y) * usize::from(self.resolution.width) + usize::from(x)]
    }

    /// The 8-bit value `generateFrame` gives a potential (see [`FrameMap`]).
    #[inline]
    pub fn frame_value(&self, v: f32) -> u8 {
        self.map.value(v)
    }

    /// The 8-bit mapping of this accumulator.
    pub fn frame_map(&self) -> FrameMap {
        self.map
    }

    /// Writes the 8-bit frame of the current potentials into `out` (row-major), without the
    /// synchronous decay step (call [`Self::synchronize`] first to mirror `generateFrame`).
    ///
    /// # Panics
    /// When `out` is not exactly one frame long.
    pub fn frame_into(&self, out: &mut [u8]) {
        assert_eq!(out.len(), self.potentials.len(), "frame buffer length");
        for (o, &v) in out.iter_mut().zip(&self.potentials) {
            *o = self.frame_value(v);
        }
    }

    /// dv-processing's `generateFrame()`: synchronous decay (if on), then the 8-bit frame.
    pub fn generate_frame(&mut self) -> Vec<u8> {
        self.synchronize();
        let mut out = vec![0; self.potentials.len()];
        self.frame_into(&mut out);
        out
    }

    /// Back to the initial state (neutral potentials, `T = 0`).
    pub fn reset(&mut self) {
        self.potentials.fill(self.params.neutral_potential);
        self.times.fill(0);
        self.highest_time = 0;
    }
}

/// One event's contribution: `+eta` for ON events (or every event with ignored polarity),
/// `-eta` for OFF events.
#[inline(always)]
fn contribution(p: &AccumulatorParams, polarity: bool) -> f32 {
    // The sign bit set from the polarity rather than chosen by a branch: polarities arrive
    // as good as random, and a mispredicted branch per event cost more than the rest of the
    // potential's update (negation is exact, so the value is the same).
    let off = !(p.ignore_polarity || polarity);
    f32::from_bits(p.eta.to_bits() ^ (u32::from(off) << 31))
}

/// dv-processing's clamp to `[min, max]`. Written as two comparisons rather than
/// `max(min).min(max)`: the same result for every potential that can occur (never NaN, never
/// -0: `x + c` with `c != 0` rounds an exact zero to +0), in fewer instructions than the
/// NaN-aware `f32::max`/`f32::min`, and no panic on unvalidated parameters as `f32::clamp` would.
#[inline(always)]
fn clamp(v: f32, p: &AccumulatorParams) -> f32 {
    let v = if v < p.min_potential {
        p.min_potential
    } else {
        v
    };
    if v > p.max_potential {
        p.max_potential
    } else {
        v
    }
}

/// One decay step of `dt` microseconds, exactly as dv-processing computes it.
#[inline]
fn decay(p: &AccumulatorParams, v: f32, dt: i64, flavor: Flavor) -> f32 {
    match p.decay {
        Decay::Exponential => {
            let n = p.neutral_potential;
            (v - n) * expf(-(dt as f32) / p.decay_param, flavor) + n
        }
        Decay::Linear => {
            let n = p.neutral_potential;
            let step = dt as f32 * p.decay_param;
            if v >= n {
                (v - step).max(n)
            } else {
                (v + step).min(n)
            }
        }
        Decay::None => v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(t: i64, x: u16, y: u16, polarity: bool) -> Event {
        Event { t, x, y, polarity }
    }

    #[test]
    fn first_event_decays_from_time_zero_and_off_clamps_at_min() {
        let mut acc =
            StaticAccumulator::new(Resolution::new(2, 2), &StaticConfig::default()).unwrap();
        acc.accumulate(&[ev(5, 0, 0, false), ev(7, 1, 0, true)])
            .unwrap();
        assert_eq!(acc.potential(0, 0), 0.0);
        assert_eq!(acc.potential(1, 0), 0.15);
        acc.accumulate(&[ev(500_007, 1, 0, true)]).unwrap();
        let expected = 0.15f32 * (-0.5f32).exp() + 0.15;
        assert_eq!(acc.potential(1, 0), expected);
    }

    #[test]
    fn u8_rounding_is_ties_to_even() {
        let acc = StaticAccumulator::new(Resolution::new(1, 1), &StaticConfig::default()).unwrap();
        // 0.3 * 255 in f32 is 76.5 exactly after rounding of the product.
        assert_eq!(acc.frame_value(0.3), 76);
        assert_eq!(acc.frame_value(2.0), 255);
        assert_eq!(acc.frame_value(-1.0), 0);
        assert_eq!(acc.frame_map().scaled(0.3), 76.5);
    }

    #[test]
    fn bad_events_are_rejected_whole() {
        let mut acc =
            StaticAccumulator::new(Resolution::new(2, 2), &StaticConfig::default()).unwrap();
        let err = acc
            .accumulate(&[ev(1, 0, 0, true), ev(2, 2, 0, true)])
            .unwrap_err();
        assert!(matches!(
            err,
            ReprError::EventOutOfFrame { index: 1, x: 2, .. }
        ));
        assert_eq!(acc.potential(0, 0), 0.0);
        let err = acc
            .accumulate(&[ev(3, 0, 0, true), ev(2, 1, 0, true)])
            .unwrap_err();
        assert!(matches!(
            err,
            ReprError::EventOutOfOrder {
                index: 1,
                t: 2,
                previous: 3
            }
        ));
    }

    proptest::proptest! {
        /// The batched update (vectorized decay factors) against the event-by-event one, with
        /// pixels repeated within a batch and gaps long enough for `expf`'s special path.
        #[test]
        fn batches_equal_event_by_event_updates(
            steps in proptest::collection::vec(
                (0u32..6, 0i64..3_000_000, proptest::bool::ANY),
                0..300,
            ),
            tau_ms in 0.01f64..2_000.0,
            linear in proptest::bool::ANY,
        ) {
            let config = StaticConfig {
                tau_ms,
                decay: if linear { Decay::Linear } else { Decay::Exponential },
                ..StaticConfig::default()
            };
            let res = Resolution::new(3, 2);
            let (mut batched, mut single) = (
                StaticAccumulator::new(res, &config).unwrap(),
                StaticAccumulator::new(res, &config).unwrap(),
            );
            let mut t = 0;
            let events: Vec<Event> = steps
                .iter()
                .map(|&(p, gap, polarity)| {
                    // Mostly short gaps, some very long ones.
                    t += if gap % 7 == 0 { gap * 1_000 } else { gap % 5_000 };
                    ev(t, (p % 3) as u16, (p / 3) as u16, polarity)
                })
                .collect();
            batched.accumulate(&events).unwrap();
            for e in &events {
                single.update(usize::from(e.y) * 3 + usize::from(e.x), e.t, e.polarity);
            }
            let bits = |a: &StaticAccumulator| {
                a.potentials().iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            };
            proptest::prop_assert_eq!(bits(&batched), bits(&single));
        }
    }

    #[test]
    fn synchronous_decay_moves_every_pixel() {
        let cfg = StaticConfig {
            synchronous_decay: true,
            ..StaticConfig::default()
        };
        let mut acc = StaticAccumulator::new(Resolution::new(2, 1), &cfg).unwrap();
        acc.accumulate(&[ev(0, 0, 0, true), ev(1_000_000, 1, 0, true)])
            .unwrap();
        assert_eq!(acc.potential(0, 0), 0.15);
        acc.synchronize();
        assert_eq!(acc.potential(0, 0), 0.15 * (-1.0f32).exp());
    }
}
