//! Synthetic IMU streams with an exactly known tilt: trapezoidal speed profiles like a robot's,
//! seen through a gyroscope with bias, scale error, white noise, quantization, timestamp jitter
//! and rotated extrinsics.

use evtac_events::ImuSample;
use evtac_labels::geometry::{self, Calibration};
use evtac_labels::{LabelSeries, Stop, TrialMotion};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// The DVXplorer's gyroscope resolution: 250 deg/s full scale in 16 bits.
pub const GYRO_LSB_DEG_S: f64 = 250.0 / 32768.0;

/// A stretch of constant acceleration: the rate goes linearly from `v0` to `v1`.
#[derive(Debug, Clone, Copy)]
struct Segment {
    start_us: i64,
    end_us: i64,
    v0: f64,
    v1: f64,
    theta0: f64,
}

struct Builder {
    segments: Vec<Segment>,
    t: i64,
    theta: f64,
    speed: f64,
    accel: f64,
}

impl Builder {
    fn push(&mut self, dur_us: i64, v0: f64, v1: f64) {
        self.segments.push(Segment {
            start_us: self.t,
            end_us: self.t + dur_us,
            v0,
            v1,
            theta0: self.theta,
        });
        self.theta += 0.5 * (v0 + v1) * dur_us as f64 * 1e-6;
        self.t += dur_us;
    }

    fn hold(&mut self, dur_us: i64) {
        self.push(dur_us, 0.0, 0.0);
    }

    /// A move of `delta` degrees: ramp up, cruise, ramp down. Durations are whole
    /// microseconds, and the cruise speed is adjusted so that they cover `delta` exactly.
    fn move_by(&mut self, delta: f64) {
        let ramp_us = (self.speed / self.accel * 1e6).round().max(1.0) as i64;
        let ramp_s = ramp_us as f64 * 1e-6;
        let cruise_s = (delta - self.speed * ramp_s) / self.speed;
        assert!(cruise_s > 0.0, "move too short for its ramps");
        let cruise_us = (cruise_s * 1e6).round() as i64;
        let v = delta / (ramp_s + cruise_us as f64 * 1e-6);
        self.push(ramp_us, 0.0, v);
        self.push(cruise_us, v, v);
        self.push(ramp_us, v, 0.0);
    }
}

/// A tilt trajectory made of linear-rate segments (exact rate and angle at any time).
#[derive(Debug, Clone)]
pub struct Profile {
    segments: Vec<Segment>,
    pub motion: TrialMotion,
    pub end_us: i64,
}

impl Profile {
    /// Still for `still_us`, then towards `total_deg` at `speed` with acceleration `accel`
    /// (deg/s^2), stopping for `stop_us` at `stop_deg` if given, then still for `still_us`.
    pub fn new(
        phi: f64,
        speed: f64,
        accel: f64,
        total_deg: f64,
        stop: Option<(f64, i64)>,
        still_us: i64,
    ) -> Self {
        let mut b = Builder {
            segments: Vec::new(),
            t: 0,
            theta: 0.0,
            speed,
            accel,
        };
        b.hold(still_us);
        let motion_start_us = b.t;
        let mut stop_meta = None;
        match stop {
            Some((stop_deg, stop_us)) => {
                b.move_by(stop_deg);
                let start_us = b.t;
                b.hold(stop_us);
                stop_meta = Some(Stop {
                    start_us,
                    end_us: b.t,
                    deg: stop_deg,
                });
                b.move_by(total_deg - stop_deg);
            }
            None => b.move_by(total_deg),
        }
        let motion_end_us = b.t;
        b.hold(still_us);
        let (segments, t) = (b.segments, b.t);
        Self {
            segments,
            end_us: t,
            motion: TrialMotion {
                direction_deg: phi,
                speed_deg_s: speed,
                total_deg,
                motion_start_us,
                motion_end_us,
                stop: stop_meta,
            },
        }
    }

    fn segment(&self, t_us: i64) -> &Segment {
        let i = self.segments.partition_point(|s| s.end_us <= t_us);
        &self.segments[i.min(self.segments.len() - 1)]
    }

    /// The exact tilt rate, deg/s.
    pub fn rate(&self, t_us: i64) -> f64 {
        let s = self.segment(t_us);
        if t_us < s.start_us || t_us >= s.end_us {
            return 0.0;
        }
        let w = (t_us - s.start_us) as f64 / (s.end_us - s.start_us) as f64;
        s.v0 + w * (s.v1 - s.v0)
    }

    /// The exact tilt, degrees.
    pub fn theta(&self, t_us: i64) -> f64 {
        let s = self.segment(t_us);
        let dt = ((t_us.clamp(s.start_us, s.end_us) - s.start_us) as f64) * 1e-6;
        let dur = (s.end_us - s.start_us) as f64 * 1e-6;
        let a = if dur > 0.0 { (s.v1 - s.v0) / dur } else { 0.0 };
        s.theta0 + s.v0 * dt + 0.5 * a * dt * dt
    }

    /// The exact truth sampled every `step_us`.
    pub fn truth(&self, step_us: i64) -> LabelSeries {
        let phi = self.motion.direction_deg;
        let t_us: Vec<i64> = (0..=self.end_us / step_us).map(|k| k * step_us).collect();
        let theta_deg: Vec<f64> = t_us.iter().map(|&t| self.theta(t)).collect();
        let (pitch_deg, roll_deg) = theta_deg
            .iter()
            .map(|&th| geometry::contact_angles(th, phi))
            .unzip();
        LabelSeries {
            t_us,
            theta_deg,
            pitch_deg,
            roll_deg,
        }
    }
}

/// How the synthetic gyroscope errs.
#[derive(Debug, Clone, Copy)]
pub struct Gyro {
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Timestamp jitter (uniform, +-), us.
    pub jitter_us: i64,
    /// Constant bias per IMU axis, deg/s.
    pub bias: [f64; 3],
    /// Relative scale error (the gyro reads `(1 + scale_error)` times the truth).
    pub scale_error: f64,
    /// White noise per axis, deg/s (standard deviation per sample).
    pub noise: f64,
    /// Quantization step, deg/s (0 for none).
    pub lsb: f64,
}

impl Gyro {
    /// A DVXplorer-like IMU: 800 Hz, biased, 3 % scale error, noisy and quantized.
    pub fn realistic() -> Self {
        Self {
            fs_hz: 800.0,
            jitter_us: 20,
            bias: [0.41, -0.27, 0.19],
            scale_error: 0.03,
            noise: 0.12,
            lsb: GYRO_LSB_DEG_S,
        }
    }

    /// A perfect gyroscope at 800 Hz.
    pub fn ideal() -> Self {
        Self {
            fs_hz: 800.0,
            jitter_us: 0,
            bias: [0.0; 3],
            scale_error: 0.0,
            noise: 0.0,
            lsb: 0.0,
        }
    }

    /// The IMU stream this gyroscope records of `profile` through `calibration`'s extrinsics.
    pub fn record(
        &self,
        profile: &Profile,
        calibration: &Calibration,
        seed: u64,
    ) -> Vec<ImuSample> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, self.noise.max(f64::MIN_POSITIVE)).expect("valid sigma");
        let period = 1e6 / self.fs_hz;
        let phi = profile.motion.direction_deg;
        let n = (profile.end_us as f64 / period) as i64;
        (0..n)
            .map(|k| {
                let jitter = if self.jitter_us > 0 {
                    rng.random_range(-self.jitter_us..=self.jitter_us)
                } else {
                    0
                };
                let t = ((k as f64 * period).round() as i64 + jitter).max(0);
                let rate = profile.rate(t) * (1.0 + self.scale_error);
                let omega = calibration.sensor_to_imu(geometry::sensor_angular_velocity(rate, phi));
                let gyroscope = std::array::from_fn(|i| {
                    let noise = if self.noise > 0.0 {
                        normal.sample(&mut rng)
                    } else {
                        0.0
                    };
                    let v = omega[i] + self.bias[i] + noise;
                    let q = if self.lsb > 0.0 {
                        (v / self.lsb).round() * self.lsb
                    } else {
                        v
                    };
                    q as f32
                });
                ImuSample {
                    t,
                    accelerometer: [0.0, 0.0, -1.0],
                    gyroscope,
                    temperature: 35.0,
                }
            })
            .collect()
    }
}

/// Extrinsics with the IMU turned 90 deg about z and tilted 2 deg about x, so that a wrong
/// frame shows.
pub fn rotated_calibration() -> Calibration {
    let (c, s) = (2f64.to_radians().cos(), 2f64.to_radians().sin());
    // R = Rx(2 deg) * Rz(90 deg)
    let rz = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let rx = [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]];
    let m = std::array::from_fn(|i| {
        std::array::from_fn(|j| (0..3).map(|k| rx[i][k] * rz[k][j]).sum::<f64>())
    });
    Calibration {
        imu_to_sensor: m,
        tip_radius_mm: 20.0,
    }
}
