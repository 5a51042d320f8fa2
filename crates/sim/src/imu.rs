//! The IMU beside the event camera: gyroscope and accelerometer samples consistent with the
//! commanded motion, in the IMU's own frame.
//!
//! The gyroscope reads `calibration.sensor_to_imu(sensor_angular_velocity(theta_dot, phi))`
//! (the convention of [`evtac_labels::geometry`]) times a per-axis scale `1 + s`, plus a
//! per-trial bias, white noise, and quantisation to the sensor's resolution. The accelerometer
//! reads the specific force of gravity: "up" in the world, which in the sensor frame is `-d`
//! (`d` the contact direction, pointing down onto the plane), again mapped into the IMU frame,
//! with bias, noise and quantisation. The robot's slow motion adds no noticeable linear
//! acceleration.
//!
//! The gyroscope's bias is not constant: it walks randomly during the trial
//! (`gyro_bias_walk_deg_s_per_sqrt_s`), so the bias measured before onset is a little off by the
//! end. The timestamps are the events' clock plus a per-trial offset and a per-sample jitter
//! (`clock_offset_sd_us`, `clock_jitter_us`): the IMU is sampled and stamped through its own
//! path. The walk and the clock come from a second random stream (`clock_seed`), so with both
//! off the samples are those of a constant-bias IMU on the events' clock.

use evtac_events::ImuSample;
use evtac_labels::geometry::{Calibration, contact_direction, sensor_angular_velocity};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::dvs::gaussian;
use crate::params::ImuParams;
use crate::protocol::Motion;

/// Simulates the IMU over the whole recording of a trial with tilt direction `phi_deg`.
pub fn simulate_imu(
    params: &ImuParams,
    calibration: &Calibration,
    motion: &Motion,
    phi_deg: f64,
    seed: u64,
    clock_seed: u64,
) -> Vec<ImuSample> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut drift_rng = ChaCha8Rng::seed_from_u64(clock_seed);
    let offset_us = params.clock_offset_sd_us * gaussian(&mut drift_rng);
    // Mutable: the bias walks during the trial (below).
    let mut gyro_bias: [f64; 3] =
        std::array::from_fn(|_| params.gyro_bias_deg_s * gaussian(&mut rng));
    let gyro_scale: [f64; 3] =
        std::array::from_fn(|_| 1.0 + params.gyro_scale_error * gaussian(&mut rng));
    let accel_bias: [f64; 3] = std::array::from_fn(|_| params.accel_bias_g * gaussian(&mut rng));
    let period_us = (1e6 / params.rate_hz.max(1.0)).round().max(1.0) as i64;
    let end_us = (motion.end_s * 1e6).round() as i64;
    let quantise = |v: f64, lsb: f64| {
        if lsb > 0.0 {
            (v / lsb).round() * lsb
        } else {
            v
        }
    };
    // The walk's step per sample: its standard deviation grows with the square root of time.
    let walk = params.gyro_bias_walk_deg_s_per_sqrt_s * (period_us as f64 * 1e-6).sqrt();
    let mut out: Vec<ImuSample> = Vec::with_capacity((end_us / period_us + 1) as usize);
    let mut t_us = 0;
    while t_us <= end_us {
        let t = t_us as f64 * 1e-6;
        let omega =
            calibration.sensor_to_imu(sensor_angular_velocity(motion.theta_dot(t), phi_deg));
        let d = contact_direction(motion.theta(t), phi_deg);
        let up = calibration.sensor_to_imu([-d[0], -d[1], -d[2]]);
        let gyroscope = std::array::from_fn(|i| {
            let v = omega[i] * gyro_scale[i]
                + gyro_bias[i]
                + params.gyro_noise_deg_s * gaussian(&mut rng);
            quantise(v, params.gyro_lsb_deg_s) as f32
        });
        let accelerometer = std::array::from_fn(|i| {
            let v = up[i] + accel_bias[i] + params.accel_noise_g * gaussian(&mut rng);
            quantise(v, params.accel_lsb_g) as f32
        });
        if walk > 0.0 {
            for b in &mut gyro_bias {
                *b += walk * gaussian(&mut drift_rng);
            }
        }
        // The stamp: offset and jitter on the true sample time, kept increasing and inside the
        // recording.
        let jitter = params.clock_jitter_us * gaussian(&mut drift_rng);
        let stamp = (t_us as f64 + offset_us + jitter).round() as i64;
        let after_last = out.last().map_or(0, |s| s.t + 1);
        if stamp >= 0 && stamp.max(after_last) <= end_us {
            out.push(ImuSample {
                t: stamp.max(after_last),
                accelerometer,
                gyroscope,
                temperature: params.temperature_c as f32,
            });
        }
        t_us += period_us;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::TimelineParams;
    use crate::protocol::{Protocol, Scale, plan};
    use evtac_labels::geometry::axial_rate;

    #[test]
    fn integrated_gyro_recovers_the_tilt() {
        let tl = TimelineParams::default();
        let spec = plan(Protocol::Exp1, Scale::Tiny, 5, &tl).remove(3);
        let motion = Motion::new(&spec, &tl, 0.5);
        let cal = Calibration {
            imu_to_sensor: [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            tip_radius_mm: 20.0,
        };
        let params = ImuParams {
            clock_offset_sd_us: 0.0,
            clock_jitter_us: 0.0,
            ..ImuParams::default()
        };
        let imu = simulate_imu(&params, &cal, &motion, spec.direction_deg, 9, 10);
        assert_eq!(imu[1].t - imu[0].t, 1250);
        // Bias from the rest before the motion, then integrate the axial rate.
        let rest: Vec<_> = imu
            .iter()
            .filter(|s| (s.t as f64) < motion.motion_start_s * 1e6)
            .collect();
        let bias: [f64; 3] = std::array::from_fn(|i| {
            rest.iter().map(|s| f64::from(s.gyroscope[i])).sum::<f64>() / rest.len() as f64
        });
        let mut theta = 0.0;
        for s in &imu {
            let w: [f64; 3] = std::array::from_fn(|i| f64::from(s.gyroscope[i]) - bias[i]);
            theta += axial_rate(cal.imu_to_sensor(w), spec.direction_deg) * 1250e-6;
        }
        // Within the unknown scale error (1 % sigma) of the true 20 degrees.
        assert!((theta - 20.0).abs() < 1.0, "{theta}");
        // Gravity says the same: the accelerometer's tilt at the end.
        let last = imu.last().unwrap();
        let up = cal.imu_to_sensor(last.accelerometer.map(f64::from));
        let tilt = (-up[2]).acos().to_degrees();
        assert!((tilt - 20.0).abs() < 0.5, "{tilt}");
    }

    #[test]
    fn stamps_carry_the_clock_offset_and_jitter_and_the_bias_walks() {
        let tl = TimelineParams::default();
        let spec = plan(Protocol::Exp1, Scale::Tiny, 5, &tl).remove(0);
        let motion = Motion::new(&spec, &tl, 0.5);
        let cal = Calibration {
            imu_to_sensor: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            tip_radius_mm: 20.0,
        };
        let quiet = ImuParams {
            gyro_bias_deg_s: 0.0,
            gyro_noise_deg_s: 0.0,
            gyro_lsb_deg_s: 0.0,
            gyro_bias_walk_deg_s_per_sqrt_s: 0.0,
            clock_offset_sd_us: 0.0,
            clock_jitter_us: 0.0,
            ..ImuParams::default()
        };
        let base = simulate_imu(&quiet, &cal, &motion, 0.0, 1, 2);
        assert!(base.iter().enumerate().all(|(k, s)| s.t == 1250 * k as i64));
        let clocked = ImuParams {
            clock_offset_sd_us: 500.0,
            clock_jitter_us: 30.0,
            ..quiet.clone()
        };
        let imu = simulate_imu(&clocked, &cal, &motion, 0.0, 1, 2);
        assert!(imu.windows(2).all(|w| w[0].t < w[1].t));
        // The same samples restamped (the first few dropped when the offset is negative, the last
        // few when positive): the offset is the mean shift, the jitter its spread.
        let shifts = |dropped: usize| -> Vec<f64> {
            imu.iter()
                .zip(&base[dropped..])
                .map(|(s, b)| (s.t - b.t) as f64)
                .collect()
        };
        let spread = |v: &[f64]| {
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let sd = (v.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
            (mean, sd)
        };
        let (mean, sd) = (0..3)
            .map(|d| spread(&shifts(d)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        assert!(mean.abs() > 1.0 && mean.abs() < 2000.0, "{mean}");
        assert!((sd - 30.0).abs() < 6.0, "{sd}");
        // A walking bias: the still lead-in's rate no longer matches the end's.
        let walking = ImuParams {
            gyro_bias_walk_deg_s_per_sqrt_s: 0.5,
            ..quiet
        };
        let imu = simulate_imu(&walking, &cal, &motion, 0.0, 1, 2);
        let (first, last) = (imu[0].gyroscope[2], imu.last().unwrap().gyroscope[2]);
        assert!((first - last).abs() > 0.01, "{first} {last}");
    }
}
