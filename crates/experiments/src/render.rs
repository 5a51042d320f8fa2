//! `evtac render`'s engine: a recording (or a dataset trial) as a sequence of frames, each the
//! panels the sensor and the network see over one frame interval, written as an animated GIF or
//! a PNG contact sheet.
//!
//! The frames come from the same [`evtac_repr::FeatureExtractor`] the feature cache runs,
//! sampled at the end of every frame interval, and are drawn with the report's plotting stack
//! (plotters and the pixel helpers of `representations.png`), so a rendered frame is the
//! report's Fig. 2 at another sample time. Encoding is the `gif` crate's (GIF) and plotters'
//! (PNG).
//!
//! ```no_run
//! use evtac_experiments::render::{self, Output, Panel, Timing};
//! use evtac_repr::{DynamicConfig, ReprConfig, StaticConfig};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let events = evtac_experiments::dataset::read_cropped("trial.aedat4".as_ref())?;
//! let reprs = evtac_experiments::exp1::representations(
//!     ReprConfig::Static(StaticConfig::default()),
//!     ReprConfig::Dynamic(DynamicConfig::default()),
//! );
//! let timing = Timing::new(&events, None, None, 30.0, 1.0)?;
//! render::render(
//!     "trial.gif".as_ref(),
//!     Output::Gif,
//!     &events,
//!     &reprs,
//!     &[None, None, None],
//!     &Panel::DEFAULT,
//!     &timing,
//! )?;
//! # Ok(())
//! # }
//! ```

mod draw;
mod frames;
mod gif;
mod sheet;

pub use draw::{Layout, draw_frame, layout};
pub use frames::{Frame, ReprFrame, Timing, for_each_frame};
pub use gif::GifWriter;
pub use sheet::{MAX_SHEET_FRAMES, SheetWriter};

use evtac_events::Event;
use evtac_repr::{Mask, ReprConfig, ReprError};
use std::path::{Path, PathBuf};

/// One kind of panel in a rendered frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Panel {
    /// The events of the frame interval, coloured by polarity.
    Events,
    /// The static representation's binary frame.
    Static,
    /// The dynamic representation's binary frame.
    Dynamic,
    /// The combined representation's binary frame.
    Combined,
    /// The 30x30 pooled features of each representation drawn, in a row below the frames.
    Features,
}

impl Panel {
    /// The panels drawn when none are asked for.
    pub const DEFAULT: [Panel; 4] = [
        Panel::Events,
        Panel::Static,
        Panel::Dynamic,
        Panel::Combined,
    ];

    /// The panel called `name` (`events`, `static`, `dynamic`, `combined`, `features`).
    pub fn parse(name: &str) -> Result<Panel, Error> {
        match name.trim().to_ascii_lowercase().as_str() {
            "events" => Ok(Panel::Events),
            "static" => Ok(Panel::Static),
            "dynamic" => Ok(Panel::Dynamic),
            "combined" => Ok(Panel::Combined),
            "features" => Ok(Panel::Features),
            _ => Err(Error::UnknownPanel {
                name: name.to_string(),
            }),
        }
    }

    /// The representation (`Static`, `Dynamic`, `Combined`, as
    /// [`crate::exp1::representations`] names them) a frame panel shows.
    pub fn repr_name(self) -> Option<&'static str> {
        match self {
            Panel::Static => Some("Static"),
            Panel::Dynamic => Some("Dynamic"),
            Panel::Combined => Some("Combined"),
            Panel::Events | Panel::Features => None,
        }
    }
}

/// The file format written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// An animated GIF, one image per frame.
    Gif,
    /// A PNG contact sheet: the frames in a grid.
    Png,
}

impl Output {
    /// The format `path`'s extension names (`.gif` or `.png`, any case).
    pub fn from_path(path: &Path) -> Result<Output, Error> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("gif") => Ok(Output::Gif),
            Some("png") => Ok(Output::Png),
            _ => Err(Error::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// Errors rendering.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A panel name is not one of the five.
    #[error("unknown panel `{name}` (expected events, static, dynamic, combined or features)")]
    UnknownPanel {
        /// The name given.
        name: String,
    },
    /// The output's extension names no format evtac writes.
    #[error("{}: unknown output format (expected .gif or .png)", path.display())]
    UnknownFormat {
        /// The output file.
        path: PathBuf,
    },
    /// The time range or frame timing is unusable.
    #[error("{0}")]
    Timing(String),
    /// The representations could not be built.
    #[error("building the representations: {0}")]
    Repr(#[from] ReprError),
    /// Drawing a frame failed.
    #[error(transparent)]
    Draw(#[from] crate::plots::Error),
    /// Encoding or writing the GIF failed.
    #[error("{}: writing the GIF failed: {message}", path.display())]
    Gif {
        /// The output file.
        path: PathBuf,
        /// The encoder's message.
        message: String,
    },
}

/// Renders `events` (cropped to [`evtac_repr::CROP`], time order) to `path` as `output`: the
/// frames of `timing`, each with `panels`, the representations `reprs` (name, config, as
/// [`crate::exp1::representations`] lists them) built with `masks` (one per config, `None` for
/// none).
pub fn render(
    path: &Path,
    output: Output,
    events: &[Event],
    reprs: &[(&str, ReprConfig)],
    masks: &[Option<&Mask>],
    panels: &[Panel],
    timing: &Timing,
) -> Result<(), Error> {
    let layout = layout(panels);
    match output {
        Output::Gif => {
            let mut gif = GifWriter::create(path, layout, *timing)?;
            for_each_frame(events, reprs, masks, timing, |f| gif.push(f))
        }
        Output::Png => {
            let mut sheet = SheetWriter::create(path, layout, *timing)?;
            for_each_frame(events, reprs, masks, timing, |f| sheet.push(f))?;
            sheet.finish()
        }
    }
}
