//! The IMU at rest: the gyroscope's and accelerometer's white noise, the gyroscope's bias, their
//! resolution, the sample rate and the temperature, in the simulator's terms
//! ([`evtac_sim::params::ImuParams`]).
//!
//! - Noise from the differences of consecutive samples at rest (`Var(x[i+1] - x[i]) = 2 sigma^2`
//!   for white noise): the gravity vector and a bias that changes between stretches at rest
//!   (the simulator draws one per trial) drop out, where a deviation from a mean would count
//!   every step of the bias as noise; a difference far beyond the others (a change of pose or
//!   bias between two stretches at rest that touch) is left out. The quantisation's `lsb^2 / 12` is taken off, as the
//!   simulator adds it back when it rounds to its resolution.
//! - Bias from the means of [`WINDOW_US`] windows at rest: the simulator's
//!   `gyro_bias_deg_s` is the spread of a per-trial bias, so its square is the mean square of
//!   the windows' means less what their own noise adds (`sigma^2 / n`). For a real gyroscope
//!   with one bias it is that bias's size (RMS over the axes).
//! - Resolution as the smallest step between consecutive readings, which a quantised sensor
//!   takes often at rest.

use evtac_events::ImuSample;
use serde::Serialize;

/// Length of a window for the bias, us: many samples (200 at 800 Hz) so the noise barely moves
/// its mean, short against the stretches at rest so few windows straddle a change of bias.
pub const WINDOW_US: i64 = 250_000;

/// Fewest samples a window needs to count (shorter ones are the ends of rest stretches).
const MIN_WINDOW_SAMPLES: u64 = 40;

/// Longest gap between two samples at rest that are still consecutive, us.
const MAX_GAP_US: i64 = 50_000;

/// What the IMU's samples say, at rest and overall.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImuStats {
    /// Samples in the recording.
    pub samples: u64,
    /// Samples per second over the IMU's time span.
    pub rate_hz: f64,
    /// Samples at rest.
    pub rest_samples: u64,
    /// Windows the bias was measured in.
    pub windows: u64,
    /// The gyroscope's white noise per sample and axis (RMS over the axes), deg/s.
    pub gyro_noise_deg_s: f64,
    /// The gyroscope's bias size (RMS over windows and axes, less the noise's share), deg/s.
    pub gyro_bias_deg_s: f64,
    /// The gyroscope's mean reading at rest per axis, deg/s.
    pub gyro_mean_deg_s: [f64; 3],
    /// The gyroscope's resolution, deg/s, if it steps at rest.
    pub gyro_lsb_deg_s: Option<f64>,
    /// The accelerometer's white noise per sample and axis (RMS over the axes), g.
    pub accel_noise_g: f64,
    /// The accelerometer's resolution, g, if it steps at rest.
    pub accel_lsb_g: Option<f64>,
    /// Mean temperature at rest, degrees Celsius; `None` when no sample states one (ROS's
    /// `sensor_msgs/Imu` has no temperature: those samples carry NaN).
    pub temperature_c: Option<f64>,
}

/// Differences counted before any is refused as a step.
const WARM_UP: u64 = 50;

/// A difference over this many (squared) standard deviations of those so far is a step, not
/// noise: the pose or the bias changed between two stretches at rest that touch (a Gaussian
/// difference lies this far out once in two million).
const OUTLIER_SIGMAS_SQ: f64 = 25.0;

/// Running sums of one sensor's (gyroscope's or accelerometer's) consecutive differences.
#[derive(Debug, Clone, Default)]
struct Differences {
    sum_sq: [f64; 3],
    n: u64,
    smallest_step: Option<f64>,
}

impl Differences {
    fn add(&mut self, a: [f32; 3], b: [f32; 3]) {
        let d: [f64; 3] = std::array::from_fn(|i| f64::from(b[i]) - f64::from(a[i]));
        if self.n >= WARM_UP
            && (0..3).any(|i| d[i] * d[i] > OUTLIER_SIGMAS_SQ * self.sum_sq[i] / self.n as f64)
        {
            return;
        }
        for (i, d) in d.into_iter().enumerate() {
            self.sum_sq[i] += d * d;
            // Readings are f32 multiples of the resolution: steps below a millionth of a unit
            // are rounding, not a step.
            if d.abs() > 1e-6 {
                self.smallest_step = Some(self.smallest_step.map_or(d.abs(), |s| s.min(d.abs())));
            }
        }
        self.n += 1;
    }

    /// The per-sample variance (mean over the axes) with the quantisation, or `None` without
    /// differences.
    fn variance(&self) -> Option<f64> {
        (self.n > 0).then(|| self.sum_sq.iter().sum::<f64>() / (3.0 * 2.0 * self.n as f64))
    }

    /// The white noise's standard deviation without the quantisation's share.
    fn noise(&self) -> Option<f64> {
        let lsb = self.smallest_step.unwrap_or(0.0);
        self.variance()
            .map(|v| (v - lsb * lsb / 12.0).max(0.0).sqrt())
    }
}

/// The IMU's samples, fed in time order with whether each lies at rest.
#[derive(Debug, Clone, Default)]
pub struct ImuAccumulator {
    samples: u64,
    first_t: Option<i64>,
    last_t: Option<i64>,
    previous: Option<ImuSample>,
    gyro: Differences,
    accel: Differences,
    rest_samples: u64,
    temperature_sum: f64,
    /// Samples at rest that state a temperature (not NaN).
    temperature_samples: u64,
    /// The open window: its start, samples and gyroscope sums.
    window: Option<(i64, u64, [f64; 3])>,
    windows: u64,
    /// Over closed windows: sum of squared means, of means per axis, and of 1/n.
    mean_sq_sum: f64,
    mean_sum: [f64; 3],
    inverse_n_sum: f64,
}

impl ImuAccumulator {
    /// Adds `s` (later than every sample before it), at rest or not.
    pub fn add(&mut self, s: &ImuSample, rest: bool) {
        self.samples += 1;
        self.first_t.get_or_insert(s.t);
        self.last_t = Some(s.t);
        if !rest {
            self.close_window();
            self.previous = None;
            return;
        }
        if let Some(p) = self.previous.filter(|p| s.t - p.t <= MAX_GAP_US) {
            self.gyro.add(p.gyroscope, s.gyroscope);
            self.accel.add(p.accelerometer, s.accelerometer);
        } else {
            self.close_window();
        }
        if self
            .window
            .is_some_and(|(start, _, _)| s.t - start >= WINDOW_US)
        {
            self.close_window();
        }
        let (_, n, sum) = self.window.get_or_insert((s.t, 0, [0.0; 3]));
        *n += 1;
        for (total, &v) in sum.iter_mut().zip(&s.gyroscope) {
            *total += f64::from(v);
        }
        self.rest_samples += 1;
        if !s.temperature.is_nan() {
            self.temperature_sum += f64::from(s.temperature);
            self.temperature_samples += 1;
        }
        self.previous = Some(*s);
    }

    fn close_window(&mut self) {
        if let Some((_, n, sum)) = self.window.take()
            && n >= MIN_WINDOW_SAMPLES
        {
            for (total, v) in self.mean_sum.iter_mut().zip(sum) {
                let mean = v / n as f64;
                *total += mean;
                self.mean_sq_sum += mean * mean;
            }
            self.inverse_n_sum += 1.0 / n as f64;
            self.windows += 1;
        }
    }

    /// The statistics, or `None` when no full window lay at rest.
    pub fn finish(mut self) -> Option<ImuStats> {
        self.close_window();
        let (first, last) = (self.first_t?, self.last_t?);
        let gyro_variance = self.gyro.variance()?;
        if self.windows == 0 || last <= first {
            return None;
        }
        let w = self.windows as f64;
        // Each window's mean carries its own noise, variance sigma^2 / n: taken off.
        let bias_sq = self.mean_sq_sum / (3.0 * w) - gyro_variance * self.inverse_n_sum / w;
        Some(ImuStats {
            samples: self.samples,
            rate_hz: (self.samples - 1) as f64 / ((last - first) as f64 * 1e-6),
            rest_samples: self.rest_samples,
            windows: self.windows,
            gyro_noise_deg_s: self.gyro.noise()?,
            gyro_bias_deg_s: bias_sq.max(0.0).sqrt(),
            gyro_mean_deg_s: self.mean_sum.map(|s| s / w),
            gyro_lsb_deg_s: self.gyro.smallest_step,
            accel_noise_g: self.accel.noise()?,
            accel_lsb_g: self.accel.smallest_step,
            temperature_c: (self.temperature_samples > 0)
                .then(|| self.temperature_sum / self.temperature_samples as f64),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// 40 s at 1 kHz at rest, a new bias (spread 0.5 deg/s) every 2 s, noise 0.08 deg/s,
    /// quantised to 1/32 deg/s; gravity along z with noise 0.003 g in 1/4096 g steps.
    #[test]
    fn recovers_noise_bias_and_resolution_of_a_quantised_imu() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let bias = Normal::new(0.0, 0.5).unwrap();
        let noise = Normal::new(0.0, 0.08).unwrap();
        let accel_noise = Normal::new(0.0, 0.003).unwrap();
        let q = |v: f64, lsb: f64| ((v / lsb).round() * lsb) as f32;
        let mut acc = ImuAccumulator::default();
        let mut b = [0.0; 3];
        for k in 0..40_000i64 {
            if k % 2000 == 0 {
                b = std::array::from_fn(|_| bias.sample(&mut rng));
            }
            let s = ImuSample {
                t: k * 1000,
                gyroscope: std::array::from_fn(|i| q(b[i] + noise.sample(&mut rng), 1.0 / 32.0)),
                accelerometer: std::array::from_fn(|i| {
                    let g = if i == 2 { 1.0 } else { 0.0 };
                    q(g + accel_noise.sample(&mut rng), 1.0 / 4096.0)
                }),
                temperature: 31.0,
            };
            // A motion (not at rest) in the middle of the record changes nothing.
            acc.add(&s, !(20_000..20_100).contains(&k));
        }
        let s = acc.finish().unwrap();
        assert!((s.rate_hz - 1000.0).abs() < 1e-6, "{}", s.rate_hz);
        assert!(
            (s.gyro_noise_deg_s - 0.08).abs() < 0.08 * 0.02,
            "{}",
            s.gyro_noise_deg_s
        );
        assert!(
            (s.accel_noise_g - 0.003).abs() < 0.003 * 0.03,
            "{}",
            s.accel_noise_g
        );
        // 20 biases per axis: the estimate's spread is about a sixth.
        assert!(
            (s.gyro_bias_deg_s - 0.5).abs() < 0.5 * 0.35,
            "{}",
            s.gyro_bias_deg_s
        );
        assert_eq!(s.gyro_lsb_deg_s, Some(1.0 / 32.0));
        assert_eq!(s.accel_lsb_g, Some(1.0 / 4096.0));
        assert_eq!(s.temperature_c, Some(31.0));
        assert_eq!(s.rest_samples, 39_900);
    }

    #[test]
    fn no_rest_no_statistics() {
        let mut acc = ImuAccumulator::default();
        for k in 0..100 {
            let s = ImuSample {
                t: k * 1000,
                gyroscope: [0.0; 3],
                accelerometer: [0.0; 3],
                temperature: 0.0,
            };
            acc.add(&s, false);
        }
        assert_eq!(acc.finish(), None);
    }
}
