//! `evtac render`'s engine: a recording (or a dataset trial) as a sequence of frames, each the
//! panels the sensor and the network see over one frame interval, written as an animated GIF, an
//! MP4 video or a PNG contact sheet.
//!
//! The frames come from the same [`evtac_repr::FeatureExtractor`] the feature cache runs,
//! sampled at the end of every frame interval, and are drawn with the report's plotting stack
//! (plotters and the pixel helpers of `representations.png`), so a rendered frame is the
//! report's Fig. 2 at another sample time. Encoding is the `gif` crate's (GIF), an `ffmpeg`
//! on the `PATH` (MP4) and plotters' (PNG). Every format is written to a temporary file beside
//! the output and renamed at the end, so a failed or interrupted render leaves no partial file.
//!
//! ```no_run
//! use evtac_report::render::{self, Output, Panel, Scene, Timing};
//! use evtac_repr::{DynamicConfig, ReprConfig, StaticConfig};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let events = evtac_experiments::dataset::read_cropped("trial.aedat4".as_ref())?;
//! let reprs = evtac_experiments::exp1::paper_representations(
//!     ReprConfig::Static(StaticConfig::default()),
//!     ReprConfig::Dynamic(DynamicConfig::default()),
//! );
//! let timing = Timing::new(&events, None, None, 30.0, 1.0)?;
//! let scene = Scene::new(&Panel::DEFAULT, timing, None)?;
//! render::render(
//!     "trial.gif".as_ref(),
//!     Output::Gif,
//!     &events,
//!     &reprs,
//!     &[None, None, None],
//!     scene,
//! )?;
//! # Ok(())
//! # }
//! ```

mod angles;
mod angles_chart;
mod draw;
mod frames;
mod gif;
mod mp4;
mod sheet;

pub use angles::{Angles, estimate_times};
pub use draw::{Layout, Scene, draw_frame, layout};
pub use frames::{Frame, Pixels, ReprFrame, Timing, for_each_frame};
pub use gif::GifWriter;
pub use mp4::Mp4Writer;
pub use sheet::{MAX_SHEET_FRAMES, SHEET_DEFAULT_FRAMES, SheetWriter};

use evtac_events::Event;
use evtac_events::output::OutputFile;
use evtac_repr::{Mask, ReprConfig, ReprError, ReprKind};
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
    /// A time surface's two polarity channels (ON red, OFF blue).
    TimeSurface,
    /// A polarity histogram's counts (ON red, OFF blue, scaled to the frame's largest).
    Histogram,
    /// A voxel grid's bins summed (positive red, negative blue, scaled to the largest).
    VoxelGrid,
    /// The 30x30 pooled features of each representation drawn, in a row below the frames.
    Features,
    /// A model's pitch and roll estimates over the rendered span, beside the labels, with a
    /// cursor at the frame's time (needs the [`Angles`]).
    Angles,
}

impl Panel {
    /// The panels drawn when none are asked for.
    pub const DEFAULT: [Panel; 4] = [
        Panel::Events,
        Panel::Static,
        Panel::Dynamic,
        Panel::Combined,
    ];

    /// The panel called `name` (`events`, `static`, `dynamic`, `combined`, `time-surface`,
    /// `histogram`, `voxel-grid`, `features`, `angles`).
    pub fn parse(name: &str) -> Result<Panel, Error> {
        match name.trim().to_ascii_lowercase().as_str() {
            "events" => Ok(Panel::Events),
            "static" => Ok(Panel::Static),
            "dynamic" => Ok(Panel::Dynamic),
            "combined" => Ok(Panel::Combined),
            "time-surface" => Ok(Panel::TimeSurface),
            "histogram" => Ok(Panel::Histogram),
            "voxel-grid" => Ok(Panel::VoxelGrid),
            "features" => Ok(Panel::Features),
            "angles" => Ok(Panel::Angles),
            _ => Err(Error::UnknownPanel {
                name: name.to_string(),
            }),
        }
    }

    /// The representation a frame panel shows.
    pub fn repr_kind(self) -> Option<ReprKind> {
        match self {
            Panel::Static => Some(ReprKind::Static),
            Panel::Dynamic => Some(ReprKind::Dynamic),
            Panel::Combined => Some(ReprKind::Combined),
            Panel::TimeSurface => Some(ReprKind::TimeSurface),
            Panel::Histogram => Some(ReprKind::Histogram),
            Panel::VoxelGrid => Some(ReprKind::VoxelGrid),
            Panel::Events | Panel::Features | Panel::Angles => None,
        }
    }

    /// The frame panel of a representation kind, if it has one (the fusions have none: their
    /// frames are the static and dynamic ones).
    pub fn of_kind(kind: ReprKind) -> Option<Panel> {
        [
            Panel::Static,
            Panel::Dynamic,
            Panel::Combined,
            Panel::TimeSurface,
            Panel::Histogram,
            Panel::VoxelGrid,
        ]
        .into_iter()
        .find(|p| p.repr_kind() == Some(kind))
    }
}

/// The file format written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// An animated GIF, one image per frame.
    Gif,
    /// An H.264 MP4 video, encoded by `ffmpeg`.
    Mp4,
    /// A PNG contact sheet: the frames in a grid.
    Png,
}

impl Output {
    /// The format `path`'s extension names (`.gif`, `.mp4` or `.png`, any case).
    pub fn from_path(path: &Path) -> Result<Output, Error> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("gif") => Ok(Output::Gif),
            Some("mp4") => Ok(Output::Mp4),
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
    /// A panel name is not one of the six.
    #[error(
        "unknown panel `{name}` (expected events, static, dynamic, combined, features or angles)"
    )]
    UnknownPanel {
        /// The name given.
        name: String,
    },
    /// The output's extension names no format evtac writes.
    #[error("{}: unknown output format (expected .gif, .mp4 or .png)", path.display())]
    UnknownFormat {
        /// The output file.
        path: PathBuf,
    },
    /// The time range or frame timing is unusable.
    #[error("{0}")]
    Timing(String),
    /// The angles panel was asked for without a model's estimates to draw.
    #[error("the angles panel shows a model's estimates: it needs a model (--model)")]
    NoAngles,
    /// The model could not predict from the features.
    #[error("{}: predicting the angles failed: {message}", model.display())]
    Predict {
        /// The model bundle's folder.
        model: PathBuf,
        /// The predictor's message.
        message: String,
    },
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
    /// No `ffmpeg` on the `PATH` for an MP4.
    #[error(
        "{}: writing MP4 needs ffmpeg, which is not on the PATH (install it, e.g. `apt install \
         ffmpeg`, or write .gif or .png, which need nothing else)",
        path.display()
    )]
    FfmpegMissing {
        /// The output file.
        path: PathBuf,
    },
    /// ffmpeg failed to encode the MP4.
    #[error("{}: encoding the MP4 with ffmpeg failed: {message}", path.display())]
    Ffmpeg {
        /// The output file.
        path: PathBuf,
        /// What failed, with ffmpeg's own message.
        message: String,
    },
    /// Creating the temporary file or renaming it to the output failed.
    #[error(transparent)]
    Io(#[from] evtac_events::IoError),
}

impl<'a> Scene<'a> {
    /// The scene of `panels` (in the order given) over `timing`, with a model's `angles` for
    /// the angles panel (an error when that panel is asked for without them).
    pub fn new(
        panels: &[Panel],
        timing: Timing,
        angles: Option<&'a Angles>,
    ) -> Result<Scene<'a>, Error> {
        let layout = layout(panels);
        if layout.angles && angles.is_none() {
            return Err(Error::NoAngles);
        }
        Ok(Scene {
            layout,
            timing,
            angles,
        })
    }
}

/// Renders `events` (cropped to [`evtac_repr::CROP`], time order) to `path` as `output`: the
/// frames of `scene`, the representations `reprs` (name, config, as
/// [`evtac_experiments::exp1::paper_representations`] lists them) built with `masks` (one per config, `None` for
/// none).
pub fn render(
    path: &Path,
    output: Output,
    events: &[Event],
    reprs: &[ReprConfig],
    masks: &[Option<&Mask>],
    scene: Scene<'_>,
) -> Result<(), Error> {
    let timing = scene.timing;
    // Written beside `path` and renamed when complete; the writers take the temporary path
    // (ffmpeg and plotters open it themselves).
    let out = OutputFile::create(path).map_err(evtac_events::IoError::at(path))?;
    let temp = out.temp_path();
    match output {
        Output::Gif => {
            let mut gif = GifWriter::create(temp, path, scene)?;
            for_each_frame(events, reprs, masks, &timing, |f| gif.push(f))?;
            gif.finish()?;
        }
        Output::Mp4 => {
            let mut mp4 = Mp4Writer::create(temp, path, scene)?;
            for_each_frame(events, reprs, masks, &timing, |f| mp4.push(f))?;
            mp4.finish()?;
        }
        Output::Png => {
            let mut sheet = SheetWriter::create(temp, path, scene)?;
            for_each_frame(events, reprs, masks, &timing, |f| sheet.push(f))?;
            sheet.finish()?;
        }
    }
    out.commit().map_err(evtac_events::IoError::at(path))?;
    Ok(())
}
