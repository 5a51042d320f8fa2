//! Gyroscope bias from the stationary segment before motion onset.
//!
//! While the robot holds still the true axial rate is zero, so the mean reading over that segment
//! is the bias (its standard error shrinks with the segment's length). The segment runs from the
//! first IMU sample to `motion_start - margin`: the margin keeps out the first instants of motion
//! in case the commanded onset and the recording's clock disagree slightly.

/// Why no bias could be estimated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BiasError {
    /// The stationary segment before motion onset is missing or too short.
    #[error(
        "no stationary segment before motion onset: the IMU samples before t = {end_us} us \
         (motion onset minus the margin) span {duration_us} us in {samples} samples, but at \
         least {min_duration_us} us and {min_samples} samples are needed"
    )]
    NoStationarySegment {
        /// End of the segment (motion onset minus the margin).
        end_us: i64,
        /// How long the samples before `end_us` span (0 when there are none).
        duration_us: i64,
        /// How many samples lie before `end_us`.
        samples: usize,
        /// The shortest segment accepted.
        min_duration_us: i64,
        /// The fewest samples accepted.
        min_samples: usize,
    },
}

/// The bias estimate and what it rests on.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Bias {
    /// The mean axial rate over the segment, deg/s: subtract it from every sample.
    pub rate_deg_s: f64,
    /// The sample standard deviation over the segment (the gyroscope's noise), deg/s.
    pub noise_deg_s: f64,
    /// Samples averaged.
    pub samples: usize,
    /// First sample time of the segment.
    pub start_us: i64,
    /// Last sample time of the segment.
    pub end_us: i64,
}

/// Estimates the bias of `rate` (sampled at `t_us`, increasing) from the samples strictly before
/// `end_us`, requiring them to span at least `min_duration_us` and number at least
/// `min_samples` (at least 2).
pub fn stationary_bias(
    t_us: &[i64],
    rate: &[f64],
    end_us: i64,
    min_duration_us: i64,
    min_samples: usize,
) -> Result<Bias, BiasError> {
    let n = t_us.partition_point(|&t| t < end_us).min(rate.len());
    let duration_us = if n > 0 { t_us[n - 1] - t_us[0] } else { 0 };
    let min_samples = min_samples.max(2);
    if n < min_samples || duration_us < min_duration_us {
        return Err(BiasError::NoStationarySegment {
            end_us,
            duration_us,
            samples: n,
            min_duration_us,
            min_samples,
        });
    }
    let segment = &rate[..n];
    let mean = segment.iter().sum::<f64>() / n as f64;
    let var = segment.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    Ok(Bias {
        rate_deg_s: mean,
        noise_deg_s: var.sqrt(),
        samples: n,
        start_us: t_us[0],
        end_us: t_us[n - 1],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn averages_the_samples_before_the_end() {
        let t: Vec<i64> = (0..100).map(|i| i * 1_000).collect();
        let rate: Vec<f64> = (0..100)
            .map(|i| {
                if i < 50 {
                    0.3 + if i % 2 == 0 { 0.1 } else { -0.1 }
                } else {
                    9.0
                }
            })
            .collect();
        let b = stationary_bias(&t, &rate, 50_000, 40_000, 10).unwrap();
        assert_eq!(b.samples, 50);
        assert!((b.rate_deg_s - 0.3).abs() < 1e-12);
        assert!((b.noise_deg_s - 0.1 * (50.0f64 / 49.0).sqrt()).abs() < 1e-12);
        assert_eq!((b.start_us, b.end_us), (0, 49_000));
    }

    #[test]
    fn refuses_a_missing_or_short_segment() {
        let t: Vec<i64> = (0..100).map(|i| 5_000 + i * 1_000).collect();
        let rate = vec![0.0; 100];
        let err = stationary_bias(&t, &rate, 4_000, 100_000, 10).unwrap_err();
        assert_eq!(
            err,
            BiasError::NoStationarySegment {
                end_us: 4_000,
                duration_us: 0,
                samples: 0,
                min_duration_us: 100_000,
                min_samples: 10
            }
        );
        assert!(matches!(
            stationary_bias(&t, &rate, 60_000, 100_000, 10),
            Err(BiasError::NoStationarySegment {
                duration_us: 54_000,
                samples: 55,
                ..
            })
        ));
        assert!(err.to_string().contains("no stationary segment"));
    }
}
