//! The example figures: one pause trial's estimates against the truth over time, and the
//! contour overlays of binary frames under two conditions.

use super::*;
use evtac_experiments::results::{ExampleTrial, Overlay};

/// An example pause trial: estimated and true pitch (left) and roll (right) over time, with the
/// stop phase shaded.
pub fn example_curves(path: &Path, ex: &ExampleTrial) -> Result<(), Error> {
    let e = draw_err(path);
    let root = canvas(path, (1300, 520), !ex.t_s.is_empty())?;
    let halves = root.split_evenly((1, 2));
    for (k, (area, what)) in halves.iter().zip(["Pitch", "Roll"]).enumerate() {
        let values = ex.truth.iter().map(|v| f64::from(v[k])).chain(
            ex.predictions
                .iter()
                .flat_map(|(_, p)| p.iter().map(move |v| f64::from(v[k]))),
        );
        let yr = padded(values, false);
        let xr = padded(ex.t_s.iter().copied(), false);
        let (y0, y1) = (yr.start, yr.end);
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{what}: trial {}", ex.trial), (FAMILY, 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(xr, yr)
            .map_err(&e)?;
        chart
            .configure_mesh()
            .x_desc("time from motion onset (s)")
            .y_desc(format!("{} (deg)", what.to_lowercase()))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .label_style((FAMILY, 16))
            .axis_desc_style((FAMILY, 18))
            .draw()
            .map_err(&e)?;
        if let Some((a, b)) = ex.stop_s {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(a, y0), (b, y1)],
                    RGBColor(230, 230, 230).filled(),
                )))
                .map_err(&e)?
                .label("stop phase")
                .legend(|(x, y)| {
                    Rectangle::new(
                        [(x, y - 6), (x + 16, y + 6)],
                        RGBColor(210, 210, 210).filled(),
                    )
                });
        }
        let truth: Vec<(f64, f64)> = ex
            .t_s
            .iter()
            .zip(&ex.truth)
            .map(|(&t, v)| (t, f64::from(v[k])))
            .collect();
        chart
            .draw_series(LineSeries::new(truth, BLACK.stroke_width(3)))
            .map_err(&e)?
            .label("ground truth")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(3)));
        for (name, pred) in &ex.predictions {
            let color = repr_color(*name);
            let pts: Vec<(f64, f64)> = ex
                .t_s
                .iter()
                .zip(pred)
                .map(|(&t, v)| (t, f64::from(v[k])))
                .collect();
            chart
                .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(&e)?
                .label(name.title())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft, 16, path)?;
    }
    root.present().map_err(&e)?;
    Ok(())
}

/// Contour overlays: in each panel the first condition's binary frame in red, the second's in
/// orange, pixels set in both in white, on black (as the paper's figure).
pub fn overlays(path: &Path, panels: &[Overlay]) -> Result<(), Error> {
    let e = draw_err(path);
    let cols = 2usize;
    let rows = panels.len().div_ceil(cols);
    let (cell_w, cell_h) = (540u32, 650u32);
    let root = canvas(
        path,
        (cell_w * cols as u32, cell_h * rows as u32),
        !panels.is_empty(),
    )?;
    let areas = root.split_evenly((rows, cols));
    let red = RGBColor(230, 30, 30);
    let orange = RGBColor(255, 165, 0);
    for (area, p) in areas.iter().zip(panels) {
        // The image, then its legend right below it, in the same titled area (a fixed split
        // left the legend too little room, so it ran into the next row's title).
        let image_area = area.titled(&p.title, (FAMILY, 20)).map_err(&e)?;
        let (w, h) = (p.width.max(1), p.height.max(1));
        let scale = ((cell_w as usize - 40) / w)
            .min((cell_h as usize - 130) / h)
            .max(1) as i32;
        let x_off = (cell_w as i32 - scale * w as i32) / 2;
        image_area
            .draw(&Rectangle::new(
                [(x_off, 0), (x_off + scale * w as i32, scale * h as i32)],
                BLACK.filled(),
            ))
            .map_err(&e)?;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let a = p.first.get(i).is_some_and(|&v| v != 0);
                let b = p.second.get(i).is_some_and(|&v| v != 0);
                let color = match (a, b) {
                    (true, true) => WHITE,
                    (true, false) => red,
                    (false, true) => orange,
                    (false, false) => continue,
                };
                let (px, py) = (x_off + x as i32 * scale, y as i32 * scale);
                image_area
                    .draw(&Rectangle::new(
                        [(px, py), (px + scale, py + scale)],
                        color.filled(),
                    ))
                    .map_err(&e)?;
            }
        }
        for (k, (label, color)) in [
            (p.first_label.as_str(), red),
            (p.second_label.as_str(), orange),
            ("both", WHITE),
        ]
        .into_iter()
        .enumerate()
        {
            let y = scale * h as i32 + 24 + 22 * k as i32;
            image_area
                .draw(&Rectangle::new([(30, y - 8), (48, y + 8)], color.filled()))
                .map_err(&e)?;
            image_area
                .draw(&Rectangle::new([(30, y - 8), (48, y + 8)], BLACK))
                .map_err(&e)?;
            image_area
                .draw(&Text::new(label.to_string(), (58, y - 9), (FAMILY, 18)))
                .map_err(&e)?;
        }
    }
    root.present().map_err(&e)?;
    Ok(())
}
