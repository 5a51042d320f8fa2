//! Checking labels against what is known independently of how they were made: the commanded
//! stop angle (as the paper does: integrated tilt at each stop against the robot's command,
//! -0.01 +- 0.04 deg there) and, for simulated data, the exact ground truth.

use serde::{Deserialize, Serialize};

use crate::series::LabelSeries;

/// Why a check could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ValidationError {
    /// No label sample falls inside the stop (after trimming the margin).
    #[error(
        "no label samples inside the stop from {start_us} to {end_us} us (after trimming \
         {margin_us} us at each end)"
    )]
    EmptyStop {
        /// Stop start.
        start_us: i64,
        /// Stop end.
        end_us: i64,
        /// The margin trimmed at each end.
        margin_us: i64,
    },
}

/// The integrated tilt over one stop against the commanded stop angle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StopCheck {
    /// The robot's commanded stop angle.
    pub commanded_deg: f64,
    /// The mean labelled `theta` over the stop.
    pub measured_deg: f64,
    /// `measured_deg - commanded_deg`.
    pub error_deg: f64,
    /// Label samples averaged.
    pub samples: usize,
}

/// Compares the mean of `labels.theta_deg` over `[start_us + margin_us, end_us - margin_us]`
/// with `commanded_deg`.
pub fn check_stop(
    labels: &LabelSeries,
    start_us: i64,
    end_us: i64,
    margin_us: i64,
    commanded_deg: f64,
) -> Result<StopCheck, ValidationError> {
    let (from, to) = (start_us + margin_us, end_us - margin_us);
    let (sum, samples) = labels
        .t_us
        .iter()
        .zip(&labels.theta_deg)
        .filter(|(t, _)| (from..=to).contains(*t))
        .fold((0.0, 0usize), |(s, n), (_, th)| (s + th, n + 1));
    if samples == 0 {
        return Err(ValidationError::EmptyStop {
            start_us,
            end_us,
            margin_us,
        });
    }
    let measured_deg = sum / samples as f64;
    Ok(StopCheck {
        commanded_deg,
        measured_deg,
        error_deg: measured_deg - commanded_deg,
        samples,
    })
}

/// Mean, standard deviation and extremes of a set of errors, as the paper reports them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Number of values.
    pub n: usize,
    /// Their mean.
    pub mean: f64,
    /// Their sample standard deviation (`n - 1` in the denominator; 0 for one value).
    pub std: f64,
    /// The smallest value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
}

impl Summary {
    /// Summarises `values`, `None` when there are none.
    pub fn of(values: &[f64]) -> Option<Self> {
        let n = values.len();
        if n == 0 {
            return None;
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let std = if n > 1 {
            (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
        } else {
            0.0
        };
        Some(Self {
            n,
            mean,
            std,
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:+.4} +- {:.4} (n = {}, range {:+.4} .. {:+.4})",
            self.mean, self.std, self.n, self.min, self.max
        )
    }
}

/// Root-mean-square errors of labels against ground truth, in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruthError {
    /// Truth samples compared.
    pub samples: usize,
    /// RMS error of `theta`.
    pub theta_rms_deg: f64,
    /// RMS error of pitch.
    pub pitch_rms_deg: f64,
    /// RMS error of roll.
    pub roll_rms_deg: f64,
    /// RMS over both contact angles together: `sqrt(mean(d_pitch^2 + d_roll^2) / 2)`.
    pub rms_deg: f64,
    /// The largest absolute pitch or roll error.
    pub max_abs_deg: f64,
}

impl TruthError {
    /// Compares `labels`, interpolated at each truth time, with `truth`. `None` when `truth` is
    /// empty.
    pub fn compare(labels: &LabelSeries, truth: &LabelSeries) -> Option<Self> {
        let n = truth.len();
        if n == 0 {
            return None;
        }
        let (mut st, mut sp, mut sr, mut max) = (0.0, 0.0, 0.0, 0.0f64);
        for i in 0..n {
            let t = truth.t_us[i];
            let (p, r) = labels.at(t);
            let (dt, dp, dr) = (
                labels.theta_at(t) - truth.theta_deg[i],
                p - truth.pitch_deg[i],
                r - truth.roll_deg[i],
            );
            st += dt * dt;
            sp += dp * dp;
            sr += dr * dr;
            max = max.max(dp.abs()).max(dr.abs());
        }
        let nf = n as f64;
        Some(Self {
            samples: n,
            theta_rms_deg: (st / nf).sqrt(),
            pitch_rms_deg: (sp / nf).sqrt(),
            roll_rms_deg: (sr / nf).sqrt(),
            rms_deg: ((sp + sr) / (2.0 * nf)).sqrt(),
            max_abs_deg: max,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> LabelSeries {
        let t_us: Vec<i64> = (0..11).map(|i| i * 100_000).collect();
        let theta_deg: Vec<f64> = t_us.iter().map(|&t| t as f64 * 1e-5).collect();
        LabelSeries {
            pitch_deg: theta_deg.clone(),
            roll_deg: vec![0.0; t_us.len()],
            t_us,
            theta_deg,
        }
    }

    #[test]
    fn stop_check_averages_inside_the_trimmed_stop() {
        let c = check_stop(&ramp(), 200_000, 800_000, 100_000, 4.9).unwrap();
        // Samples at 0.3 .. 0.7 s: theta 3..7, mean 5.
        assert_eq!(c.samples, 5);
        assert!((c.measured_deg - 5.0).abs() < 1e-12);
        assert!((c.error_deg - 0.1).abs() < 1e-12);
        assert_eq!(
            check_stop(&ramp(), 210_000, 290_000, 30_000, 3.0),
            Err(ValidationError::EmptyStop {
                start_us: 210_000,
                end_us: 290_000,
                margin_us: 30_000
            })
        );
    }

    #[test]
    fn summary_uses_the_sample_std() {
        let s = Summary::of(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!((s.n, s.mean, s.min, s.max), (4, 2.5, 1.0, 4.0));
        assert!((s.std - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!(Summary::of(&[2.0]).map(|s| s.std), Some(0.0));
        assert!(Summary::of(&[]).is_none());
    }

    #[test]
    fn truth_error_measures_an_offset() {
        let truth = ramp();
        let mut labels = ramp();
        labels.pitch_deg.iter_mut().for_each(|p| *p += 0.03);
        labels.roll_deg.iter_mut().for_each(|r| *r -= 0.04);
        let e = TruthError::compare(&labels, &truth).unwrap();
        assert_eq!(e.samples, 11);
        assert!(e.theta_rms_deg < 1e-15);
        assert!((e.pitch_rms_deg - 0.03).abs() < 1e-12);
        assert!((e.roll_rms_deg - 0.04).abs() < 1e-12);
        assert!((e.rms_deg - (0.0009f64 + 0.0016).sqrt() / 2f64.sqrt()).abs() < 1e-12);
        assert!((e.max_abs_deg - 0.04).abs() < 1e-12);
    }
}
