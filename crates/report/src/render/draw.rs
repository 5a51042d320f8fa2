//! One frame drawn with the report's plotting stack: a row of 240x240 panels (the interval's
//! events by polarity, each representation's frame: binary ones white on black, the real-valued
//! kinds' ON red and OFF blue (a voxel grid's bins summed, positive red), scaled to the frame's
//! largest value where that is above 1), with `features` each
//! representation's pooled features below its frame, scaled to the same size, and with
//! `angles` a model's estimates over time below them all.

use super::Panel;
use super::angles::Angles;
use super::angles_chart::draw_angles;
use super::frames::{Frame, Pixels, Timing};
use crate::plots::images::{draw_image, grey, polarity_color};
use crate::plots::{Error, FAMILY, draw_err};
use evtac_repr::CROP;
use evtac_repr::pool::CELL;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Margin around and between panels.
const MARGIN: i32 = 10;
/// Height of the header line (the frame's time).
const HEADER: i32 = 26;
/// Height of a panel's title above it.
const TITLE: i32 = 22;
/// Height of the angles panel.
const ANGLES_HEIGHT: i32 = 240;
/// The narrowest angles panel: two charts with readable axes.
const ANGLES_MIN_WIDTH: i32 = 760;

/// Where the panels of a frame go.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// The panels of the first row, left to right (events and frames).
    pub columns: Vec<Panel>,
    /// Whether the second row shows the features under each frame.
    pub features: bool,
    /// Whether the angles panel goes below the images.
    pub angles: bool,
    /// Size of the frame in pixels.
    pub size: (u32, u32),
}

/// The layout of `panels` (in the order given; `features` adds the second row).
pub fn layout(panels: &[Panel]) -> Layout {
    let columns: Vec<Panel> = panels
        .iter()
        .copied()
        .filter(|p| !matches!(p, Panel::Features | Panel::Angles))
        .collect();
    let features = panels.contains(&Panel::Features);
    let angles = panels.contains(&Panel::Angles);
    let side = i32::from(CROP.width);
    let rows = 1 + i32::from(features);
    let mut width = MARGIN + columns.len().max(1) as i32 * (side + MARGIN);
    let mut height = HEADER + rows * (TITLE + side + MARGIN);
    if angles {
        width = width.max(ANGLES_MIN_WIDTH + 2 * MARGIN);
        height += ANGLES_HEIGHT + MARGIN;
    }
    Layout {
        columns,
        features,
        angles,
        size: (width as u32, height as u32),
    }
}

/// What every frame of a render shares: where the panels go, when the frames are, and the
/// angles panel's data.
#[derive(Debug, Clone)]
pub struct Scene<'a> {
    /// Where the panels go.
    pub layout: Layout,
    /// When the frames are.
    pub timing: Timing,
    /// The model's estimates and their references, for the angles panel.
    pub angles: Option<&'a Angles>,
}

/// Top-left corner of the image in column `c`, row `r`.
fn origin(c: usize, r: i32) -> (i32, i32) {
    let side = i32::from(CROP.width);
    (
        MARGIN + c as i32 * (side + MARGIN),
        HEADER + TITLE + r * (TITLE + side + MARGIN),
    )
}

/// Draws `frame` of `scene` onto `area` (white background; the output at `path`, named in
/// errors). Frame panels whose representation was not rendered stay blank, as does the angles
/// panel without angles.
pub fn draw_frame<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    scene: &Scene<'_>,
    frame: &Frame<'_>,
    path: &Path,
) -> Result<(), Error> {
    let (layout, timing) = (&scene.layout, &scene.timing);
    let e = draw_err(path);
    crate::plots::register_font()?;
    area.fill(&WHITE).map_err(&e)?;
    let (w, h) = (usize::from(CROP.width), usize::from(CROP.height));
    let text =
        |s: String, (x, y): (i32, i32)| area.draw(&Text::new(s, (x, y), (FAMILY, 16))).map_err(&e);
    let t_s = (frame.t_us - timing.start_us) as f64 / 1e6;
    text(
        format!(
            "t = {t_s:.3} s   frame {} of {}   {}x real time",
            frame.index + 1,
            timing.count,
            timing.speed
        ),
        (MARGIN, 6),
    )?;
    for (c, panel) in layout.columns.iter().enumerate() {
        let (x, y) = origin(c, 0);
        if *panel == Panel::Events {
            // Bit 0: an ON event in the pixel during the interval; bit 1: an OFF event.
            let mut seen = vec![0u8; w * h];
            for ev in frame.events {
                if let Some(s) = seen.get_mut(usize::from(ev.y) * w + usize::from(ev.x)) {
                    *s |= if ev.polarity { 1 } else { 2 };
                }
            }
            let ms = timing.step_us as f64 / 1000.0;
            text(
                format!("Events, last {ms:.1} ms ({})", frame.events.len()),
                (x, y - TITLE + 2),
            )?;
            draw_image(
                area,
                (x, y),
                (w, h),
                1,
                |px, py| {
                    let s = seen[py * w + px];
                    polarity_color(s & 1 != 0, s & 2 != 0)
                },
                path,
            )?;
            continue;
        }
        let Some(repr) = panel.repr_kind().and_then(|k| frame.repr(k)) else {
            continue;
        };
        text(format!("{} frame", repr.kind), (x, y - TITLE + 2))?;
        match repr.pixels {
            // A binary frame: white where the representation is set.
            Pixels::Binary(bits) => {
                let set = |px: usize, py: usize| bits.get(py * w + px).is_some_and(|&v| v != 0);
                let color = |px, py| if set(px, py) { WHITE } else { BLACK };
                draw_image(area, (x, y), (w, h), 1, color, path)?;
            }
            Pixels::Values { channels, values } => {
                let (on, off) = polarities(channels, values, w * h);
                let color = |px: usize, py: usize| {
                    let p = py * w + px;
                    RGBColor(level(on[p]), 0, level(off[p]))
                };
                draw_image(area, (x, y), (w, h), 1, color, path)?;
            }
        }
        if layout.features {
            let (fx, fy) = origin(c, 1);
            let (cw, ch) = (w / CELL, h / CELL);
            text(
                format!("{} features ({cw}x{ch})", repr.kind),
                (fx, fy - TITLE + 2),
            )?;
            // The real-valued kinds' channels summed per cell, scaled as their frames.
            let cells = cw * ch;
            let mut sums = vec![0f32; cells];
            for channel in repr.features.chunks_exact(cells) {
                for (s, &v) in sums.iter_mut().zip(channel) {
                    *s += v.abs();
                }
            }
            let scale = sums.iter().fold(1f32, |m, &v| m.max(v));
            draw_image(
                area,
                (fx, fy),
                (cw, ch),
                CELL as i32,
                |cx, cy| grey(sums.get(cy * cw + cx).copied().unwrap_or(0.0) / scale),
                path,
            )?;
        }
    }
    if let (true, Some(angles)) = (layout.angles, scene.angles) {
        let side = i32::from(CROP.width);
        let top = HEADER + (1 + i32::from(layout.features)) * (TITLE + side + MARGIN);
        let width = layout.size.0 as i32 - 2 * MARGIN;
        let panel = area
            .clone()
            .shrink((MARGIN, top), (width as u32, ANGLES_HEIGHT as u32));
        draw_angles(&panel, angles, frame.t_us, timing, path)?;
    }
    Ok(())
}

/// Per pixel, the ON and OFF intensities of a real-valued frame of `channels` channels of
/// `pixels` values, in 0..=1: a polarity pair's two channels (OFF first, tonic's order), or a
/// voxel grid's bins summed (positive ON, negative OFF), divided by the frame's largest value
/// where it is above 1 (a histogram's counts; a time surface's values are already in 0..=1).
fn polarities(channels: usize, values: &[f32], pixels: usize) -> (Vec<f32>, Vec<f32>) {
    let (mut on, mut off) = (vec![0f32; pixels], vec![0f32; pixels]);
    if channels == 2 {
        off.copy_from_slice(&values[..pixels]);
        on.copy_from_slice(&values[pixels..2 * pixels]);
    } else {
        for bin in values.chunks_exact(pixels) {
            for (o, &v) in on.iter_mut().zip(bin) {
                *o += v;
            }
        }
        for (o, f) in on.iter_mut().zip(&mut off) {
            *f = (-*o).max(0.0);
            *o = o.max(0.0);
        }
    }
    let scale = on.iter().chain(&off).fold(1f32, |m, &v| m.max(v));
    for v in on.iter_mut().chain(&mut off) {
        *v /= scale;
    }
    (on, off)
}

/// A colour channel's level for an intensity in 0..=1.
fn level(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_valued_frames_split_into_on_and_off_scaled_to_their_largest() {
        // Two polarity channels of two pixels: OFF [0.5, 0], ON [0.25, 1].
        let (on, off) = polarities(2, &[0.5, 0.0, 0.25, 1.0], 2);
        assert_eq!((on, off), (vec![0.25, 1.0], vec![0.5, 0.0]));
        // Counts above 1 are scaled to the largest.
        let (on, off) = polarities(2, &[4.0, 0.0, 2.0, 8.0], 2);
        assert_eq!((on, off), (vec![0.25, 1.0], vec![0.5, 0.0]));
        // Three signed bins summed: +3 and -1.5.
        let (on, off) = polarities(3, &[1.0, -0.5, 1.0, -0.5, 1.0, -0.5], 2);
        assert_eq!((on, off), (vec![1.0, 0.0], vec![0.0, 0.5]));
        assert_eq!((level(1.5), level(0.5), level(-1.0)), (255, 128, 0));
    }
}
