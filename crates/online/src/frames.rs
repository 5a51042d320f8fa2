//! The representation's binary frames, captured at a lower rate than the estimates, for logs
//! (`evtac online --mcap-frames HZ`): what the network saw, beside what it estimated.
//!
//! A frame is taken at an estimate's time, once at least the frame interval has passed since
//! the previous one (the first at the first estimate), so each frame is exactly the state the
//! estimate at its time was computed from. For each part the model's representation has, one
//! frame of the 240x240 crop, 0 or 1 per pixel:
//! - a static model: `static`; a dynamic one: `dynamic`;
//! - a combined model: its `static` and `dynamic` parts (thresholded from the accumulator's
//!   potentials, masked, and from the window's counts, by `evtac_repr::combine`, the rules the
//!   representation itself applies) and the `combined` frame the network saw, their OR;
//! - stacked and late models: `static` and `dynamic`, the two halves of their frame.
//!
//! Capturing costs a pass over the crop per part per frame, on the estimation thread, and the
//! combined representation's accumulator is then kept up to date at every estimate instead of
//! deferred (see `Estimator::capture_frames`): a few microseconds per estimate, the same values.

use evtac_repr::{FeatureExtractor, Mask, ReprConfig, combine};

/// Which frame of the representation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Part {
    /// The accumulator's thresholded (and masked) potentials.
    Static,
    /// The sliding window's thresholded counts.
    Dynamic,
    /// The OR of the two (combined models).
    Combined,
}

impl Part {
    /// Its name, as topics and file names spell it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Static => "static",
            Self::Dynamic => "dynamic",
            Self::Combined => "combined",
        }
    }
}

/// One binary frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Frame {
    /// Which one.
    pub part: Part,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// 0 or 1 per pixel, row-major.
    pub pixels: Vec<u8>,
}

/// The frames of one time.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameSet {
    /// The estimate's time they were taken at (us).
    pub t_us: i64,
    /// One per part (see the module docs), in [`Part`] order.
    pub frames: Vec<Frame>,
}

/// Takes frames every `every_us` of event time and holds them until the pipeline collects them.
#[derive(Debug)]
pub(crate) struct FrameCapture {
    every_us: i64,
    next_us: Option<i64>,
    ready: Vec<FrameSet>,
}

impl FrameCapture {
    /// A capture of one frame set per `every_us` (at least 1).
    pub(crate) fn new(every_us: i64) -> Self {
        Self {
            every_us: every_us.max(1),
            next_us: None,
            ready: Vec::new(),
        }
    }

    /// Takes the frames at estimate time `t_us` if one is due.
    pub(crate) fn at_estimate(
        &mut self,
        t_us: i64,
        extractor: &FeatureExtractor,
        config: &ReprConfig,
        mask: Option<&Mask>,
    ) {
        if self.next_us.is_some_and(|next| t_us < next) {
            return;
        }
        self.next_us = Some(t_us.saturating_add(self.every_us));
        let frames = frames_of(extractor, config, mask);
        self.ready.push(FrameSet { t_us, frames });
    }

    /// The frame sets taken since the last call.
    pub(crate) fn take(&mut self) -> Vec<FrameSet> {
        std::mem::take(&mut self.ready)
    }
}

/// The frames of `extractor`'s first output, whose representation is `config` (see the module
/// docs). The extractor must not defer its accumulation (its potentials are read).
fn frames_of(extractor: &FeatureExtractor, config: &ReprConfig, mask: Option<&Mask>) -> Vec<Frame> {
    let size = extractor.resolution();
    let frame = |part, pixels: Vec<u8>| Frame {
        part,
        width: u32::from(size.width),
        height: (pixels.len() / usize::from(size.width.max(1))) as u32,
        pixels,
    };
    // Read only for the binary kinds (a real-valued kind has no binary frame).
    let whole = || extractor.frame(0);
    match config {
        ReprConfig::Static(_) => vec![frame(Part::Static, whole().to_vec())],
        ReprConfig::Dynamic(_) => vec![frame(Part::Dynamic, whole().to_vec())],
        ReprConfig::Combined {
            static_part,
            dynamic_part,
        } => {
            let mut frames = Vec::with_capacity(3);
            if let Some(potentials) = extractor.potentials(0) {
                frames.push(frame(
                    Part::Static,
                    combine::static_frame(static_part, potentials, mask),
                ));
            }
            if let Some(counts) = extractor.counts(0) {
                frames.push(frame(
                    Part::Dynamic,
                    combine::dynamic_frame(dynamic_part, counts),
                ));
            }
            frames.push(frame(Part::Combined, whole().to_vec()));
            frames
        }
        // Refused when frames are asked for (`Estimator::capture_frames`): not binary.
        ReprConfig::TimeSurface(_) | ReprConfig::Histogram(_) | ReprConfig::VoxelGrid(_) => {
            Vec::new()
        }
        // The static part's frame above the dynamic part's.
        ReprConfig::Stacked { .. } | ReprConfig::Late { .. } => {
            let whole = whole();
            let (top, bottom) = whole.split_at(whole.len() / 2);
            vec![
                frame(Part::Static, top.to_vec()),
                frame(Part::Dynamic, bottom.to_vec()),
            ]
        }
    }
}
