//! Sample times: where in a trial the features are read and the network is asked for an angle.
//!
//! The paper samples each trial on a 1 ms grid from motion onset to motion end and takes the same
//! 50 equally spaced points from the motion phase; Experiment 2 adds 10 equally spaced points from
//! the stop phase. "Equally spaced" is over grid points: the first and last grid points of a phase
//! are always taken, the rest at evenly spaced grid indices in between (rounded to the nearest).

use serde::{Deserialize, Serialize};

/// Spacing of the sampling grid in microseconds (1 ms).
pub const GRID_US: i64 = 1_000;
/// Points taken from each trial's motion phase.
pub const MOTION_POINTS: usize = 50;
/// Points taken from each trial's stop phase (Experiment 2).
pub const STOP_POINTS: usize = 10;

/// The phase of a trial a sample belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// The sensor is rolling.
    Motion,
    /// The sensor pauses at an intermediate tilt (Experiment 2).
    Stop,
}

impl Phase {
    /// The lowercase name used in files (`motion`, `stop`).
    pub fn as_str(self) -> &'static str {
        match self {
            Phase::Motion => "motion",
            Phase::Stop => "stop",
        }
    }

    /// Parses `motion` or `stop`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "motion" => Some(Phase::Motion),
            "stop" => Some(Phase::Stop),
            _ => None,
        }
    }
}

/// One sample time of a trial.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SampleTime {
    /// Time in microseconds on the recording's clock.
    pub t_us: i64,
    /// Phase the time falls in.
    pub phase: Phase,
}

/// Which points of a trial are sampled: the identity of a sampling scheme for caches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Sampling {
    /// Points from the motion phase.
    pub motion_points: usize,
    /// Points from the stop phase (0: none).
    pub stop_points: usize,
}

impl Sampling {
    /// Experiments 1 and 3: 50 motion points.
    pub const MOTION: Sampling = Sampling {
        motion_points: MOTION_POINTS,
        stop_points: 0,
    };
    /// Experiment 2: 50 motion points and 10 stop points.
    pub const WITH_STOP: Sampling = Sampling {
        motion_points: MOTION_POINTS,
        stop_points: STOP_POINTS,
    };

    /// A short stable name for cache folders, e.g. `m50-s10`.
    pub fn key(&self) -> String {
        format!("m{}-s{}", self.motion_points, self.stop_points)
    }

    /// The sample times of a trial whose motion runs from `motion` start to end (us) with an
    /// optional stop interval inside it, in time order.
    pub fn times(&self, motion: (i64, i64), stop: Option<(i64, i64)>) -> Vec<SampleTime> {
        let grid = grid(motion.0, motion.1);
        let in_stop = |t: i64| stop.is_some_and(|(a, b)| t >= a && t <= b);
        let motion_grid: Vec<i64> = grid.iter().copied().filter(|&t| !in_stop(t)).collect();
        let stop_grid: Vec<i64> = grid.iter().copied().filter(|&t| in_stop(t)).collect();
        let mut out: Vec<SampleTime> = equally_spaced(&motion_grid, self.motion_points)
            .into_iter()
            .map(|t_us| SampleTime {
                t_us,
                phase: Phase::Motion,
            })
            .collect();
        out.extend(
            equally_spaced(&stop_grid, self.stop_points)
                .into_iter()
                .map(|t_us| SampleTime {
                    t_us,
                    phase: Phase::Stop,
                }),
        );
        out.sort_by_key(|s| s.t_us);
        out
    }
}

/// The 1 ms grid from `start` to `end` inclusive (empty when `end < start`).
pub fn grid(start: i64, end: i64) -> Vec<i64> {
    if end < start {
        return Vec::new();
    }
    let n = (end - start) / GRID_US + 1;
    (0..n).map(|i| start + i * GRID_US).collect()
}

/// `n` points of `points` at evenly spaced indices (first and last included); all of them when
/// there are fewer than `n`.
pub fn equally_spaced(points: &[i64], n: usize) -> Vec<i64> {
    if n == 0 || points.is_empty() {
        return Vec::new();
    }
    if points.len() <= n {
        return points.to_vec();
    }
    if n == 1 {
        return vec![points[points.len() / 2]];
    }
    let last = (points.len() - 1) as f64;
    (0..n)
        .map(|i| points[(i as f64 * last / (n - 1) as f64).round() as usize])
        .collect()
}

/// `n` indices evenly spread over `0..len` (first and last included), all of them when `len <= n`.
pub fn equally_spaced_indices(len: usize, n: usize) -> Vec<usize> {
    let idx: Vec<i64> = (0..len as i64).collect();
    equally_spaced(&idx, n)
        .into_iter()
        .map(|i| i as usize)
        .collect()
}

/// Linear interpolation of `(t, values)` rows sorted by time at `t`, clamped at both ends.
/// `None` when there are no rows.
pub fn interpolate<const N: usize>(rows: &[(i64, [f64; N])], t: i64) -> Option<[f64; N]> {
    let first = rows.first()?;
    let last = rows.last()?;
    if t <= first.0 {
        return Some(first.1);
    }
    if t >= last.0 {
        return Some(last.1);
    }
    let hi = rows.partition_point(|r| r.0 <= t);
    let (a, b) = (&rows[hi - 1], &rows[hi]);
    if b.0 == a.0 {
        return Some(a.1);
    }
    let w = (t - a.0) as f64 / (b.0 - a.0) as f64;
    Some(std::array::from_fn(|i| a.1[i] + w * (b.1[i] - a.1[i])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motion_points_span_the_motion_phase() {
        let times = Sampling::MOTION.times((1_000_000, 3_000_000), None);
        assert_eq!(times.len(), 50);
        assert_eq!(times[0].t_us, 1_000_000);
        assert_eq!(times[49].t_us, 3_000_000);
        assert!(times.iter().all(|s| s.t_us % GRID_US == 0));
        assert!(times.windows(2).all(|w| w[1].t_us > w[0].t_us));
        // 2000 grid intervals over 49 gaps: spacing 40.8 ms, rounded to the grid.
        let gaps: Vec<i64> = times.windows(2).map(|w| w[1].t_us - w[0].t_us).collect();
        assert!(gaps.iter().all(|&g| g == 41_000 || g == 40_000), "{gaps:?}");
    }

    #[test]
    fn stop_points_lie_in_the_stop() {
        let stop = (2_000_000, 2_500_000);
        let times = Sampling::WITH_STOP.times((1_000_000, 4_000_000), Some(stop));
        let stops: Vec<_> = times.iter().filter(|s| s.phase == Phase::Stop).collect();
        let motions: Vec<_> = times.iter().filter(|s| s.phase == Phase::Motion).collect();
        assert_eq!(stops.len(), 10);
        assert_eq!(motions.len(), 50);
        assert!(stops.iter().all(|s| s.t_us >= stop.0 && s.t_us <= stop.1));
        assert!(motions.iter().all(|s| s.t_us < stop.0 || s.t_us > stop.1));
        assert_eq!(stops[0].t_us, stop.0);
        assert_eq!(stops[9].t_us, stop.1);
        // The motion-only scheme ignores the stop points but still avoids the stop.
        let m = Sampling::MOTION.times((1_000_000, 4_000_000), Some(stop));
        assert_eq!(m.len(), 50);
        assert!(m.iter().all(|s| s.phase == Phase::Motion));
    }

    #[test]
    fn short_phases_keep_every_grid_point() {
        let times = Sampling::MOTION.times((0, 10_000), None);
        assert_eq!(times.len(), 11);
        assert!(Sampling::MOTION.times((10, 0), None).is_empty());
    }

    #[test]
    fn interpolation_is_linear_and_clamped() {
        let rows = [(0, [0.0, 10.0]), (10, [1.0, 20.0]), (20, [3.0, 20.0])];
        assert_eq!(interpolate(&rows, -5), Some([0.0, 10.0]));
        assert_eq!(interpolate(&rows, 5), Some([0.5, 15.0]));
        assert_eq!(interpolate(&rows, 15), Some([2.0, 20.0]));
        assert_eq!(interpolate(&rows, 10), Some([1.0, 20.0]));
        assert_eq!(interpolate(&rows, 99), Some([3.0, 20.0]));
        assert_eq!(interpolate::<2>(&[], 0), None);
    }
}
