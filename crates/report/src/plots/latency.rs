//! The latency study's figure: latency distributions per representation and sampling interval.

use super::*;
use evtac_experiments::results::LatencyCell;

fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let i = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// Latency distributions per representation (one panel each): per sampling interval a box from
/// the 25th to the 75th percentile, the median, whiskers from min to max and the P99 as a
/// diamond, on a log time axis, with the interval itself (dashed) and the paper's 10 ms bound.
pub fn latency(path: &Path, cells: &[LatencyCell]) -> Result<(), Error> {
    let e = draw_err(path);
    let names = ReprKind::in_order(cells.iter().map(|c| c.name));
    let width = 500 * names.len().max(1) as u32;
    let root = canvas(path, (width, 520), !cells.is_empty())?;
    let areas = root.split_evenly((1, names.len().max(1)));
    let mut intervals: Vec<u32> = cells.iter().map(|c| c.interval_ms).collect();
    intervals.sort_unstable();
    intervals.dedup();
    let lo = cells
        .iter()
        .flat_map(|c| c.times_us.iter().copied())
        .filter(|v| *v > 0.0)
        .fold(f64::INFINITY, f64::min)
        .min(1_000.0)
        / 1.5;
    let lo = if lo.is_finite() { lo.max(0.1) } else { 1.0 };
    let hi = cells.iter().map(|c| c.max_us).fold(20_000.0f64, f64::max) * 1.5;
    for (area, name) in areas.iter().zip(names) {
        let color = repr_color(name);
        let n = intervals.len() as f64;
        let mut chart = ChartBuilder::on(area)
            .caption(name.title(), (FAMILY, 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0f64..n, (lo..hi).log_scale())
            .map_err(&e)?;
        let labels = intervals.clone();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(intervals.len() * 2 + 1)
            .x_label_formatter(&|x| {
                let i = (x - 0.5).round();
                if (x - 0.5 - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < labels.len() {
                    format!("{} ms", labels[i as usize])
                } else {
                    String::new()
                }
            })
            .x_desc("sampling interval")
            .y_desc("processing time per estimate (us)")
            .y_label_formatter(&tick)
            .label_style((FAMILY, 16))
            .axis_desc_style((FAMILY, 18))
            .draw()
            .map_err(&e)?;
        chart
            .draw_series(LineSeries::new(
                vec![(0.0, 10_000.0), (n, 10_000.0)],
                BLACK.stroke_width(2),
            ))
            .map_err(&e)?
            .label("10 ms bound (paper)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        let mut first = true;
        for (i, &iv) in intervals.iter().enumerate() {
            let x = i as f64 + 0.5;
            // The interval itself, dashed across this column.
            let ivus = f64::from(iv) * 1000.0;
            let dashes: Vec<_> = (0..6)
                .map(|k| {
                    let a = i as f64 + 0.05 + k as f64 * 0.15;
                    PathElement::new(
                        vec![(a, ivus), (a + 0.09, ivus)],
                        RGBColor(90, 90, 90).stroke_width(2),
                    )
                })
                .collect();
            let s = chart.draw_series(dashes).map_err(&e)?;
            if first {
                s.label("sampling interval").legend(|(x, y)| {
                    PathElement::new(
                        vec![(x, y), (x + 8, y)],
                        RGBColor(90, 90, 90).stroke_width(2),
                    )
                });
            }
            let Some(c) = cells.iter().find(|c| c.name == name && c.interval_ms == iv) else {
                continue;
            };
            let mut t: Vec<f64> = c.times_us.iter().copied().filter(|v| *v > 0.0).collect();
            t.sort_by(f64::total_cmp);
            if t.is_empty() {
                continue;
            }
            let (q1, q3) = (quantile(&t, 0.25), quantile(&t, 0.75));
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x, t[0]), (x, t[t.len() - 1])],
                    color.stroke_width(1),
                )))
                .map_err(&e)?;
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x - 0.2, q1), (x + 0.2, q3)],
                    color.mix(0.5).filled(),
                )))
                .map_err(&e)?;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x - 0.2, c.median_us), (x + 0.2, c.median_us)],
                    BLACK.stroke_width(3),
                )))
                .map_err(&e)?;
            let p99 = chart
                .draw_series(std::iter::once(TriangleMarker::new(
                    (x, c.p99_us),
                    7,
                    color.filled(),
                )))
                .map_err(&e)?;
            if first {
                p99.label("P99")
                    .legend(move |(x, y)| TriangleMarker::new((x + 10, y), 6, color.filled()));
                first = false;
            }
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft, 14, path)?;
    }
    root.present().map_err(&e)?;
    Ok(())
}
