//! A recording's statistics as simulator parameters (`evtac stats --sim-params`): the fields
//! the recording measures replaced in a base parameter set (the defaults), everything else kept,
//! and a list of what was replaced and from what, so the file's provenance can be told.
//!
//! Replaced when measured: the sensor's size, the leak and shot noise rates (the background's
//! ON excess and the rest), the hot pixels' number and rate range, and the IMU's rate, noise,
//! bias, resolution and temperature. The thresholds, the photoreceptor, the contact model and
//! the accelerometer's bias (indistinguishable from gravity at an unknown tilt) cannot be read
//! from a sensor at rest and keep the base's values.

use evtac_sim::SimParams;
use serde::Serialize;

use super::SensorStats;

/// One replaced field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measured {
    /// The field's path in the parameter file (`dvs.leak_rate_hz`).
    pub field: &'static str,
    /// Its new value, as written.
    pub value: String,
    /// What it was measured from.
    pub from: String,
}

/// The parameters and what in them was measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Fitted {
    /// The base's parameters with the measured fields replaced.
    pub params: SimParams,
    /// The replaced fields, in the parameter file's order.
    pub measured: Vec<Measured>,
}

/// `base` with every field `stats` measures replaced.
pub fn fit(stats: &SensorStats, base: SimParams) -> Fitted {
    let mut p = base;
    let mut measured = Vec::new();
    let mut note = |field: &'static str, value: String, from: String| {
        measured.push(Measured { field, value, from });
    };
    p.camera.width = stats.resolution.width;
    p.camera.height = stats.resolution.height;
    note(
        "camera.width",
        p.camera.width.to_string(),
        "the file's header".into(),
    );
    note(
        "camera.height",
        p.camera.height.to_string(),
        "the file's header".into(),
    );
    if let Some(bg) = &stats.background {
        let at_rest = format!("{:.1} s at rest, {} pixels", bg.rest_s, bg.pixels);
        p.dvs.leak_rate_hz = bg.leak_rate_hz();
        p.dvs.shot_noise_rate_hz = bg.shot_rate_hz();
        let on = bg
            .on_fraction()
            .map_or_else(|| "-".into(), |f| format!("{f:.3}"));
        note(
            "dvs.leak_rate_hz",
            format!("{:.5}", p.dvs.leak_rate_hz),
            format!("ON minus OFF rate per pixel ({at_rest}, ON fraction {on})"),
        );
        note(
            "dvs.shot_noise_rate_hz",
            format!("{:.5}", p.dvs.shot_noise_rate_hz),
            format!("the rest of the background rate {:.5} Hz", bg.rate_hz()),
        );
        p.dvs.hot_pixels = u32::try_from(stats.hot.len()).unwrap_or(u32::MAX);
        note(
            "dvs.hot_pixels",
            p.dvs.hot_pixels.to_string(),
            format!("pixels with at least {} events at rest", bg.hot_threshold),
        );
        if let Some(range) = uniform_range(stats.hot.iter().map(|h| h.rate_hz)) {
            p.dvs.hot_pixel_rate_hz = range;
            note(
                "dvs.hot_pixel_rate_hz",
                format!("[{:.2}, {:.2}]", range[0], range[1]),
                "the hot pixels' rates (the range of a uniform draw that gives them)".into(),
            );
        }
    }
    if let Some(imu) = &stats.imu {
        let at_rest = format!("{} samples at rest", imu.rest_samples);
        p.imu.rate_hz = imu.rate_hz;
        note(
            "imu.rate_hz",
            format!("{:.2}", imu.rate_hz),
            format!("{} samples", imu.samples),
        );
        p.imu.gyro_noise_deg_s = imu.gyro_noise_deg_s;
        note(
            "imu.gyro_noise_deg_s",
            format!("{:.5}", imu.gyro_noise_deg_s),
            format!("consecutive differences ({at_rest})"),
        );
        p.imu.gyro_bias_deg_s = imu.gyro_bias_deg_s;
        note(
            "imu.gyro_bias_deg_s",
            format!("{:.4}", imu.gyro_bias_deg_s),
            format!("{} windows' means at rest", imu.windows),
        );
        if let Some(lsb) = imu.gyro_lsb_deg_s {
            p.imu.gyro_lsb_deg_s = lsb;
            note(
                "imu.gyro_lsb_deg_s",
                format!("{lsb:.6}"),
                "the smallest step at rest".into(),
            );
        }
        p.imu.accel_noise_g = imu.accel_noise_g;
        note(
            "imu.accel_noise_g",
            format!("{:.6}", imu.accel_noise_g),
            format!("consecutive differences ({at_rest})"),
        );
        if let Some(lsb) = imu.accel_lsb_g {
            p.imu.accel_lsb_g = lsb;
            note(
                "imu.accel_lsb_g",
                format!("{lsb:.7}"),
                "the smallest step at rest".into(),
            );
        }
        if let Some(t) = imu.temperature_c {
            p.imu.temperature_c = t;
            note(
                "imu.temperature_c",
                format!("{t:.1}"),
                format!("the mean at rest ({at_rest})"),
            );
        }
    }
    Fitted {
        params: p,
        measured,
    }
}

/// The range `[lo, hi]` of a uniform distribution that `rates` were drawn from: the smallest
/// and largest widened by the mean gap between the sorted draws (the unbiased estimate; the
/// draws themselves always fall inside the true range). `None` without rates.
pub fn uniform_range(rates: impl Iterator<Item = f64>) -> Option<[f64; 2]> {
    let (mut lo, mut hi, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0u32);
    for r in rates {
        lo = lo.min(r);
        hi = hi.max(r);
        n += 1;
    }
    match n {
        0 => None,
        1 => Some([lo, hi]),
        _ => {
            let gap = (hi - lo) / f64::from(n - 1);
            Some([(lo - gap).max(0.0), hi + gap])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_range_widens_the_extremes_by_the_mean_gap() {
        assert_eq!(uniform_range([].into_iter()), None);
        assert_eq!(uniform_range([7.0].into_iter()), Some([7.0, 7.0]));
        assert_eq!(
            uniform_range([30.0, 40.0, 50.0].into_iter()),
            Some([20.0, 60.0])
        );
        assert_eq!(uniform_range([1.0, 5.0].into_iter()), Some([0.0, 9.0]));
    }
}
