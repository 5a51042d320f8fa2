//! The tuning figure: validation MAE against each representation parameter, the other at its
//! chosen value (the paper's tuning curves).

use super::*;
use evtac_experiments::results::Tuning;

/// One tuning panel: validation MAE against one parameter with the other fixed.
struct Curve {
    title: String,
    x_desc: String,
    points: Vec<(f64, f64)>,
    chosen: Option<f64>,
}

fn tuning_panels(tuning: &[Tuning]) -> Vec<Curve> {
    let mut out = Vec::new();
    for t in tuning {
        let label = t.repr.title();
        let time_desc = if t.repr == ReprKind::Static {
            "decay tau (ms)"
        } else {
            "window (ms)"
        };
        let th_desc = if t.repr == ReprKind::Static {
            "threshold (event contributions)"
        } else {
            "threshold (event count)"
        };
        let mut by_time: Vec<(f64, f64)> = t
            .runs
            .iter()
            .filter(|r| r.threshold == t.curve_threshold)
            .map(|r| (r.time_ms, r.val.overall))
            .collect();
        by_time.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut by_th: Vec<(f64, f64)> = t
            .runs
            .iter()
            .filter(|r| r.time_ms == t.curve_time_ms)
            .map(|r| (r.threshold, r.val.overall))
            .collect();
        by_th.sort_by(|a, b| a.0.total_cmp(&b.0));
        // The chosen point is highlighted where it lies on a curve.
        out.push(Curve {
            title: format!("{label}: threshold fixed at {}", t.curve_threshold),
            x_desc: time_desc.into(),
            points: by_time,
            chosen: (t.chosen_threshold == t.curve_threshold).then_some(t.chosen_time_ms),
        });
        out.push(Curve {
            title: format!(
                "{label}: {} fixed at {} ms",
                time_desc.split(' ').next().unwrap_or(""),
                t.curve_time_ms
            ),
            x_desc: th_desc.into(),
            points: by_th,
            chosen: (t.chosen_time_ms == t.curve_time_ms).then_some(t.chosen_threshold),
        });
    }
    out
}

/// Tuning curves (4 panels): validation MAE against decay tau and threshold (static), window and
/// threshold (dynamic), each with the other parameter at its chosen value.
pub fn tuning_curves(path: &Path, tuning: &[Tuning]) -> Result<(), Error> {
    let panels = tuning_panels(tuning);
    let e = draw_err(path);
    let root = canvas(path, (1200, 900), !panels.is_empty())?;
    let areas = root.split_evenly((2, 2));
    for (area, c) in areas.iter().zip(&panels) {
        let xr = padded(c.points.iter().map(|p| p.0), false);
        let yr = padded(c.points.iter().map(|p| p.1), false);
        let mut chart = xy_chart(
            area,
            (xr, yr),
            &c.title,
            (&c.x_desc, "validation MAE (deg)"),
            path,
        )?;
        chart
            .draw_series(LineSeries::new(
                c.points.clone(),
                REPR_COLORS[0].stroke_width(2),
            ))
            .map_err(&e)?;
        chart
            .draw_series(c.points.iter().map(|&(x, y)| {
                let chosen = c.chosen == Some(x);
                let style = if chosen {
                    REPR_COLORS[1].filled()
                } else {
                    REPR_COLORS[0].filled()
                };
                Circle::new((x, y), if chosen { 7 } else { 4 }, style)
            }))
            .map_err(&e)?;
    }
    root.present().map_err(&e)?;
    Ok(())
}
