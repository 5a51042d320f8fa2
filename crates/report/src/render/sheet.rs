//! The PNG contact sheet: every frame in a grid, left to right and top to bottom, drawn straight
//! onto one plotters bitmap.

use super::Error;
use super::draw::{Scene, draw_frame};
use super::frames::Frame;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The most frames a sheet holds; more would make a PNG too large to look at.
pub const MAX_SHEET_FRAMES: usize = 100;

/// Frames a contact sheet shows when neither `--fps` nor `--speed` is given: a 6 x 4 grid.
pub const SHEET_DEFAULT_FRAMES: usize = 24;

/// Streams frames onto a contact sheet, written on [`SheetWriter::finish`].
pub struct SheetWriter<'p> {
    path: &'p Path,
    scene: Scene<'p>,
    columns: usize,
    root: DrawingArea<BitMapBackend<'p>, Shift>,
}

impl<'p> SheetWriter<'p> {
    /// A sheet written to `file` for every frame of `scene`, in a grid about as tall as wide;
    /// errors name `path`, the output `file` becomes.
    pub fn create(file: &'p Path, path: &'p Path, scene: Scene<'p>) -> Result<Self, Error> {
        let n = scene.timing.count;
        if n > MAX_SHEET_FRAMES {
            return Err(Error::Timing(format!(
                "{}: a contact sheet holds at most {MAX_SHEET_FRAMES} frames, the range has {n}: \
                 lower --fps, raise --speed or shorten --from-us/--to-us",
                path.display()
            )));
        }
        let (w, h) = (
            f64::from(scene.layout.size.0),
            f64::from(scene.layout.size.1),
        );
        let columns = ((n as f64 * h / w).sqrt().ceil() as usize).clamp(1, n.max(1));
        let rows = n.div_ceil(columns).max(1);
        let size = (
            scene.layout.size.0 * columns as u32,
            scene.layout.size.1 * rows as u32,
        );
        crate::plots::register_font()?;
        let root = BitMapBackend::new(file, size).into_drawing_area();
        root.fill(&WHITE).map_err(crate::plots::draw_err(path))?;
        Ok(SheetWriter {
            path,
            scene,
            columns,
            root,
        })
    }

    /// Draws `frame` in its cell.
    pub fn push(&mut self, frame: &Frame<'_>) -> Result<(), Error> {
        let (w, h) = self.scene.layout.size;
        let (c, r) = (frame.index % self.columns, frame.index / self.columns);
        let cell = self
            .root
            .clone()
            .shrink(((c as u32 * w) as i32, (r as u32 * h) as i32), (w, h));
        draw_frame(&cell, &self.scene, frame, self.path)?;
        Ok(())
    }

    /// Writes the PNG.
    pub fn finish(self) -> Result<(), Error> {
        self.root
            .present()
            .map_err(crate::plots::draw_err(self.path))?;
        Ok(())
    }
}
