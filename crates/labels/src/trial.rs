//! Labelling one trial: from its IMU stream and commanded motion to `theta(t)` and the contact
//! angles on the IMU's time base.
//!
//! The steps, in order (the paper's Methods, "Data acquisition and label generation"):
//!
//! 1. **Axial rate** ([`AxialRate`]): the gyroscope, mapped into the sensor frame by the
//!    calibrated extrinsics, projected on the rolling axis of the tilt direction `phi`.
//! 2. **Bias** ([`stationary_bias`]): the mean rate over the stationary segment before motion
//!    onset (minus [`LabelConfig::bias_margin_us`]) is subtracted.
//! 3. **Motion prior**: the robot is still before onset, after the end and (with
//!    [`LabelConfig::hold_stops`]) during a commanded stop, so the rate counts only inside the
//!    moving intervals; window edges between IMU samples are integrated exactly.
//! 4. **Scale** ([`ScaleMethod`]): by default the rate integrated over the motion is scaled onto
//!    the commanded total rotation `total_deg`. The stop angle `stop_deg` is *not* used, so it
//!    stays an independent check.
//! 5. **Integration** ([`CumulativeTrapezoid`]): trapezoidal, from motion onset.
//! 6. **Zero-phase low-pass** ([`LowPass`]): Butterworth, forward-backward with SciPy's edge
//!    padding. It is applied to the integrated `theta` rather than to the rate: both are linear
//!    and time-invariant, so the order does not matter away from the record's edges, and
//!    filtering after the motion prior keeps the filter from spreading the onset's rate into the
//!    still segment, where it would be cut off and lost from the integral.
//! 7. **Hold**: `theta` is exactly 0 before onset and exactly its end value after the end (and
//!    constant during held stops); the filter only shapes the moving segments.
//! 8. **Contact angles** ([`geometry::contact_angles`]) from `theta` and `phi`.
//! 9. **Validation** ([`check_stop`]): the mean `theta` over the stop against `stop_deg`.

use evtac_events::ImuSample;
use evtac_events::manifest::TrialMeta;
use serde::{Deserialize, Serialize};

use crate::bias::{Bias, stationary_bias};
use crate::error::TrialError;
use crate::filter::LowPass;
use crate::geometry::{self, Calibration};
use crate::integration::CumulativeTrapezoid;
use crate::rate::AxialRate;
use crate::scale::{self, ScaleMethod};
use crate::series::LabelSeries;
use crate::validation::{StopCheck, check_stop};

/// Settings of the label pipeline. The defaults suit a DVXplorer's IMU (about 800 Hz).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LabelConfig {
    /// Order of the Butterworth low-pass (one pass; zero-phase filtering doubles it).
    pub filter_order: usize,
    /// Cutoff (-3 dB of one pass) of the low-pass, Hz.
    pub cutoff_hz: f64,
    /// The stationary segment for the bias ends this long before the motion onset, us.
    pub bias_margin_us: i64,
    /// The shortest stationary segment accepted for the bias, us.
    pub min_stationary_us: i64,
    /// The fewest stationary samples accepted for the bias.
    pub min_stationary_samples: usize,
    /// The longest accepted interval between IMU samples, in median intervals.
    pub max_gap_factor: f64,
    /// How the gyroscope's scale is calibrated.
    pub scale: ScaleMethod,
    /// The largest accepted deviation of the scale factor from 1.
    pub scale_tolerance: f64,
    /// Whether the rate counts as zero during a commanded stop (the robot is still there).
    pub hold_stops: bool,
    /// Trimmed from each end of a stop before averaging `theta` over it, us.
    pub stop_margin_us: i64,
}

impl Default for LabelConfig {
    fn default() -> Self {
        Self {
            filter_order: 4,
            cutoff_hz: 20.0,
            bias_margin_us: 50_000,
            min_stationary_us: 100_000,
            min_stationary_samples: 20,
            max_gap_factor: 5.0,
            scale: ScaleMethod::TotalRotation,
            scale_tolerance: 0.25,
            hold_stops: true,
            stop_margin_us: 50_000,
        }
    }
}

impl LabelConfig {
    /// How long the sensor must be still, with IMU samples, before each motion onset: the
    /// stationary segment the gyroscope bias is taken from plus the margin before the onset.
    pub fn still_lead_in_us(&self) -> i64 {
        self.min_stationary_us + self.bias_margin_us
    }

    /// The lowest IMU rate that gives the stationary segment its fewest accepted samples, Hz.
    pub fn min_imu_rate_hz(&self) -> f64 {
        self.min_stationary_samples.max(2) as f64 / (self.min_stationary_us as f64 * 1e-6)
    }
}

/// A commanded mid-motion stop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stop {
    /// When the stop starts, us.
    pub start_us: i64,
    /// When the stop ends, us.
    pub end_us: i64,
    /// The commanded tilt during the stop, degrees.
    pub deg: f64,
}

/// What the labeller needs to know about a trial's commanded motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrialMotion {
    /// Tilt direction `phi`, degrees.
    pub direction_deg: f64,
    /// Commanded tilt speed, deg/s.
    pub speed_deg_s: f64,
    /// Commanded final tilt, degrees.
    pub total_deg: f64,
    /// Motion onset, us.
    pub motion_start_us: i64,
    /// Motion end, us.
    pub motion_end_us: i64,
    /// The mid-motion stop, if any.
    pub stop: Option<Stop>,
}

impl TrialMotion {
    /// Takes the motion from a manifest row, checking it is consistent.
    pub fn from_meta(meta: &TrialMeta) -> Result<Self, TrialError> {
        let stop = match (meta.stop_start_us, meta.stop_end_us, meta.stop_deg) {
            (Some(start_us), Some(end_us), Some(deg)) => Some(Stop {
                start_us,
                end_us,
                deg,
            }),
            (None, None, None) => None,
            (s, e, d) => {
                let missing: Vec<&str> = [
                    ("stop_start_us", s.is_none()),
                    ("stop_end_us", e.is_none()),
                    ("stop_deg", d.is_none()),
                ]
                .iter()
                .filter(|(_, m)| *m)
                .map(|(c, _)| *c)
                .collect();
                return Err(TrialError::Motion {
                    reason: format!(
                        "the stop columns must be all set or all empty; missing {}",
                        missing.join(", ")
                    ),
                });
            }
        };
        let motion = Self {
            direction_deg: meta.direction_deg,
            speed_deg_s: meta.speed_deg_s,
            total_deg: meta.total_deg,
            motion_start_us: meta.motion_start_us,
            motion_end_us: meta.motion_end_us,
            stop,
        };
        motion.check()?;
        Ok(motion)
    }

    /// Checks the motion is consistent: finite values, a non-empty motion window, a stop inside
    /// it.
    pub fn check(&self) -> Result<(), TrialError> {
        let bad = |reason: String| Err(TrialError::Motion { reason });
        for (column, v) in [
            ("direction_deg", self.direction_deg),
            ("speed_deg_s", self.speed_deg_s),
            ("total_deg", self.total_deg),
        ] {
            if !v.is_finite() {
                return bad(format!("{column} is {v}"));
            }
        }
        if self.motion_end_us <= self.motion_start_us {
            return bad(format!(
                "motion_end_us {} is not after motion_start_us {}",
                self.motion_end_us, self.motion_start_us
            ));
        }
        if let Some(s) = self.stop {
            if !s.deg.is_finite() {
                return bad(format!("stop_deg is {}", s.deg));
            }
            if !(self.motion_start_us <= s.start_us
                && s.start_us < s.end_us
                && s.end_us <= self.motion_end_us)
            {
                return bad(format!(
                    "the stop from {} to {} us must be a non-empty part of the motion from {} to \
                     {} us",
                    s.start_us, s.end_us, self.motion_start_us, self.motion_end_us
                ));
            }
        }
        Ok(())
    }

    /// The intervals in which the sensor moves: the motion window, minus the stop when
    /// `hold_stops`.
    pub fn moving_intervals(&self, hold_stops: bool) -> Vec<(i64, i64)> {
        match self.stop {
            Some(s) if hold_stops => vec![
                (self.motion_start_us, s.start_us),
                (s.end_us, self.motion_end_us),
            ],
            _ => vec![(self.motion_start_us, self.motion_end_us)],
        }
    }
}

/// The labels of one trial and what they rest on.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialLabels {
    /// `theta`, pitch and roll at every IMU sample.
    pub labels: LabelSeries,
    /// The gyroscope bias that was removed.
    pub bias: Bias,
    /// The scale factor applied to the bias-free rate.
    pub scale_factor: f64,
    /// The labelled tilt at motion end minus the commanded `total_deg` (0 by construction with
    /// [`ScaleMethod::TotalRotation`], an independent check otherwise).
    pub final_error_deg: f64,
    /// The stop check (trials with a stop only).
    pub stop: Option<StopCheck>,
}

impl TrialLabels {
    /// `(pitch_deg, roll_deg)` at `t_us` (see [`LabelSeries::at`]).
    pub fn at(&self, t_us: i64) -> (f64, f64) {
        self.labels.at(t_us)
    }

    /// The stop error (measured minus commanded), if the trial has a stop.
    pub fn stop_error_deg(&self) -> Option<f64> {
        self.stop.map(|s| s.error_deg)
    }
}

/// Labels one trial from its IMU stream `imu`, its commanded `motion` and the sensor's
/// `calibration` (see the module docs for the steps).
pub fn label_imu(
    imu: &[ImuSample],
    motion: &TrialMotion,
    calibration: &Calibration,
    config: &LabelConfig,
) -> Result<TrialLabels, TrialError> {
    motion.check()?;
    let rate = AxialRate::from_imu(
        imu,
        calibration,
        motion.direction_deg,
        config.max_gap_factor,
    )?;
    let t = &rate.t_us;
    // A motion that starts before the stream shows up here as a missing stationary segment.
    let bias = stationary_bias(
        t,
        &rate.rate_deg_s,
        motion.motion_start_us - config.bias_margin_us,
        config.min_stationary_us,
        config.min_stationary_samples,
    )?;
    let (first_us, last_us) = (t[0], t[t.len() - 1]);
    if motion.motion_end_us > last_us {
        return Err(TrialError::MotionOutsideRecording {
            motion_start_us: motion.motion_start_us,
            motion_end_us: motion.motion_end_us,
            first_us,
            last_us,
        });
    }
    let corrected: Vec<f64> = rate
        .rate_deg_s
        .iter()
        .map(|r| r - bias.rate_deg_s)
        .collect();
    let integral = CumulativeTrapezoid::new(t, &corrected)?;
    let moving = motion.moving_intervals(config.hold_stops);
    // Each moving interval with the running integral at its ends.
    let spans: Vec<(i64, i64, f64, f64)> = moving
        .iter()
        .map(|&(a, b)| (a, b, integral.at(a), integral.at(b)))
        .collect();
    // The bias-free rate integrated over the moving intervals up to sample `i`; the running
    // integral at a sample is already known, so no search is needed.
    let travelled_at_sample = |i: usize| -> f64 {
        let ti = t[i];
        spans
            .iter()
            .map(|&(a, b, ia, ib)| {
                if ti <= a {
                    0.0
                } else if ti >= b {
                    ib - ia
                } else {
                    integral.at_samples()[i] - ia
                }
            })
            .sum()
    };
    let measured_deg: f64 = spans.iter().map(|&(_, _, ia, ib)| ib - ia).sum();
    let scale_factor = match config.scale {
        ScaleMethod::TotalRotation => scale::factor(
            "rotation (deg)",
            measured_deg,
            motion.total_deg,
            config.scale_tolerance,
        )?,
        ScaleMethod::CommandedSpeed => {
            let inside: Vec<f64> = t
                .iter()
                .zip(&corrected)
                .filter(|(t, _)| moving.iter().any(|&(a, b)| (a..=b).contains(*t)))
                .map(|(_, r)| *r)
                .collect();
            let measured = scale::median(&inside).unwrap_or(0.0);
            scale::factor(
                "speed (deg/s)",
                measured,
                motion.speed_deg_s,
                config.scale_tolerance,
            )?
        }
        ScaleMethod::None => 1.0,
    };
    let held: Vec<f64> = (0..t.len())
        .map(|i| scale_factor * travelled_at_sample(i))
        .collect();
    let filter = LowPass::new(config.filter_order, config.cutoff_hz, rate.fs_hz())?;
    let mut theta = filter.filtfilt(&held)?;
    // Where the robot is still, the held value is exact; the filter only shapes the motion.
    for (i, &ti) in t.iter().enumerate() {
        let moving_now = moving.iter().any(|&(a, b)| a < ti && ti < b);
        if !moving_now {
            theta[i] = held[i];
        }
    }
    let (pitch_deg, roll_deg) = theta
        .iter()
        .map(|&th| geometry::contact_angles(th, motion.direction_deg))
        .unzip();
    let labels = LabelSeries {
        t_us: t.clone(),
        theta_deg: theta,
        pitch_deg,
        roll_deg,
    };
    let stop = motion
        .stop
        .map(|s| check_stop(&labels, s.start_us, s.end_us, config.stop_margin_us, s.deg))
        .transpose()?;
    Ok(TrialLabels {
        final_error_deg: scale_factor * measured_deg - motion.total_deg,
        labels,
        bias,
        scale_factor,
        stop,
    })
}
