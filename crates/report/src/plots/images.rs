//! Pixel images on a figure: a row-major image drawn pixel for pixel (or cell for cell, scaled)
//! with a caller's colour per value, as the image figures (`representations.png`,
//! `sensor.png`) and `evtac render`'s frames need and plotters offers no element for without its `image` feature.

use super::{Error, draw_err};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// ON events only in a pixel.
pub const ON: RGBColor = RGBColor(255, 60, 60);
/// OFF events only.
pub const OFF: RGBColor = RGBColor(70, 140, 255);
/// Both polarities.
pub const BOTH: RGBColor = RGBColor(235, 90, 235);

/// The colour of an events pixel that saw ON events (`on`) and/or OFF events (`off`): black when
/// it saw none.
pub fn polarity_color(on: bool, off: bool) -> RGBColor {
    match (on, off) {
        (true, true) => BOTH,
        (true, false) => ON,
        (false, true) => OFF,
        (false, false) => BLACK,
    }
}

/// Draws a `width x height` image with its top-left corner at `origin` on `area`, each pixel a
/// `scale x scale` square coloured by `color(x, y)` (the figure at `path`).
pub fn draw_image<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    origin: (i32, i32),
    (width, height): (usize, usize),
    scale: i32,
    color: impl Fn(usize, usize) -> RGBColor,
    path: &Path,
) -> Result<(), Error> {
    let e = draw_err(path);
    for y in 0..height {
        for x in 0..width {
            let c = color(x, y);
            let (px, py) = (origin.0 + x as i32 * scale, origin.1 + y as i32 * scale);
            if scale == 1 {
                area.draw_pixel((px, py), &c).map_err(&e)?;
            } else {
                area.draw(&Rectangle::new(
                    [(px, py), (px + scale, py + scale)],
                    c.filled(),
                ))
                .map_err(&e)?;
            }
        }
    }
    Ok(())
}

/// Grey for a value in 0..=1 (black 0, white 1; outside the range clamped).
pub fn grey(v: f32) -> RGBColor {
    let g = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    RGBColor(g, g, g)
}
