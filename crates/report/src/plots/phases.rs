//! Experiment 2's figure: motion- and stop-phase MAE per representation and training setting.

use super::*;
use evtac_experiments::results::{Exp2Cell, Exp2Setting};

/// Motion- and stop-phase MAE (mean ± std over seeds) per representation and training setting.
pub fn phase_bars(path: &Path, cells: &[Exp2Cell]) -> Result<(), Error> {
    let e = draw_err(path);
    let names = ReprKind::in_order(cells.iter().map(|c| c.name));
    let root = canvas(
        path,
        (400 + 300 * names.len() as u32, 520),
        !cells.is_empty(),
    )?;
    let halves = root.split_evenly((1, 2));
    let slots = names.len().max(1) as f64;
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
            .build_cartesian_2d(0.0f64..slots, 0.0..top.max(1e-3))
            .map_err(&e)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(2 * names.len() + 1)
            .x_label_formatter(&|x| {
                let i = (x - 0.5).round();
                if (x - 0.5 - i).abs() < 1e-6 && (0.0..slots).contains(&i) {
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
        for (si, setting) in Exp2Setting::ALL.iter().enumerate() {
            let (key, label) = (*setting, setting.label());
            let color = SETTING_COLORS[si % 3];
            let mut first = true;
            for (ri, name) in names.iter().enumerate() {
                let Some(c) = cells.iter().find(|c| c.setting == key && c.name == *name) else {
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
                    series.label(label).legend(move |(x, y)| {
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
