//! The axial angular velocity: the gyroscope, taken from the IMU frame into the sensor frame by
//! the calibrated extrinsics, projected on the rolling axis of the tilt direction `phi`
//! ([`geometry::axial_rate`]). This is where an IMU stream is checked before anything trusts it:
//! present, finite, in time order and without gaps.

use evtac_events::ImuSample;

use crate::geometry::{self, Calibration};

/// What makes an IMU stream unusable for labels.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StreamError {
    /// The recording holds no IMU samples.
    #[error("the recording has no IMU stream (0 IMU samples)")]
    Empty,
    /// Too few samples to tell the sampling rate.
    #[error("the IMU stream has {samples} samples; at least {needed} are needed")]
    TooFew {
        /// Samples present.
        samples: usize,
        /// Samples needed.
        needed: usize,
    },
    /// A gyroscope value is NaN or infinite.
    #[error("IMU sample {index} (t = {t_us} us): gyroscope axis {axis} is not finite ({value})")]
    NonFinite {
        /// Index of the sample in the stream.
        index: usize,
        /// Its timestamp.
        t_us: i64,
        /// The axis (0 = x, 1 = y, 2 = z).
        axis: usize,
        /// The value read.
        value: f32,
    },
    /// Timestamps do not strictly increase.
    #[error(
        "IMU sample {index} has t = {t_us} us, not after the previous sample's {previous_us} us"
    )]
    NotIncreasing {
        /// Index of the offending sample.
        index: usize,
        /// Its timestamp.
        t_us: i64,
        /// The previous sample's timestamp.
        previous_us: i64,
    },
    /// Two consecutive samples are further apart than the configured limit.
    #[error(
        "gap of {gap_us} us in the IMU stream after t = {after_us} us (sample {index}); the \
         limit is {limit_us} us ({factor} x the median interval of {median_us} us)"
    )]
    Gap {
        /// Index of the sample before the gap.
        index: usize,
        /// Timestamp of the sample before the gap.
        after_us: i64,
        /// Length of the gap.
        gap_us: i64,
        /// The longest interval accepted.
        limit_us: i64,
        /// The limit as a multiple of the median interval.
        factor: f64,
        /// The stream's median sampling interval.
        median_us: i64,
    },
}

/// The axial angular velocity of one trial, sample by sample on the IMU's time base.
#[derive(Debug, Clone, PartialEq)]
pub struct AxialRate {
    /// Sample times in microseconds, strictly increasing.
    pub t_us: Vec<i64>,
    /// Tilt rate in degrees per second about the rolling axis (positive while `theta` grows).
    pub rate_deg_s: Vec<f64>,
    /// The median sampling interval in microseconds.
    pub median_interval_us: i64,
}

impl AxialRate {
    /// The fewest samples accepted: enough to tell a median interval and to filter at all.
    pub const MIN_SAMPLES: usize = 16;

    /// Checks `imu` and projects its gyroscope on the rolling axis of `phi_deg`.
    ///
    /// Consecutive samples may be at most `max_gap_factor` median intervals apart.
    pub fn from_imu(
        imu: &[ImuSample],
        calibration: &Calibration,
        phi_deg: f64,
        max_gap_factor: f64,
    ) -> Result<Self, StreamError> {
        if imu.is_empty() {
            return Err(StreamError::Empty);
        }
        if imu.len() < Self::MIN_SAMPLES {
            return Err(StreamError::TooFew {
                samples: imu.len(),
                needed: Self::MIN_SAMPLES,
            });
        }
        for (index, s) in imu.iter().enumerate() {
            if let Some(axis) = s.gyroscope.iter().position(|g| !g.is_finite()) {
                return Err(StreamError::NonFinite {
                    index,
                    t_us: s.t,
                    axis,
                    value: s.gyroscope[axis],
                });
            }
        }
        for (i, w) in imu.windows(2).enumerate() {
            if w[1].t <= w[0].t {
                return Err(StreamError::NotIncreasing {
                    index: i + 1,
                    t_us: w[1].t,
                    previous_us: w[0].t,
                });
            }
        }
        let mut intervals: Vec<i64> = imu.windows(2).map(|w| w[1].t - w[0].t).collect();
        let mid = intervals.len() / 2;
        let median_us = *intervals.select_nth_unstable(mid).1;
        // Rounded up so that a factor of 1.5 on a 1 us interval still admits 2 us.
        let limit_us = (median_us as f64 * max_gap_factor).ceil() as i64;
        if let Some((index, w)) = imu
            .windows(2)
            .enumerate()
            .find(|(_, w)| w[1].t - w[0].t > limit_us)
        {
            return Err(StreamError::Gap {
                index,
                after_us: w[0].t,
                gap_us: w[1].t - w[0].t,
                limit_us,
                factor: max_gap_factor,
                median_us,
            });
        }
        let rate_deg_s = imu
            .iter()
            .map(|s| {
                let g = s.gyroscope.map(f64::from);
                geometry::axial_rate(calibration.imu_to_sensor(g), phi_deg)
            })
            .collect();
        Ok(Self {
            t_us: imu.iter().map(|s| s.t).collect(),
            rate_deg_s,
            median_interval_us: median_us,
        })
    }

    /// The nominal sampling rate in Hz, from the median interval.
    pub fn fs_hz(&self) -> f64 {
        1e6 / self.median_interval_us as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stream(n: usize, dt: i64) -> Vec<ImuSample> {
        (0..n)
            .map(|i| ImuSample {
                t: 1_000 + i as i64 * dt,
                ..ImuSample::default()
            })
            .collect()
    }

    #[test]
    fn projects_through_the_extrinsics() {
        // IMU x = sensor y, IMU y = -sensor x: a 90 degree turn about z.
        let cal = Calibration {
            imu_to_sensor: [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            tip_radius_mm: 20.0,
        };
        let phi = 30.0;
        let omega_imu = cal.sensor_to_imu(geometry::sensor_angular_velocity(4.0, phi));
        let mut imu = stream(20, 1250);
        for s in &mut imu {
            s.gyroscope = omega_imu.map(|v| v as f32);
        }
        let r = AxialRate::from_imu(&imu, &cal, phi, 5.0).unwrap();
        assert_eq!(r.median_interval_us, 1250);
        assert!((r.fs_hz() - 800.0).abs() < 1e-9);
        assert!(r.rate_deg_s.iter().all(|v| (v - 4.0).abs() < 1e-6));
    }

    #[test]
    fn rejects_broken_streams() {
        let cal = Calibration::default();
        assert_eq!(
            AxialRate::from_imu(&[], &cal, 0.0, 5.0),
            Err(StreamError::Empty)
        );
        let mut imu = stream(40, 1000);
        imu[12].gyroscope[1] = f32::NAN;
        let err = AxialRate::from_imu(&imu, &cal, 0.0, 5.0).unwrap_err();
        assert!(matches!(
            err,
            StreamError::NonFinite {
                index: 12,
                axis: 1,
                ..
            }
        ));
        let mut imu = stream(40, 1000);
        imu[20].t = imu[19].t;
        assert!(matches!(
            AxialRate::from_imu(&imu, &cal, 0.0, 5.0),
            Err(StreamError::NotIncreasing { index: 20, .. })
        ));
        let mut imu = stream(40, 1000);
        for s in &mut imu[30..] {
            s.t += 4_500;
        }
        let err = AxialRate::from_imu(&imu, &cal, 0.0, 5.0).unwrap_err();
        assert_eq!(
            err,
            StreamError::Gap {
                index: 29,
                after_us: 30_000,
                gap_us: 5_500,
                limit_us: 5_000,
                factor: 5.0,
                median_us: 1_000
            }
        );
        assert!(err.to_string().contains("gap of 5500 us"), "{err}");
    }
}
