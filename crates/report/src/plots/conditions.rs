//! Test MAE against a condition, a line per representation: Experiment 3 (speed, depth) and
//! Experiment 1 at other background noise.

use super::*;
use evtac_experiments::results::{Exp3Point, NoisePoint};

/// One marker of an error-vs-condition panel: a representation's test MAE at `x`.
struct Marker {
    name: ReprKind,
    x: f64,
    stats: evtac_experiments::results::MeanStd,
    /// Filled (seen during training) or hollow (unseen).
    filled: bool,
}

impl Marker {
    fn new(
        name: ReprKind,
        x: f64,
        stats: evtac_experiments::results::MeanStd,
        filled: bool,
    ) -> Self {
        Self {
            name,
            x,
            stats,
            filled,
        }
    }
}

/// One panel of test MAE (mean ± std) against a condition, a line per representation.
fn mae_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    markers: &[Marker],
    (caption, desc): (&str, &str),
    path: &Path,
) -> Result<(), Error>
where
    DB::ErrorType: 'static,
{
    let e = draw_err(path);
    let xr = padded(markers.iter().map(|p| p.x), false);
    let yr = padded(
        markers
            .iter()
            .flat_map(|p| [p.stats.mean - p.stats.std, p.stats.mean + p.stats.std]),
        false,
    );
    let mut chart = xy_chart(area, (xr, yr), caption, (desc, "test MAE (deg)"), path)?;
    for name in ReprKind::ALL {
        let color = repr_color(name);
        let mut pts: Vec<&Marker> = markers.iter().filter(|p| p.name == name).collect();
        pts.sort_by(|a, b| a.x.total_cmp(&b.x));
        if pts.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(
                pts.iter().map(|p| (p.x, p.stats.mean)),
                color.stroke_width(2),
            ))
            .map_err(&e)?
            .label(name.title())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        let half = (pts[pts.len() - 1].x - pts[0].x).abs().max(1.0) * 0.012;
        for p in &pts {
            let s = p.stats;
            chart
                .draw_series(error_bar(
                    p.x,
                    s.mean - s.std,
                    s.mean + s.std,
                    half,
                    color.stroke_width(1),
                ))
                .map_err(&e)?;
        }
        chart
            .draw_series(pts.iter().map(|p| {
                let style = if p.filled {
                    color.filled()
                } else {
                    WHITE.filled()
                };
                Circle::new((p.x, p.stats.mean), 6, style)
            }))
            .map_err(&e)?;
        chart
            .draw_series(
                pts.iter()
                    .map(|p| Circle::new((p.x, p.stats.mean), 6, color.stroke_width(2))),
            )
            .map_err(&e)?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperRight, 16, path)
}

/// Experiment 3: test MAE against speed (left) and depth (right) per representation, mean ±
/// std over seeds; hollow markers are unseen levels.
pub fn speed_depth(path: &Path, speed: &[Exp3Point], depth: &[Exp3Point]) -> Result<(), Error> {
    let root = canvas(path, (1300, 520), !(speed.is_empty() && depth.is_empty()))?;
    let halves = root.split_evenly((1, 2));
    for (area, (points, axis, desc)) in halves.iter().zip([
        (speed, "speed", "speed (deg/s)"),
        (depth, "depth", "depth (mm)"),
    ]) {
        if points.is_empty() {
            continue;
        }
        let markers: Vec<Marker> = points
            .iter()
            .map(|p| Marker::new(p.name, p.value, p.stats.overall, p.seen))
            .collect();
        mae_panel(area, &markers, (&format!("Error vs {axis}"), desc), path)?;
    }
    root.present().map_err(draw_err(path))?;
    Ok(())
}

/// Experiment 1 at other background noise: test MAE against the noise factor per
/// representation, mean ± std over seeds.
pub fn noise(path: &Path, points: &[NoisePoint]) -> Result<(), Error> {
    let root = canvas(path, (800, 520), !points.is_empty())?;
    let markers: Vec<Marker> = points
        .iter()
        .map(|p| Marker::new(p.name, p.level, p.test.overall, true))
        .collect();
    mae_panel(
        &root,
        &markers,
        (
            "Error vs background noise",
            "noise factor (leak, shot, hot pixels)",
        ),
        path,
    )?;
    root.present().map_err(draw_err(path))?;
    Ok(())
}
