//! One frame drawn with the report's plotting stack: a row of 240x240 panels (the interval's
//! events by polarity, each representation's binary frame), with `features` each
//! representation's pooled features below its frame, scaled to the same size, and with
//! `angles` a model's estimates over time below them all.

use super::Panel;
use super::angles::Angles;
use super::angles_chart::draw_angles;
use super::frames::{Frame, Timing};
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
        // A binary frame: white where the representation is set.
        let set = |px: usize, py: usize| repr.frame.get(py * w + px).is_some_and(|&v| v != 0);
        draw_image(
            area,
            (x, y),
            (w, h),
            1,
            |px, py| if set(px, py) { WHITE } else { BLACK },
            path,
        )?;
        if layout.features {
            let (fx, fy) = origin(c, 1);
            let (cw, ch) = (w / CELL, h / CELL);
            text(
                format!("{} features ({cw}x{ch})", repr.kind),
                (fx, fy - TITLE + 2),
            )?;
            draw_image(
                area,
                (fx, fy),
                (cw, ch),
                CELL as i32,
                |cx, cy| grey(repr.features.get(cy * cw + cx).copied().unwrap_or(0.0)),
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
