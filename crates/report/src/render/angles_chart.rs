//! The angles panel drawn: pitch (left) and roll (right) over the rendered span as the report's
//! example curves draw them (plotters charts, the representations' colours), the model's
//! estimates beside the IMU labels and the simulator's truth, with a cursor at the current
//! frame.

use super::angles::Angles;
use super::frames::Timing;
use crate::plots::{Error, FAMILY, draw_err, legend, padded, repr_color, tick};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The truth's colour: grey, so the label and the estimate stay in front (one of the
/// features' greys, which the GIF palette holds exactly).
pub(crate) const TRUTH: RGBColor = RGBColor(148, 148, 148);

/// Draws `angles` on `area` with the cursor at `t_us` (`timing` gives the time axis, seconds
/// from its start; the output at `path`).
pub fn draw_angles<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    angles: &Angles,
    t_us: i64,
    timing: &Timing,
    path: &Path,
) -> Result<(), Error> {
    let e = draw_err(path);
    let secs = |t: i64| (t - timing.start_us) as f64 / 1e6;
    let t_s: Vec<f64> = angles.t_us.iter().map(|&t| secs(t)).collect();
    let end_s = secs(timing.end_us(timing.count.saturating_sub(1)));
    let name = angles.model_repr;
    let estimate = repr_color(name);
    for (k, (half, what)) in area
        .split_evenly((1, 2))
        .iter()
        .zip(["Pitch", "Roll"])
        .enumerate()
    {
        let references = [&angles.labels, &angles.truth]
            .into_iter()
            .flatten()
            .flat_map(|r| r.iter().map(move |v| v[k]));
        let yr = padded(
            angles
                .estimates
                .iter()
                .map(|v| f64::from(v[k]))
                .chain(references),
            false,
        );
        let (y0, y1) = (yr.start, yr.end);
        let mut chart = ChartBuilder::on(half)
            .margin(6)
            .x_label_area_size(34)
            .y_label_area_size(52)
            .build_cartesian_2d(0.0..end_s.max(1e-6), yr)
            .map_err(&e)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc(format!("{} (deg)", what.to_lowercase()))
            .x_labels(6)
            .y_labels(5)
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .label_style((FAMILY, 14))
            .axis_desc_style((FAMILY, 14))
            .draw()
            .map_err(&e)?;
        let references = [
            (&angles.truth, TRUTH, "truth".to_string()),
            (&angles.labels, BLACK, "IMU label".to_string()),
        ];
        let points: Vec<(f64, f64)> = t_s
            .iter()
            .zip(&angles.estimates)
            .map(|(&t, v)| (t, f64::from(v[k])))
            .collect();
        // Truth first, then the label, then the estimate: the estimate is drawn on top.
        let lines = references
            .into_iter()
            .filter_map(|(values, color, label)| {
                let values = values.as_ref()?;
                let pts = t_s.iter().zip(values).map(|(&t, v)| (t, v[k])).collect();
                Some((pts, color, label))
            })
            .chain(std::iter::once((points, estimate, format!("{name} model"))));
        for (pts, color, label) in lines {
            chart
                .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(&e)?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
        }
        let now = secs(t_us);
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(now, y0), (now, y1)],
                BLACK.stroke_width(1),
            )))
            .map_err(&e)?;
        legend(&mut chart, SeriesLabelPosition::UpperLeft, 13, path)?;
    }
    Ok(())
}
