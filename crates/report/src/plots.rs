//! The report's figures as PNG, drawn with plotters, one figure family per submodule: the
//! charts ([`tuning_curves()`], [`phase_bars()`], [`example_curves()`] and [`overlays()`],
//! [`speed_depth()`] and [`noise()`], [`latency()`]) and the image figures
//! ([`representations()`], the paper's Fig. 2 for one sample, and [`sensor()`], the sensor's
//! camera view; the private `images` draws their pixels). What they share lives here: the
//! embedded font, the colours, [`Error`], the blank canvas every figure starts from, the legend,
//! tick labels, padded ranges, error bars and the captioned x-y chart.
//!
//! Text is rendered with DejaVu Sans, embedded in the binary (`assets/fonts/DejaVuSans.ttf`, from
//! Debian's `fonts-dejavu-core`; Bitstream Vera license with public-domain DejaVu changes, see
//! `assets/fonts/LICENSE-DejaVu.txt`), so figures look the same on every machine and need no
//! system fonts.

mod conditions;
mod examples;
pub(crate) mod images;
mod latency;
mod phases;
mod representations;
mod sensitivity;
mod sensor;
mod tuning;

pub use conditions::{noise, speed_depth};
pub use examples::{example_curves, overlays};
pub use latency::latency;
pub use phases::phase_bars;
pub use representations::representations;
pub use sensitivity::gap_tornado;
pub use sensor::sensor;
pub use tuning::tuning_curves;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use evtac_repr::ReprKind;

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
const REPR_COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
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

/// The color of a representation (one per [`ReprKind::ALL`], in that order; a kind added later
/// reuses the palette from the start until it gets a colour of its own).
pub(crate) fn repr_color(kind: ReprKind) -> RGBColor {
    // The enum's variants are declared in `ALL`'s order, so its discriminant is the index.
    REPR_COLORS[kind as usize % REPR_COLORS.len()]
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
