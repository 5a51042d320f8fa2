//! `sensor.png`: the sensor's images side by side (simulated camera brightness at rest and in
//! contact, or a real dataset's event-count images), the centered 240x240 crop outlined.

use super::images::{draw_image, grey};
use super::{Error, FAMILY, canvas, draw_err};
use evtac_experiments::results::{SensorKind, SensorView};
use evtac_repr::CROP;
use plotters::prelude::*;
use std::path::Path;

/// Space above each image for its title.
const TITLE: i32 = 40;
/// Margin around and between images.
const MARGIN: i32 = 20;

/// Draws `view` into `path`, one image per panel in a row, each at full resolution.
pub fn sensor(path: &Path, view: &SensorView) -> Result<(), Error> {
    let e = draw_err(path);
    let (w, h) = (
        usize::from(view.resolution.width),
        usize::from(view.resolution.height),
    );
    let n = view.panels.len() as i32;
    let root = canvas(
        path,
        (
            (MARGIN + n * (w as i32 + MARGIN)) as u32,
            (TITLE + h as i32 + MARGIN + 30) as u32,
        ),
        n > 0 && w > 0 && h > 0,
    )?;
    let roi = evtac_repr::centered_crop(view.resolution).ok();
    let crop_color = RGBColor(255, 200, 0);
    for (k, panel) in view.panels.iter().enumerate() {
        let x0 = MARGIN + k as i32 * (w as i32 + MARGIN);
        root.draw(&Text::new(
            panel.title.clone(),
            (x0, TITLE - 30),
            (FAMILY, 20),
        ))
        .map_err(&e)?;
        draw_image(
            &root,
            (x0, TITLE),
            (w, h),
            1,
            |x, y| grey(panel.values.get(y * w + x).copied().unwrap_or(0.0)),
            path,
        )?;
        if let Some(roi) = roi {
            let (cx, cy) = (x0 + i32::from(roi.x0), TITLE + i32::from(roi.y0));
            root.draw(&Rectangle::new(
                [
                    (cx, cy),
                    (cx + i32::from(CROP.width), cy + i32::from(CROP.height)),
                ],
                crop_color.stroke_width(2),
            ))
            .map_err(&e)?;
        }
    }
    let key = match view.kind {
        SensorKind::Simulated => "simulated camera brightness (gamma 0.5)",
        SensorKind::EventCounts => "events per pixel (log scale, black none)",
    };
    root.draw(&Text::new(
        format!("{key}; yellow: the centered 240x240 crop"),
        (MARGIN, TITLE + h as i32 + 8),
        (FAMILY, 18),
    ))
    .map_err(&e)?;
    root.present().map_err(&e)?;
    Ok(())
}
