//! The frame sequence: when each frame is taken, and what it holds (the events of its interval,
//! each representation's frame, binary or real-valued, and pooled features at its end).

use super::Error;
use evtac_events::Event;
use evtac_repr::{CROP, FeatureExtractor, Mask, ReprConfig, ReprKind};

/// When the frames are taken: `count` frames, the k-th at the end of the recording-time
/// interval `(start_us + k * step_us, start_us + (k + 1) * step_us]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Start of the first interval, microseconds.
    pub start_us: i64,
    /// Recording time per frame, microseconds.
    pub step_us: i64,
    /// Number of frames.
    pub count: usize,
    /// Frames per second of the output.
    pub fps: f64,
    /// Playback speed: recording seconds per output second.
    pub speed: f64,
}

impl Timing {
    /// Frames at `fps` played at `speed` times real time over `[from_us, to_us]` (default: the
    /// first and last event of `events`).
    pub fn new(
        events: &[Event],
        from_us: Option<i64>,
        to_us: Option<i64>,
        fps: f64,
        speed: f64,
    ) -> Result<Timing, Error> {
        if !(fps.is_finite() && fps > 0.0 && speed.is_finite() && speed > 0.0) {
            return Err(Error::Timing(format!(
                "--fps ({fps}) and --speed ({speed}) must be positive numbers"
            )));
        }
        let step_us = (speed * 1e6 / fps).round() as i64;
        if step_us < 1 {
            return Err(Error::Timing(format!(
                "--speed {speed} at --fps {fps} gives frames shorter than 1 us"
            )));
        }
        let (start_us, end_us) = range(events, from_us, to_us)?;
        // The last, partial interval still gets a frame so the range's end is shown.
        let count = ((end_us - start_us + step_us - 1) / step_us) as usize;
        Ok(Timing {
            start_us,
            step_us,
            count,
            fps,
            speed,
        })
    }

    /// `frames` frames (fewer when the range is shorter than `frames` microseconds) spread
    /// evenly over `[from_us, to_us]` (default: the first and last event), as a contact sheet
    /// shows a whole trial: one frame per second of output, at the speed that takes.
    pub fn spread(
        events: &[Event],
        from_us: Option<i64>,
        to_us: Option<i64>,
        frames: usize,
    ) -> Result<Timing, Error> {
        let (start_us, end_us) = range(events, from_us, to_us)?;
        let frames = frames.max(1) as i64;
        let step_us = (end_us - start_us + frames - 1) / frames;
        Self::new(events, from_us, to_us, 1.0, step_us as f64 * 1e-6)
    }

    /// The end of frame `k`'s interval, where its representations are sampled.
    pub fn end_us(&self, k: usize) -> i64 {
        self.start_us + (k as i64 + 1) * self.step_us
    }
}

/// `[from_us, to_us]`, by default the first and last event's times; an empty range is an error.
fn range(events: &[Event], from_us: Option<i64>, to_us: Option<i64>) -> Result<(i64, i64), Error> {
    let (first, last) = match (events.first(), events.last()) {
        (Some(a), Some(b)) => (a.t, b.t),
        _ => (0, 0),
    };
    let start_us = from_us.unwrap_or(first);
    let end_us = to_us.unwrap_or(last);
    if end_us <= start_us {
        return Err(Error::Timing(format!(
            "the time range is empty: from {start_us} us to {end_us} us (no events in the crop, \
             or --to-us not after --from-us)"
        )));
    }
    Ok((start_us, end_us))
}

/// A representation's frame.
#[derive(Debug, Clone, Copy)]
pub enum Pixels<'a> {
    /// A binary frame, row-major, 0 or 1.
    Binary(&'a [u8]),
    /// A real-valued kind's channels (`channels x height x width`, tonic's layout).
    Values {
        /// Channels: two polarities (OFF, ON) or a voxel grid's bins.
        channels: usize,
        /// The values.
        values: &'a [f32],
    },
}

/// One representation in a frame.
#[derive(Debug, Clone, Copy)]
pub struct ReprFrame<'a> {
    /// The representation.
    pub kind: ReprKind,
    /// Its frame.
    pub pixels: Pixels<'a>,
    /// The pooled features, row-major (channel after channel for the real-valued kinds).
    pub features: &'a [f32],
}

/// One frame: the events of its interval and the representations at its end.
#[derive(Debug, Clone)]
pub struct Frame<'a> {
    /// Index in the sequence.
    pub index: usize,
    /// End of the interval, microseconds.
    pub t_us: i64,
    /// The events of the interval (crop coordinates).
    pub events: &'a [Event],
    /// Each representation, in the order given.
    pub reprs: Vec<ReprFrame<'a>>,
}

impl Frame<'_> {
    /// The representation of `kind`, if rendered.
    pub fn repr(&self, kind: ReprKind) -> Option<&ReprFrame<'_>> {
        self.reprs.iter().find(|r| r.kind == kind)
    }
}

/// Runs `reprs` (each with its mask from `masks`, `None` for none) over `events`
/// (cropped to [`CROP`], time order) and calls `visit` with every frame of `timing`, in order.
/// Stops at `visit`'s first error and returns it.
pub fn for_each_frame(
    events: &[Event],
    reprs: &[ReprConfig],
    masks: &[Option<&Mask>],
    timing: &Timing,
    mut visit: impl FnMut(&Frame<'_>) -> Result<(), Error>,
) -> Result<(), Error> {
    let mut fx = FeatureExtractor::new_with_masks(reprs, CROP, masks)?;
    let samples: Vec<i64> = (0..timing.count).map(|k| timing.end_us(k)).collect();
    // The real-valued kinds' frames are built on request, into these.
    let mut values: Vec<Vec<f32>> = vec![Vec::new(); reprs.len()];
    // Events before the range still build up the representations' state (the static
    // accumulator and the dynamic window), as they would live.
    let mut failed = None;
    fx.run(events, &samples, |k, fx| {
        if failed.is_some() {
            return;
        }
        let t_us = samples[k];
        let first = events.partition_point(|e| e.t <= t_us - timing.step_us);
        let last = events.partition_point(|e| e.t <= t_us);
        for (i, config) in reprs.iter().enumerate() {
            if config.dense_part().is_some() {
                fx.frame_values_into(i, &mut values[i]);
            }
        }
        let frame = Frame {
            index: k,
            t_us,
            events: &events[first..last],
            reprs: reprs
                .iter()
                .enumerate()
                .map(|(i, config)| ReprFrame {
                    kind: config.kind(),
                    pixels: match config.dense_part() {
                        Some(_) => Pixels::Values {
                            channels: config.frames(),
                            values: &values[i],
                        },
                        None => Pixels::Binary(fx.frame(i)),
                    },
                    features: fx.features(i),
                })
                .collect(),
        };
        if let Err(e) = visit(&frame) {
            failed = Some(e);
        }
    })?;
    failed.map_or(Ok(()), Err)
}
