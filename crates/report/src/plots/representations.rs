//! `representations.png`, the paper's Fig. 2 as data: for one test sample, the events of the
//! last dynamic window and the static, dynamic and combined binary frames side by side, each
//! frame's 30x30 pooled features below it.

use super::images::{BOTH, OFF, ON, draw_image, grey, polarity_color};
use super::{Error, FAMILY, canvas, draw_err};
use evtac_experiments::results::ReprExample;
use plotters::prelude::*;
use std::path::Path;

/// Width of one column (a 240-pixel image and its margins).
const COLUMN: i32 = 290;
/// Top of the first row of images (below the column titles).
const ROW1: i32 = 44;
/// Top of the second row of images.
const ROW2: i32 = ROW1 + 240 + 56;

/// Draws `ex` into `path`: row 1 the events and the three frames, row 2 the pooled features
/// (grey: black 0, white 1) under each frame, and a key under the events.
pub fn representations(path: &Path, ex: &ReprExample) -> Result<(), Error> {
    let e = draw_err(path);
    let columns = 1 + ex.panels.len() as i32;
    let (w, h) = (ex.width, ex.height);
    let has_data = w > 0 && h > 0 && !ex.panels.is_empty();
    let root = canvas(
        path,
        (
            (COLUMN * columns + 20) as u32,
            (ROW2 + h as i32 + 30) as u32,
        ),
        has_data,
    )?;
    let left = |c: i32| 20 + c * COLUMN + (COLUMN - 20 - w as i32) / 2;
    let text = |s: String, (x, y): (i32, i32), size: u32| {
        root.draw(&Text::new(s, (x, y), (FAMILY, size))).map_err(&e)
    };

    // The events of the window, by polarity, on black.
    text(
        format!("Events, last {} ms", ex.window_ms),
        (left(0), ROW1 - 30),
        20,
    )?;
    draw_image(
        &root,
        (left(0), ROW1),
        (w, h),
        1,
        |x, y| {
            let i = y * w + x;
            polarity_color(
                ex.on.get(i).is_some_and(|&c| c > 0),
                ex.off.get(i).is_some_and(|&c| c > 0),
            )
        },
        path,
    )?;
    for (k, (label, color)) in [("ON", ON), ("OFF", OFF), ("both", BOTH)]
        .into_iter()
        .enumerate()
    {
        let y = ROW2 + 10 + 26 * k as i32;
        root.draw(&Rectangle::new(
            [(left(0), y), (left(0) + 18, y + 16)],
            color.filled(),
        ))
        .map_err(&e)?;
        text(label.to_string(), (left(0) + 28, y), 18)?;
    }
    let events: u32 = ex.on.iter().chain(&ex.off).sum();
    let notes = [
        format!("trial {}", ex.trial),
        format!("sample at {:.0} ms after onset", ex.t_ms),
        format!("{events} events in the crop"),
        "pooled: 8x8 mean, 0 black, 1 white".to_string(),
    ];
    for (k, note) in notes.into_iter().enumerate() {
        text(note, (left(0), ROW2 + 100 + 24 * k as i32), 16)?;
    }

    // Each representation: its binary frame (white on black), its pooled features below.
    let (cw, ch) = (w / 8, h / 8);
    for (c, panel) in ex.panels.iter().enumerate() {
        let x = left(c as i32 + 1);
        text(format!("{} frame", panel.name), (x, ROW1 - 30), 20)?;
        draw_image(
            &root,
            (x, ROW1),
            (w, h),
            1,
            |px, py| {
                let set = panel.frame.get(py * w + px).is_some_and(|&v| v != 0);
                if set { WHITE } else { BLACK }
            },
            path,
        )?;
        text(
            format!("{} features ({cw}x{ch})", panel.name),
            (x, ROW2 - 30),
            20,
        )?;
        draw_image(
            &root,
            (x, ROW2),
            (cw, ch),
            8,
            |cx, cy| grey(panel.features.get(cy * cw + cx).copied().unwrap_or(0.0)),
            path,
        )?;
    }
    root.present().map_err(&e)?;
    Ok(())
}
