//! The representations the paper did not choose: time surfaces, polarity histograms and voxel
//! grids, real-valued frames of `C` channels, each pooled 8x8 per channel to `C x 900` features
//! on the 240x240 crop, incrementally at each sample time.
//!
//! The paper's related work names two families of static representation and picks one
//! (decaying integration, its accumulator) over time surfaces; the field's libraries (tonic,
//! event_utils) also feed networks polarity histograms and voxel grids. These kinds let a reader
//! ask whether the paper's binary frames beat them. Each follows tonic 1.7's functional transform
//! of the same name, so that a network trained on either sees the same numbers:
//! - [`TimeSurfaceConfig`]: per polarity, `exp(-(t_k - t_last) / tau)` at each pixel
//!   (`tonic.functional.to_timesurface_numpy` at its slice ends), or its binarized form, set
//!   where that value is above a threshold;
//! - [`HistogramConfig`]: event counts per polarity over the window before `t_k`
//!   (`to_frame_numpy` with `time_window`);
//! - [`VoxelGridConfig`]: `B` temporal bins over the window before `t_k`, each event split
//!   between its two nearest bins with signed polarity (`to_voxel_grid_numpy`).
//!
//! # Sample times: tonic's slice ends
//! tonic slices are half-open, `[start, end)`, and a time surface is evaluated at its slice's end
//! with the events before it. So a sample at `t_k` sees the events with **`t < t_k`** (an event
//! at exactly `t_k` waits for the next sample) and a window of `W` is **`[t_k - W, t_k)`**.
//! This differs by one microsecond at both ends from the paper's dynamic window
//! `(t_k - W, t_k]`, and is what makes every frame here tonic's own output at that slice.
//! Channels are in tonic's order: polarity 0 (OFF) first, then ON; a voxel grid is one signed
//! channel per bin (OFF counts -1, ON +1), bins in time order.
//!
//! # Incremental
//! A sample costs the events that entered or left since the previous one, never the whole
//! window: histograms count events in and out of the window; time surfaces keep each pixel's
//! latest time and, per cell, the decayed sum of its pixels (rescaled, not recomputed, as
//! time passes); voxel grids keep, per cell and bin, integer sums of weights and weighted times,
//! from which the pooled bilinear weights follow exactly. Frames (for `represent --what frames`
//! and rendering) are built on request from the same state.

mod histogram;
mod surface;
mod voxel;

pub use histogram::HistogramConfig;
pub use surface::TimeSurfaceConfig;
pub use voxel::VoxelGridConfig;

use std::collections::VecDeque;

use evtac_events::{Event, Resolution, Roi};
use serde::{Deserialize, Serialize};

use crate::ReprError;

/// Settings of one of the real-valued kinds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum DenseConfig {
    /// Per-polarity time surface, continuous or binarized.
    TimeSurface(TimeSurfaceConfig),
    /// Per-polarity event counts over a window.
    Histogram(HistogramConfig),
    /// Signed bilinear voxel grid over a window.
    VoxelGrid(VoxelGridConfig),
}

impl DenseConfig {
    /// Checks every field (finite, positive durations; a threshold in (0, 1); at least one bin).
    pub fn validate(&self) -> Result<(), ReprError> {
        match self {
            Self::TimeSurface(c) => c.validate(),
            Self::Histogram(c) => c.validate(),
            Self::VoxelGrid(c) => c.validate(),
        }
    }

    /// Channels per frame: 2 for the per-polarity kinds, the bins for a voxel grid.
    pub fn channels(&self) -> usize {
        match self {
            Self::TimeSurface(_) | Self::Histogram(_) => 2,
            Self::VoxelGrid(c) => c.bins as usize,
        }
    }

    /// A stable, file-name-safe key for the settings (feature caches).
    pub fn cache_key(&self) -> String {
        match self {
            Self::TimeSurface(c) => c.cache_key(),
            Self::Histogram(c) => c.cache_key(),
            Self::VoxelGrid(c) => c.cache_key(),
        }
    }

    fn engine(&self, cell_of: &[u32], cells: usize) -> Box<dyn Channels> {
        let pixels = cell_of.len();
        match *self {
            Self::TimeSurface(c) => Box::new(surface::TimeSurface::new(c, cell_of, cells)),
            Self::Histogram(c) => Box::new(histogram::Histogram::new(c, pixels, cells)),
            Self::VoxelGrid(c) => Box::new(voxel::VoxelGrid::new(c, cells)),
        }
    }
}

/// One event as the engines take it: where it falls (pixel and pooling cell of the frame) and
/// its polarity channel (0 OFF, 1 ON).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Placed {
    pub(crate) t: i64,
    pub(crate) pixel: u32,
    pub(crate) cell: u32,
    pub(crate) on: bool,
}

/// The seam between [`DenseExtractor`], which checks, queues and places events and keeps the
/// sample clock, and each kind's state. Events come in time order, every one before `t_k` before
/// `settle(t_k)`; sample times never go back.
pub(crate) trait Channels: Send {
    /// Takes events that the next sample will see, in time order.
    fn enter(&mut self, events: &[Placed]);
    /// Moves the sample time to `t_k`: windows drop what left them.
    fn settle(&mut self, t_k: i64);
    /// The pooled features at `t_k` (the time of the last `settle`): `channels x cells` values,
    /// channel-major.
    fn features(&self, t_k: i64, out: &mut [f32]);
    /// The frame at `t_k`: `channels x pixels` values, channel-major, row-major pixels.
    fn frame(&self, t_k: i64, out: &mut [f32]);
    /// Forgets every event (a new trial).
    fn reset(&mut self);
}

/// Streaming time surfaces, histograms or voxel grids at sample times, pooled 8x8 per channel.
///
/// ```
/// use evtac_events::{Event, Resolution};
/// use evtac_repr::{DenseConfig, DenseExtractor, HistogramConfig};
///
/// let config = DenseConfig::Histogram(HistogramConfig { window_ms: 1.0 });
/// let mut fx = DenseExtractor::new(config, Resolution::new(16, 8))?;
/// let e = |t, x, polarity| Event { t, x, y: 0, polarity };
/// fx.push(&[e(100, 1, true), e(200, 9, false), e(1_500, 1, true)])?;
/// fx.advance_to(1_200)?; // the window [200, 1200): the ON event at 100 has left it
/// // Channels OFF then ON, each with its two cells.
/// assert_eq!(fx.features(), &[0.0, 1.0 / 64.0, 0.0, 0.0]);
/// # Ok::<(), evtac_repr::ReprError>(())
/// ```
pub struct DenseExtractor {
    config: DenseConfig,
    resolution: Resolution,
    cell_of: Vec<u32>,
    cells: usize,
    engine: Box<dyn Channels>,
    pending: VecDeque<Event>,
    placed: Vec<Placed>,
    features: Vec<f32>,
    last_pushed: Option<i64>,
    sample_time: Option<i64>,
}

impl std::fmt::Debug for DenseExtractor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseExtractor")
            .field("config", &self.config)
            .field("resolution", &self.resolution)
            .field("pending", &self.pending.len())
            .field("sample_time", &self.sample_time)
            .finish()
    }
}

impl DenseExtractor {
    /// An extractor for `config` over a `frame`-sized crop (sides multiples of 8).
    pub fn new(config: DenseConfig, frame: Resolution) -> Result<Self, ReprError> {
        config.validate()?;
        let (cell_of, cells) = crate::pool::cell_map(frame)?;
        Ok(Self {
            config,
            resolution: frame,
            engine: config.engine(&cell_of, cells),
            cell_of,
            cells,
            pending: VecDeque::new(),
            placed: Vec::new(),
            features: vec![0.0; config.channels() * cells],
            last_pushed: None,
            sample_time: None,
        })
    }

    /// The settings.
    pub fn config(&self) -> &DenseConfig {
        &self.config
    }

    /// The frame size.
    pub fn resolution(&self) -> Resolution {
        self.resolution
    }

    /// Channels per frame ([`DenseConfig::channels`]).
    pub fn channels(&self) -> usize {
        self.config.channels()
    }

    /// Features per sample: channels x cells (`C x 900` on the 240x240 crop).
    pub fn feature_len(&self) -> usize {
        self.features.len()
    }

    /// The latest sample time, if any.
    pub fn sample_time(&self) -> Option<i64> {
        self.sample_time
    }

    /// Number of pushed events not yet applied (at or after the latest sample time).
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// Queues events in crop coordinates, in time order (also after earlier pushes). The whole
    /// chunk is checked first: on error nothing is queued.
    pub fn push(&mut self, events: &[Event]) -> Result<(), ReprError> {
        self.queue(events, None)
    }

    /// Queues events in full-sensor coordinates, cropping them with `roi` on the way (events
    /// outside it are dropped). `roi.size` must be the frame size.
    pub fn push_with_roi(&mut self, events: &[Event], roi: &Roi) -> Result<(), ReprError> {
        self.queue(events, Some(roi))
    }

    fn queue(&mut self, events: &[Event], roi: Option<&Roi>) -> Result<(), ReprError> {
        let (pending, last) = (&mut self.pending, &mut self.last_pushed);
        crate::check::queue_events(pending, last, self.resolution, events, roi)
    }

    /// Applies every queued event with `t < t_k` (tonic's slice end: see the module docs),
    /// moves the window to `[t_k - W, t_k)` and updates the features. `t_k` must not be before
    /// the previous sample time.
    pub fn advance_to(&mut self, t_k: i64) -> Result<(), ReprError> {
        if let Some(previous) = self.sample_time
            && t_k < previous
        {
            return Err(ReprError::SampleTimeBackwards { t: t_k, previous });
        }
        let width = usize::from(self.resolution.width);
        while self.pending.front().is_some_and(|e| e.t < t_k) {
            // In batches, so the engine's per-event loop is not a virtual call each.
            self.placed.clear();
            while self.placed.len() < 4096
                && let Some(e) = self.pending.front().filter(|e| e.t < t_k).copied()
            {
                self.pending.pop_front();
                let pixel = usize::from(e.y) * width + usize::from(e.x);
                self.placed.push(Placed {
                    t: e.t,
                    pixel: pixel as u32,
                    cell: self.cell_of[pixel],
                    on: e.polarity,
                });
            }
            self.engine.enter(&self.placed);
        }
        self.engine.settle(t_k);
        self.engine.features(t_k, &mut self.features);
        self.sample_time = Some(t_k);
        Ok(())
    }

    /// The pooled features at the latest sample time: channel-major, each channel's cells
    /// row-major (all zero before the first sample).
    pub fn features(&self) -> &[f32] {
        &self.features
    }

    /// The frame at the latest sample time into `out` (`channels x height x width` values,
    /// tonic's layout), float32 of the float64 values tonic computes.
    pub fn frame_into(&self, out: &mut [f32]) -> Result<(), ReprError> {
        let expected = self.channels() * self.resolution.pixels();
        if out.len() != expected {
            return Err(ReprError::BufferLength {
                what: "frame values",
                len: out.len(),
                expected,
                width: self.resolution.width,
                height: self.resolution.height,
            });
        }
        match self.sample_time {
            Some(t_k) => self.engine.frame(t_k, out),
            None => out.fill(0.0),
        }
        Ok(())
    }

    /// Forgets every event and the sample clock (a new trial), keeping the buffers.
    pub fn reset(&mut self) {
        self.engine.reset();
        self.pending.clear();
        self.features.fill(0.0);
        self.last_pushed = None;
        self.sample_time = None;
    }

    /// Cells per channel.
    pub fn cells(&self) -> usize {
        self.cells
    }
}

/// One-shot: the features of `config` at every time of `samples` (non-decreasing) over
/// `events` (crop coordinates, time order), `samples.len() x feature_len` values.
pub fn extract_dense_features(
    config: DenseConfig,
    frame: Resolution,
    events: &[Event],
    samples: &[i64],
) -> Result<Vec<f32>, ReprError> {
    let mut fx = DenseExtractor::new(config, frame)?;
    fx.push(events)?;
    let mut out = Vec::with_capacity(samples.len() * fx.feature_len());
    for &t in samples {
        fx.advance_to(t)?;
        out.extend_from_slice(fx.features());
    }
    Ok(out)
}

/// A duration in milliseconds as whole microseconds, or an error naming `field` when it is not
/// finite, not positive or not a whole number of microseconds (windows slice integer times).
pub(crate) fn whole_us(field: &'static str, ms: f64) -> Result<i64, ReprError> {
    // Rounded first: 0.1 ms is 100.00000000000001 us in binary.
    let us = (ms * 1000.0).round();
    let whole = (ms * 1000.0 - us).abs() < 1e-6;
    if !(us.is_finite() && us >= 1.0 && us <= i64::MAX as f64 / 4.0 && whole) {
        return Err(ReprError::InvalidConfig {
            field,
            value: ms.to_string(),
            reason: "must be a positive whole number of microseconds",
        });
    }
    Ok(us as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn configs_round_trip_through_json_tagged_by_kind() {
        let configs = [
            DenseConfig::TimeSurface(TimeSurfaceConfig {
                tau_ms: 50.0,
                threshold: Some(0.25),
            }),
            DenseConfig::Histogram(HistogramConfig { window_ms: 100.0 }),
            DenseConfig::VoxelGrid(VoxelGridConfig {
                window_ms: 100.0,
                bins: 5,
            }),
        ];
        for config in configs {
            let json = serde_json::to_string(&config).expect("serializes");
            assert_eq!(
                serde_json::from_str::<DenseConfig>(&json).ok(),
                Some(config)
            );
        }
        let json = r#"{"kind":"voxel-grid","window_ms":100.0,"bins":5}"#;
        assert_eq!(
            serde_json::from_str::<DenseConfig>(json).ok(),
            Some(configs[2])
        );
        let unknown = r#"{"kind":"histogram","window_ms":1.0,"bins":3}"#;
        assert!(serde_json::from_str::<DenseConfig>(unknown).is_err());
    }
}
