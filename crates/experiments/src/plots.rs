//! The report's figures as PNG, drawn with plotters: the charts here, the image figures in
//! submodules ([`representations()`], the paper's Fig. 2 for one sample, and [`sensor()`], the
//! sensor's camera view; the private `images` draws their pixels).
//!
//! Text is rendered with DejaVu Sans, embedded in the binary (`assets/fonts/DejaVuSans.ttf`, from
//! Debian's `fonts-dejavu-core`; Bitstream Vera license with public-domain DejaVu changes, see
//! `assets/fonts/LICENSE-DejaVu.txt`), so figures look the same on every machine and need no
//! system fonts.

pub(crate) mod images;
mod representations;
mod sensor;

pub use representations::representations;
pub use sensor::sensor;

use crate::results::{ExampleTrial, Exp2Cell, Exp3Point, LatencyCell, NoisePoint, Overlay, Tuning};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The embedded font (DejaVu Sans, Bitstream Vera license).
static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
/// The font family name figures use.
///
/// Every text size in this file is even: plotters 0.3.7's ab_glyph renderer places each glyph
/// at `(size / 2 + top) as i32`, which truncates toward zero, so at odd sizes glyphs above and
/// below that line round in opposite directions and a decimal point sits a pixel above the
/// digits' baseline.
pub(crate) const FAMILY: &str = "sans-serif";

/// Colors of the three representations, used in every figure.
const REPR_COLORS: [RGBColor; 3] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
];
/// Colors of Experiment 2's three training settings.
const SETTING_COLORS: [RGBColor; 3] = [
    RGBColor(127, 127, 127),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
];

/// Errors drawing a figure.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The embedded font could not be registered.
    #[error("the embedded DejaVu Sans font could not be registered with plotters")]
    Font,
    /// Drawing or writing the PNG failed.
    #[error("{}: drawing failed: {message}", path.display())]
    Draw {
        /// The figure file.
        path: PathBuf,
        /// plotters' message.
        message: String,
    },
    /// There is nothing to draw.
    #[error("{}: no data for this figure", path.display())]
    Empty {
        /// The figure file.
        path: PathBuf,
    },
}

pub(crate) fn register_font() -> Result<(), Error> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE
        .get_or_init(|| plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_ok());
    if ok { Ok(()) } else { Err(Error::Font) }
}

pub(crate) fn draw_err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> Error + '_ {
    move |e| Error::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// A white canvas of `size` pixels for the figure at `path`, the font registered, or
/// [`Error::Empty`] when there is no data to draw: where every figure starts (it ends with
/// `present()`).
fn canvas(
    path: &Path,
    size: (u32, u32),
    has_data: bool,
) -> Result<DrawingArea<BitMapBackend<'_>, Shift>, Error> {
    if !has_data {
        return Err(Error::Empty {
            path: path.to_path_buf(),
        });
    }
    register_font()?;
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(draw_err(path))?;
    Ok(root)
}

/// The legend every figure uses: translucent white, framed, at `position` with labels of
/// `font_size` (for the figure at `path`).
pub(crate) fn legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    font_size: u32,
    path: &Path,
) -> Result<(), Error>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(position)
        .label_font((FAMILY, font_size))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(draw_err(path))
}

/// The color of a representation by name (`Static`, `Dynamic`, `Combined`).
pub(crate) fn repr_color(name: &str) -> RGBColor {
    match name {
        "Static" => REPR_COLORS[0],
        "Dynamic" => REPR_COLORS[1],
        _ => REPR_COLORS[2],
    }
}

/// A tick label: at most three decimals, without trailing zeros (`5.5`, `100`, `0.25`).
pub(crate) fn tick(v: &f64) -> String {
    let text = format!("{v:.3}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// A padded range around `values` (never empty).
pub(crate) fn padded(values: impl Iterator<Item = f64>, floor_zero: bool) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((hi - lo) * 0.1).max(1e-3 + hi.abs() * 0.05);
    let lo = if floor_zero { 0.0 } else { lo - pad };
    lo..hi + pad
}

/// A vertical error bar from `lo` to `hi` at `x`, with caps `half` wide on each side (drawn
/// by hand: plotters' `ErrorBar` sits behind a feature the workspace does not enable).
fn error_bar(
    x: f64,
    lo: f64,
    hi: f64,
    half: f64,
    style: ShapeStyle,
) -> Vec<PathElement<(f64, f64)>> {
    vec![
        PathElement::new(vec![(x, lo), (x, hi)], style),
        PathElement::new(vec![(x - half, lo), (x + half, lo)], style),
        PathElement::new(vec![(x - half, hi), (x + half, hi)], style),
    ]
}

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
        let label = if t.repr == "static" {
            "Static"
        } else {
            "Dynamic"
        };
        let time_desc = if t.repr == "static" {
            "decay tau (ms)"
        } else {
            "window (ms)"
        };
        let th_desc = if t.repr == "static" {
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

/// Motion- and stop-phase MAE (mean ± std over seeds) per representation and training setting.
pub fn phase_bars(path: &Path, cells: &[Exp2Cell], settings: &[(&str, &str)]) -> Result<(), Error> {
    let e = draw_err(path);
    let root = canvas(path, (1300, 520), !cells.is_empty())?;
    let halves = root.split_evenly((1, 2));
    let names = ["Static", "Dynamic", "Combined"];
    for (pi, (area, phase)) in halves
        .iter()
        .zip(["Motion phase", "Stop phase"])
        .enumerate()
    {
        let stat = |c: &Exp2Cell| {
            if pi == 0 {
                c.motion.overall
            } else {
                c.stop.overall
            }
        };
        let top = cells
            .iter()
            .map(|c| stat(c).mean + stat(c).std)
            .fold(0.0f64, f64::max)
            * 1.25;
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{phase} MAE"), (FAMILY, 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(65)
            .build_cartesian_2d(0.0f64..3.0, 0.0..top.max(1e-3))
            .map_err(&e)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(7)
            .x_label_formatter(&|x| {
                let i = (x - 0.5).round();
                if (x - 0.5 - i).abs() < 1e-6 && (0.0..3.0).contains(&i) {
                    names[i as usize].to_string()
                } else {
                    String::new()
                }
            })
            .y_desc("test MAE (deg)")
            .label_style((FAMILY, 16))
            .axis_desc_style((FAMILY, 18))
            .y_label_formatter(&tick)
            .draw()
            .map_err(&e)?;
        for (si, (key, label)) in settings.iter().enumerate() {
            let color = SETTING_COLORS[si % 3];
            let mut first = true;
            for (ri, name) in names.iter().enumerate() {
                let Some(c) = cells.iter().find(|c| c.setting == *key && c.name == *name) else {
                    continue;
                };
                let s = stat(c);
                if s.n == 0 {
                    continue;
                }
                let x0 = ri as f64 + 0.15 + si as f64 * 0.23;
                let x1 = x0 + 0.2;
                let series = chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(x0, 0.0), (x1, s.mean)],
                        color.filled(),
                    )))
                    .map_err(&e)?;
                if first {
                    series.label(*label).legend(move |(x, y)| {
                        Rectangle::new([(x, y - 6), (x + 16, y + 6)], color.filled())
                    });
                    first = false;
                }
                chart
                    .draw_series(error_bar(
                        (x0 + x1) / 2.0,
                        (s.mean - s.std).max(0.0),
                        s.mean + s.std,
                        0.04,
                        BLACK.stroke_width(2),
                    ))
                    .map_err(&e)?;
            }
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight, 16, path)?;
    }
    root.present().map_err(&e)?;
    Ok(())
}

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
            let color = repr_color(name);
            let pts: Vec<(f64, f64)> = ex
                .t_s
                .iter()
                .zip(pred)
                .map(|(&t, v)| (t, f64::from(v[k])))
                .collect();
            chart
                .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(&e)?
                .label(name.as_str())
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

/// A captioned x-y chart on `area` over `ranges`, its mesh labelled `descs` (x, y), as every
/// line figure draws it.
fn xy_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    (xr, yr): (std::ops::Range<f64>, std::ops::Range<f64>),
    caption: &str,
    (x_desc, y_desc): (&str, &str),
    path: &Path,
) -> Result<
    ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    Error,
>
where
    DB::ErrorType: 'static,
{
    let e = draw_err(path);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(65)
        .build_cartesian_2d(xr, yr)
        .map_err(&e)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FAMILY, 16))
        .axis_desc_style((FAMILY, 18))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()
        .map_err(&e)?;
    Ok(chart)
}

/// One marker of an error-vs-condition panel: a representation's test MAE at `x`.
struct Marker<'a> {
    name: &'a str,
    x: f64,
    stats: crate::results::MeanStd,
    /// Filled (seen during training) or hollow (unseen).
    filled: bool,
}

impl<'a> Marker<'a> {
    fn new(name: &'a str, x: f64, stats: crate::results::MeanStd, filled: bool) -> Self {
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
    markers: &[Marker<'_>],
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
    for name in ["Static", "Dynamic", "Combined"] {
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
            .label(name)
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
            .map(|p| Marker::new(&p.name, p.value, p.stats.overall, p.seen))
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
        .map(|p| Marker::new(&p.name, p.level, p.test.overall, true))
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
    let root = canvas(path, (1500, 520), !cells.is_empty())?;
    let names = ["Static", "Dynamic", "Combined"];
    let areas = root.split_evenly((1, 3));
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
            .caption(name, (FAMILY, 22))
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
