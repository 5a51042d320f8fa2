//! Labels from the robot's commanded motion, for recordings without an IMU (a dataset whose
//! [`LabelSource`](crate::source::LabelSource) is `commanded`).
//!
//! The NeuroTac lab's collection code records events only, and labels its trials with the
//! robot's pose; these labels are that pose over time. `theta(t)` runs straight through the
//! log's points: 0 until `motion_start_us`, `stop_deg` from `stop_start_us` to `stop_end_us`
//! (Experiment 2), `total_deg` from `motion_end_us` on, at a constant rate in between (the
//! commanded speed, as the log's times give it), then pitch and roll from `theta` and the
//! direction as for the IMU's labels ([`geometry::contact_angles`]).
//!
//! What this leaves out, and the IMU's labels measure: how the robot tracks its command (its
//! acceleration ramps, its repeatability), the clock offset's error, and the stop's actual
//! angle. So a dataset labelled this way has no stop check, and its labels are exact only as
//! far as the log's times are; the report says which source labelled the data.

use crate::geometry;
use crate::series::LabelSeries;
use crate::trial::TrialMotion;

/// The label series' sample spacing, us: the rate of the DVXplorer's IMU, so that these labels
/// are sampled as IMU labels would be.
pub const STEP_US: i64 = 1_000;
/// How far the series reaches before the onset and after the end, us (it holds its first and
/// last values beyond, see [`LabelSeries::at`]).
pub const MARGIN_US: i64 = 1_000_000;

/// The log's points of `motion`, in time order: `(t_us, theta_deg)` at the onset, the stop's
/// start and end, and the end.
fn knots(motion: &TrialMotion) -> Vec<(i64, f64)> {
    let mut points = vec![(motion.motion_start_us, 0.0)];
    if let Some(s) = motion.stop {
        points.extend([(s.start_us, s.deg), (s.end_us, s.deg)]);
    }
    points.push((motion.motion_end_us, motion.total_deg));
    points
}

/// The commanded tilt at `t_us`, straight through `points` (see [`knots`]) and held beyond them.
fn theta_at(points: &[(i64, f64)], t_us: i64) -> f64 {
    if t_us <= points[0].0 {
        return points[0].1;
    }
    for w in points.windows(2) {
        let ((a, va), (b, vb)) = (w[0], w[1]);
        if t_us <= b {
            if b == a {
                return vb;
            }
            return va + (vb - va) * (t_us - a) as f64 / (b - a) as f64;
        }
    }
    points[points.len() - 1].1
}

/// The commanded motion as a label series: every [`STEP_US`] from [`MARGIN_US`] before the
/// onset to as long after the end, with the log's points themselves among the samples (so the
/// series' linear interpolation is the commanded motion exactly).
pub fn label_commanded(motion: &TrialMotion) -> LabelSeries {
    let (from, to) = (
        motion.motion_start_us - MARGIN_US,
        motion.motion_end_us + MARGIN_US,
    );
    let mut t: Vec<i64> = (0..)
        .map(|k| from + k * STEP_US)
        .take_while(|&t| t <= to)
        .collect();
    t.push(motion.motion_start_us);
    t.push(motion.motion_end_us);
    if let Some(s) = motion.stop {
        t.extend([s.start_us, s.end_us]);
    }
    t.sort_unstable();
    t.dedup();
    let points = knots(motion);
    let theta: Vec<f64> = t.iter().map(|&t| theta_at(&points, t)).collect();
    let (pitch, roll) = theta
        .iter()
        .map(|&th| geometry::contact_angles(th, motion.direction_deg))
        .unzip();
    LabelSeries {
        t_us: t,
        theta_deg: theta,
        pitch_deg: pitch,
        roll_deg: roll,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trial::Stop;

    fn motion(stop: Option<Stop>) -> TrialMotion {
        TrialMotion {
            direction_deg: 90.0,
            speed_deg_s: 10.0,
            total_deg: 20.0,
            motion_start_us: 2_000_000,
            motion_end_us: 4_000_000,
            stop,
        }
    }

    #[test]
    fn theta_ramps_through_the_logs_points() {
        let m = motion(None);
        let labels = label_commanded(&m);
        assert_eq!(labels.theta_at(0), 0.0);
        assert_eq!(labels.theta_at(2_000_000), 0.0);
        assert!((labels.theta_at(3_000_000) - 10.0).abs() < 1e-12);
        assert!((labels.theta_at(3_000_500) - 10.005).abs() < 1e-12);
        assert_eq!(labels.theta_at(4_000_000), 20.0);
        assert_eq!(labels.theta_at(9_000_000), 20.0);
        // phi = 90 deg tilts about x: all roll (see geometry).
        let (pitch, roll) = labels.at(3_000_000);
        let (p, r) = geometry::contact_angles(10.0, 90.0);
        assert!((pitch - p).abs() < 1e-12 && (roll - r).abs() < 1e-12);
        assert_eq!(labels.t_us.first(), Some(&1_000_000));
        assert_eq!(labels.t_us.last(), Some(&5_000_000));
        assert!(labels.t_us.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn a_stop_holds_its_commanded_angle() {
        let m = motion(Some(Stop {
            start_us: 2_500_000,
            end_us: 3_000_500,
            deg: 5.0,
        }));
        let labels = label_commanded(&m);
        assert!((labels.theta_at(2_250_000) - 2.5).abs() < 1e-12);
        assert_eq!(labels.theta_at(2_500_000), 5.0);
        assert_eq!(labels.theta_at(2_800_000), 5.0);
        // The stop's end lies between two 1 ms samples: it is a sample itself.
        assert!(labels.t_us.contains(&3_000_500));
        assert_eq!(labels.theta_at(3_000_500), 5.0);
        assert!((labels.theta_at(3_500_250) - 12.5).abs() < 1e-12);
    }
}
