//! The sensitivity study's tornado figure: for each simulator parameter, the dynamic - static
//! test-MAE gap at half and at one and a half times its default, as bars from the baseline's
//! gap, the parameters sorted by how far they move it (the largest on top). The key is in the
//! axis title: a legend box would cover bars wherever it sat.

use super::*;
use evtac_experiments::sensitivity::{Study, Varied};

/// The factor below 1 is drawn in this colour, the one above in the other.
const LOW: RGBColor = RGBColor(31, 119, 180);
const HIGH: RGBColor = RGBColor(214, 39, 40);

/// One row: the parameter and its gap at each factor.
struct Row<'a> {
    name: &'a str,
    gaps: Vec<(f64, f64)>,
}

/// The parameters' rows, sorted by how far either factor moves the gap from `base`'s (the
/// farthest last).
fn rows(study: &Study, base: f64) -> Vec<Row<'_>> {
    let mut rows: Vec<Row<'_>> = Vec::new();
    for p in study
        .points
        .iter()
        .filter(|p| p.parameter != Varied::Baseline)
    {
        match rows.iter_mut().find(|r| r.name == p.parameter.name()) {
            Some(r) => r.gaps.push((p.factor, p.gap_deg)),
            None => rows.push(Row {
                name: p.parameter.name(),
                gaps: vec![(p.factor, p.gap_deg)],
            }),
        }
    }
    let spread = |r: &Row<'_>| {
        r.gaps
            .iter()
            .map(|g| (g.1 - base).abs())
            .fold(0.0, f64::max)
    };
    // Smallest first: plotters' y axis grows upwards, so the largest lands on top.
    rows.sort_by(|a, b| spread(a).total_cmp(&spread(b)));
    rows
}

/// The tornado figure of `study` at `path`.
pub fn gap_tornado(path: &Path, study: &Study) -> Result<(), Error> {
    let base = study.baseline().map_or(0.0, |b| b.gap_deg);
    let rows = rows(study, base);
    let height = 120 + 34 * rows.len() as u32;
    let root = canvas(path, (900, height), !rows.is_empty())?;
    let e = draw_err(path);
    let xr = padded(
        rows.iter()
            .flat_map(|r| r.gaps.iter().map(|g| g.1))
            .chain([base, 0.0]),
        false,
    );
    let n = rows.len();
    let names: Vec<&str> = rows.iter().map(|r| r.name).collect();
    let label = |y: &f64| {
        let i = y.round();
        if (y - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < n {
            names[i as usize].to_string()
        } else {
            String::new()
        }
    };
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Dynamic - static test MAE gap per simulator parameter",
            (FAMILY, 22),
        )
        .margin(14)
        .x_label_area_size(45)
        .y_label_area_size(170)
        .build_cartesian_2d(xr.clone(), -0.6..(n as f64 - 0.4))
        .map_err(&e)?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(n)
        .y_label_formatter(&label)
        .x_label_formatter(&tick)
        .x_desc(format!(
            "gap (deg; above 0, static is better). Blue x0.5, red x1.5, black the baseline's {base:.3}"
        ))
        .label_style((FAMILY, 16))
        .axis_desc_style((FAMILY, 18))
        .draw()
        .map_err(&e)?;
    for (i, row) in rows.iter().enumerate() {
        let y = i as f64;
        for &(factor, gap) in &row.gaps {
            let (color, lo, hi) = if factor < 1.0 {
                (LOW, y, y + 0.32)
            } else {
                (HIGH, y - 0.32, y)
            };
            chart
                .draw_series([Rectangle::new(
                    [(base.min(gap), lo), (base.max(gap), hi)],
                    color.mix(0.8).filled(),
                )])
                .map_err(&e)?;
        }
    }
    let yr = (-0.6, n as f64 - 0.4);
    chart
        .draw_series([PathElement::new(
            vec![(base, yr.0), (base, yr.1)],
            BLACK.stroke_width(2),
        )])
        .map_err(&e)?;
    if xr.start < 0.0 {
        chart
            .draw_series([PathElement::new(
                vec![(0.0, yr.0), (0.0, yr.1)],
                RGBColor(127, 127, 127).stroke_width(1),
            )])
            .map_err(&e)?;
    }
    root.present().map_err(draw_err(path))?;
    Ok(())
}
