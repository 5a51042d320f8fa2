//! The paper's data-collection protocols (Methods, "Data acquisition"), at three scales, and the
//! robot's motion within a trial.
//!
//! Every trial indents the tip into a flat plane, settles, then tilts from 0 to 20 degrees at a
//! constant speed in one direction. [`Protocol::Exp2`] inserts a 500 ms stop at a random tilt.
//! Experiment 3 varies one of speed or depth over seen (training) and interpolated unseen levels
//! with a fixed set of combinations of the other two variables taken from training values.
//!
//! | protocol | paper | small | tiny |
//! |---|---|---|---|
//! | `exp1`, `exp2` | 20 dirs x 5 speeds x 5 depths x 2 = 1000 | 8 x 5 x 3 x 1 = 120 | 4 x 2 x 2 x 1 = 16 |
//! | `exp3-speed` | 9 speeds (2..10, odd unseen) x 30 | 9 x 12 | 3 x 4 |
//! | `exp3-depth` | 9 depths (1..3 by 0.25, quarter steps unseen) x 30 | 5 x 20 | 3 x 4 |
//! | `no-contact` | 10 | 4 | 2 |

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::params::TimelineParams;

/// Errors parsing a protocol or scale name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ProtocolError {
    /// The protocol's name is not one of the five.
    #[error("unknown protocol `{0}` (expected exp1, exp2, exp3-speed, exp3-depth or no-contact)")]
    UnknownProtocol(String),
    /// The scale's name is not one of the three.
    #[error("unknown scale `{0}` (expected tiny, small or paper)")]
    UnknownScale(String),
}

/// One of the paper's data-collection protocols.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Protocol {
    /// Experiment 1: continuous tilting.
    Exp1,
    /// Experiment 2: continuous tilting with a 500 ms stop at a random tilt.
    Exp2,
    /// Experiment 3, speed-wise: seen and unseen speeds, fixed depth-direction combinations.
    Exp3Speed,
    /// Experiment 3, depth-wise: seen and unseen depths, fixed speed-direction combinations.
    Exp3Depth,
    /// The same motion with the plane out of reach: noise only.
    NoContact,
}

impl Protocol {
    /// All protocols, in the order above.
    pub const ALL: [Protocol; 5] = [
        Protocol::Exp1,
        Protocol::Exp2,
        Protocol::Exp3Speed,
        Protocol::Exp3Depth,
        Protocol::NoContact,
    ];

    /// The protocol's command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Protocol::Exp1 => "exp1",
            Protocol::Exp2 => "exp2",
            Protocol::Exp3Speed => "exp3-speed",
            Protocol::Exp3Depth => "exp3-depth",
            Protocol::NoContact => "no-contact",
        }
    }
}

impl std::fmt::Display for Protocol {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Protocol {
    type Err = ProtocolError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| ProtocolError::UnknownProtocol(s.to_string()))
    }
}

/// How many trials: the paper's design or a smaller one that keeps its structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Scale {
    /// A few trials per protocol, for tests (seconds to simulate).
    Tiny,
    /// About a hundred trials per protocol: the whole pipeline in minutes.
    Small,
    /// The paper's numbers of trials.
    Paper,
}

impl Scale {
    /// All scales, smallest first.
    pub const ALL: [Scale; 3] = [Scale::Tiny, Scale::Small, Scale::Paper];

    /// The scale's command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Scale::Tiny => "tiny",
            Scale::Small => "small",
            Scale::Paper => "paper",
        }
    }

    /// The levels and trial counts of this scale.
    ///
    /// Every scale keeps one Experiment 3 design, evtac's (the paper gives neither its levels
    /// nor their count, only 30 trials per level and that unseen levels are interpolated): the
    /// unseen speeds lie halfway between seen ones, 1 deg/s from the nearest (seen 2, 4, ..., 10;
    /// unseen 3, 5, ..., 9), and the unseen depths 0.25 mm from the nearest (seen 1.0, 1.5, ...,
    /// 3.0; unseen the quarter steps). Smaller scales take fewer levels or directions, never a
    /// coarser spacing.
    pub fn design(self) -> Design {
        let directions = |n: usize| (0..n).map(|i| 360.0 * i as f64 / n as f64).collect();
        match self {
            Scale::Paper => Design {
                directions: directions(20),
                speeds: vec![2.0, 4.0, 6.0, 8.0, 10.0],
                depths: vec![1.0, 1.5, 2.0, 2.5, 3.0],
                repeats: 2,
                exp3_speeds: (2..=10).map(f64::from).collect(),
                exp3_depths: (0..=8).map(|i| 1.0 + 0.25 * f64::from(i)).collect(),
                exp3_speed_trials: 30,
                exp3_depth_trials: 30,
                no_contact_trials: 10,
            },
            // The paper's speeds and depths in 5 directions (125 trials, about the 120 of 8
            // directions x 3 depths before, whose unseen depths were 0.5 mm from a seen one).
            Scale::Small => Design {
                directions: directions(5),
                speeds: vec![2.0, 4.0, 6.0, 8.0, 10.0],
                depths: vec![1.0, 1.5, 2.0, 2.5, 3.0],
                repeats: 1,
                exp3_speeds: (2..=10).map(f64::from).collect(),
                exp3_depths: (0..=8).map(|i| 1.0 + 0.25 * f64::from(i)).collect(),
                exp3_speed_trials: 12,
                exp3_depth_trials: 12,
                no_contact_trials: 4,
            },
            // Two neighbouring seen levels per axis and the unseen one between them.
            Scale::Tiny => Design {
                directions: directions(4),
                speeds: vec![6.0, 8.0],
                depths: vec![1.5, 2.0],
                repeats: 1,
                exp3_speeds: vec![6.0, 7.0, 8.0],
                exp3_depths: vec![1.5, 1.75, 2.0],
                exp3_speed_trials: 4,
                exp3_depth_trials: 4,
                no_contact_trials: 2,
            },
        }
    }
}

impl std::fmt::Display for Scale {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Scale {
    type Err = ProtocolError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| ProtocolError::UnknownScale(s.to_string()))
    }
}

/// The levels of a scale. Training levels are `speeds` x `depths` x `directions`; Experiment 3's
/// levels that are not training levels are the "unseen" ones.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Design {
    /// Tilt directions, degrees.
    pub directions: Vec<f64>,
    /// Training speeds, deg/s.
    pub speeds: Vec<f64>,
    /// Training depths, mm.
    pub depths: Vec<f64>,
    /// Trials per direction-speed-depth combination in Experiments 1 and 2.
    pub repeats: usize,
    /// Experiment 3's speeds (seen and unseen).
    pub exp3_speeds: Vec<f64>,
    /// Experiment 3's depths (seen and unseen).
    pub exp3_depths: Vec<f64>,
    /// Trials per speed in Experiment 3.
    pub exp3_speed_trials: usize,
    /// Trials per depth in Experiment 3.
    pub exp3_depth_trials: usize,
    /// Trials of the no-contact protocol.
    pub no_contact_trials: usize,
}

impl Design {
    /// This design with `repeats` passes over the conditions of Experiments 1 and 2.
    pub fn with_repeats(self, repeats: usize) -> Design {
        Design { repeats, ..self }
    }
}

/// What one trial does.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialSpec {
    /// The trial's name (also its file stem).
    pub name: String,
    /// Tilt direction, degrees.
    pub direction_deg: f64,
    /// Commanded tilt speed, deg/s.
    pub speed_deg_s: f64,
    /// Indentation depth, mm (ignored without contact).
    pub depth_mm: f64,
    /// Commanded tilt of the mid-motion stop, if any.
    pub stop_deg: Option<f64>,
    /// Experiment 3's `seen` / `unseen`.
    pub group: Option<String>,
    /// Whether the plane is within reach (false for `no-contact`).
    pub contact: bool,
    /// The trial's own seed (noise, IMU errors, per-trial variation).
    pub seed: u64,
    /// The seed of the sensor's seating in its mount ([`crate::rig::Seating`]): one per pass
    /// over the conditions (Experiments 1 and 2 seat the sensor again for each repeat) and one
    /// for each other protocol, so trials of one pass share it. Absent from older files: 0.
    #[serde(default)]
    pub seating: u64,
}

/// The seating seed of pass `pass` of a protocol whose trial seeds come from `base`.
fn seating_seed(base: u64, pass: usize) -> u64 {
    // Indices far above the trial indices (0, 1, ...) drawn from the same `base`.
    trial_seed(base, usize::MAX / 2 + pass)
}

/// The seed of trial `index` of a dataset with seed `seed`: independent of how trials are
/// scheduled, and different for every trial.
pub fn trial_seed(seed: u64, index: usize) -> u64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream((index as u64).wrapping_add(1));
    rng.random()
}

/// The trials of `protocol` at `scale`, named `t0000`, `t0001`, ... Trial seeds come from
/// `seed` and the protocol, so two protocols with one seed do not share their noise.
pub fn plan(
    protocol: Protocol,
    scale: Scale,
    seed: u64,
    timeline: &TimelineParams,
) -> Vec<TrialSpec> {
    plan_design(protocol, &scale.design(), seed, timeline)
}

/// [`plan`] on a given design (a scale's, e.g. with other repeats, [`Design::with_repeats`]).
pub fn plan_design(
    protocol: Protocol,
    design: &Design,
    seed: u64,
    timeline: &TimelineParams,
) -> Vec<TrialSpec> {
    let protocol_index = Protocol::ALL
        .iter()
        .position(|&p| p == protocol)
        .unwrap_or(0);
    let base = trial_seed(seed, usize::MAX - 2 - protocol_index);
    // (direction, speed, depth, group, pass)
    let mut rows: Vec<(f64, f64, f64, Option<String>, usize)> = Vec::new();
    let group = |levels: &[f64], v: f64| {
        let seen = levels.iter().any(|&l| (l - v).abs() < 1e-9);
        Some(if seen { "seen" } else { "unseen" }.to_string())
    };
    match protocol {
        Protocol::Exp1 | Protocol::Exp2 => {
            for &direction in &design.directions {
                for &speed in &design.speeds {
                    for &depth in &design.depths {
                        for pass in 0..design.repeats {
                            rows.push((direction, speed, depth, None, pass));
                        }
                    }
                }
            }
        }
        Protocol::Exp3Speed => {
            let combos = combinations(&design.directions, &design.depths, design.exp3_speed_trials);
            for &speed in &design.exp3_speeds {
                for &(direction, depth) in &combos {
                    rows.push((direction, speed, depth, group(&design.speeds, speed), 0));
                }
            }
        }
        Protocol::Exp3Depth => {
            let combos = combinations(&design.directions, &design.speeds, design.exp3_depth_trials);
            for &depth in &design.exp3_depths {
                for &(direction, speed) in &combos {
                    rows.push((direction, speed, depth, group(&design.depths, depth), 0));
                }
            }
        }
        Protocol::NoContact => {
            let n = design.no_contact_trials;
            let fastest = design.speeds.iter().copied().fold(0.0, f64::max);
            for i in 0..n {
                rows.push((360.0 * i as f64 / n.max(1) as f64, fastest, 0.0, None, 0));
            }
        }
    }
    rows.into_iter()
        .enumerate()
        .map(|(i, (direction_deg, speed_deg_s, depth_mm, group, pass))| {
            let seed = trial_seed(base, i);
            let stop_deg = (protocol == Protocol::Exp2).then(|| {
                // A separate stream, so that the stop does not shift the trial's other draws.
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                rng.set_stream(u64::MAX);
                let [lo, hi] = timeline.stop_range_deg;
                lo + (hi - lo) * rng.random::<f64>()
            });
            TrialSpec {
                name: format!("t{i:04}"),
                direction_deg,
                speed_deg_s,
                depth_mm,
                stop_deg,
                group,
                contact: protocol != Protocol::NoContact,
                seed,
                seating: seating_seed(base, pass),
            }
        })
        .collect()
}

/// `n` (first, second) combinations with balanced marginals: the first cycles through `a`, the
/// second through `b`, shifted by one on each pass over `a` so that repeats differ.
fn combinations(a: &[f64], b: &[f64], n: usize) -> Vec<(f64, f64)> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    (0..n)
        .map(|i| (a[i % a.len()], b[(i + i / a.len()) % b.len()]))
        .collect()
}

/// One constant-acceleration piece of the commanded tilt.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    t0: f64,
    theta0: f64,
    v0: f64,
    accel: f64,
}

/// The commanded motion of a trial: indentation depth and tilt against time (seconds from the
/// start of the recording).
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    pieces: Vec<Piece>,
    depth_mm: f64,
    gap_mm: f64,
    indent_s: f64,
    /// When the tilt starts.
    pub motion_start_s: f64,
    /// When the final tilt is reached.
    pub motion_end_s: f64,
    /// When the stop's tilt is reached (Experiment 2).
    pub stop_start_s: Option<f64>,
    /// When the tilt resumes after the stop.
    pub stop_end_s: Option<f64>,
    /// When the recording ends.
    pub end_s: f64,
}

impl Motion {
    /// The commanded motion of `spec` (`gap_mm`: how far the plane starts from the tip; without
    /// contact the plane stays at that gap).
    pub fn new(spec: &TrialSpec, timeline: &TimelineParams, gap_mm: f64) -> Self {
        Self::reaching(spec, timeline, gap_mm, [0.0, 0.0])
    }

    /// The motion the robot makes for `spec`: the commanded one, but reaching the stop and the
    /// final tilt `errors_deg` (stop, final) away from the commanded angles (the robot's
    /// repeatability, [`crate::rig::TrialErrors`]).
    pub fn reaching(
        spec: &TrialSpec,
        timeline: &TimelineParams,
        gap_mm: f64,
        errors_deg: [f64; 2],
    ) -> Self {
        let total = timeline.total_deg + errors_deg[1];
        let start = timeline.indent_s + timeline.settle_s;
        let accel = timeline.accel_deg_s2.max(1e-6);
        let v = spec.speed_deg_s.max(1e-6);
        let mut pieces = vec![Piece {
            t0: 0.0,
            theta0: 0.0,
            v0: 0.0,
            accel: 0.0,
        }];
        let mut t = start;
        let mut theta = 0.0;
        let mut stop = (None, None);
        let mut targets = Vec::new();
        if let Some(s) = spec.stop_deg {
            targets.push((s.clamp(0.0, timeline.total_deg) + errors_deg[0]).clamp(0.0, total));
        }
        targets.push(total);
        for (k, target) in targets.iter().enumerate() {
            let dist = target - theta;
            if dist > 0.0 {
                // Trapezoidal velocity: accelerate, cruise, decelerate; a triangle if too short.
                let ramp = (v / accel).min((dist / accel).sqrt());
                let peak = accel * ramp;
                let cruise = (dist - peak * ramp) / peak;
                pieces.push(Piece {
                    t0: t,
                    theta0: theta,
                    v0: 0.0,
                    accel,
                });
                let a_end = theta + 0.5 * peak * ramp;
                pieces.push(Piece {
                    t0: t + ramp,
                    theta0: a_end,
                    v0: peak,
                    accel: 0.0,
                });
                pieces.push(Piece {
                    t0: t + ramp + cruise,
                    theta0: a_end + peak * cruise,
                    v0: peak,
                    accel: -accel,
                });
                t += 2.0 * ramp + cruise;
                theta = *target;
            }
            pieces.push(Piece {
                t0: t,
                theta0: theta,
                v0: 0.0,
                accel: 0.0,
            });
            if k + 1 < targets.len() {
                stop = (Some(t), Some(t + timeline.stop_s));
                t += timeline.stop_s;
            }
        }
        Self {
            pieces,
            depth_mm: if spec.contact { spec.depth_mm } else { -gap_mm },
            gap_mm,
            indent_s: timeline.indent_s,
            motion_start_s: start,
            motion_end_s: t,
            stop_start_s: stop.0,
            stop_end_s: stop.1,
            end_s: t + timeline.hold_s,
        }
    }

    /// A sensor at rest out of contact (the plane `gap_mm` away) for `duration_s`.
    pub fn rest(duration_s: f64, gap_mm: f64) -> Self {
        Self {
            pieces: vec![Piece {
                t0: 0.0,
                theta0: 0.0,
                v0: 0.0,
                accel: 0.0,
            }],
            depth_mm: -gap_mm,
            gap_mm,
            indent_s: 0.0,
            motion_start_s: 0.0,
            motion_end_s: 0.0,
            stop_start_s: None,
            stop_end_s: None,
            end_s: duration_s.max(0.0),
        }
    }

    fn piece(&self, t: f64) -> &Piece {
        let i = self.pieces.partition_point(|p| p.t0 <= t);
        &self.pieces[i.saturating_sub(1)]
    }

    /// Commanded tilt at `t`, degrees.
    pub fn theta(&self, t: f64) -> f64 {
        let p = self.piece(t);
        let dt = t - p.t0;
        p.theta0 + p.v0 * dt + 0.5 * p.accel * dt * dt
    }

    /// Commanded tilt rate at `t`, deg/s.
    pub fn theta_dot(&self, t: f64) -> f64 {
        let p = self.piece(t);
        p.v0 + p.accel * (t - p.t0)
    }

    /// Commanded indentation depth at `t` (a cosine ramp from the gap to the depth).
    pub fn depth(&self, t: f64) -> f64 {
        if t >= self.indent_s || self.indent_s <= 0.0 {
            return self.depth_mm;
        }
        let s = 0.5 - 0.5 * (std::f64::consts::PI * t.max(0.0) / self.indent_s).cos();
        -self.gap_mm + (self.depth_mm + self.gap_mm) * s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count(p: Protocol, s: Scale) -> usize {
        plan(p, s, 1, &TimelineParams::default()).len()
    }

    #[test]
    fn paper_scale_has_the_paper_s_trial_counts() {
        assert_eq!(count(Protocol::Exp1, Scale::Paper), 1000);
        assert_eq!(count(Protocol::Exp2, Scale::Paper), 1000);
        assert_eq!(count(Protocol::Exp3Speed, Scale::Paper), 270);
        assert_eq!(count(Protocol::Exp3Depth, Scale::Paper), 270);
        assert_eq!(count(Protocol::Exp1, Scale::Small), 125);
        assert_eq!(count(Protocol::Exp1, Scale::Tiny), 16);
    }

    /// At every scale each unseen level of Experiment 3 lies between two seen ones, at the
    /// paper's distance from the nearest: 1 deg/s, 0.25 mm.
    #[test]
    fn unseen_levels_are_at_the_paper_s_spacing_at_every_scale() {
        let check = |seen: &[f64], all: &[f64], gap: f64, what: &str, scale: Scale| {
            let unseen: Vec<f64> = all.iter().copied().filter(|v| !seen.contains(v)).collect();
            assert!(!unseen.is_empty(), "{scale}: no unseen {what}");
            for v in unseen {
                let below = seen
                    .iter()
                    .copied()
                    .filter(|&s| s < v)
                    .fold(f64::NAN, f64::max);
                let above = seen
                    .iter()
                    .copied()
                    .filter(|&s| s > v)
                    .fold(f64::NAN, f64::min);
                assert!(
                    (v - below - gap).abs() < 1e-9 && (above - v - gap).abs() < 1e-9,
                    "{scale}: unseen {what} {v} is not {gap} from seen {below} and {above}"
                );
            }
        };
        for scale in Scale::ALL {
            let d = scale.design();
            check(&d.speeds, &d.exp3_speeds, 1.0, "speed", scale);
            check(&d.depths, &d.exp3_depths, 0.25, "depth", scale);
        }
    }

    #[test]
    fn exp3_groups_and_balanced_combinations() {
        let trials = plan(
            Protocol::Exp3Speed,
            Scale::Paper,
            1,
            &TimelineParams::default(),
        );
        let design = Scale::Paper.design();
        for t in &trials {
            let seen = design.speeds.contains(&t.speed_deg_s);
            assert_eq!(
                t.group.as_deref(),
                Some(if seen { "seen" } else { "unseen" })
            );
            assert!(design.depths.contains(&t.depth_mm));
            assert!(design.directions.contains(&t.direction_deg));
        }
        // The same 30 depth-direction combinations at every speed, all distinct.
        let at = |s: f64| -> Vec<(f64, f64)> {
            trials
                .iter()
                .filter(|t| t.speed_deg_s == s)
                .map(|t| (t.direction_deg, t.depth_mm))
                .collect()
        };
        assert_eq!(at(3.0), at(8.0));
        let mut combos = at(3.0);
        assert_eq!(combos.len(), 30);
        combos.sort_by(|a, b| a.partial_cmp(b).unwrap());
        combos.dedup();
        assert_eq!(combos.len(), 30);
        for depth in &design.depths {
            assert_eq!(at(3.0).iter().filter(|c| c.1 == *depth).count(), 6);
        }
    }

    #[test]
    fn seeds_differ_and_stops_lie_in_range() {
        let tl = TimelineParams::default();
        let trials = plan(Protocol::Exp2, Scale::Small, 7, &tl);
        let mut seeds: Vec<u64> = trials.iter().map(|t| t.seed).collect();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds.len(), trials.len());
        for t in &trials {
            let s = t.stop_deg.unwrap();
            assert!((4.0..=16.0).contains(&s));
        }
        assert_eq!(trials, plan(Protocol::Exp2, Scale::Small, 7, &tl));
        assert_ne!(trials, plan(Protocol::Exp2, Scale::Small, 8, &tl));
    }

    #[test]
    fn motion_reaches_its_targets_at_constant_speed() {
        let tl = TimelineParams::default();
        let mut spec = plan(Protocol::Exp2, Scale::Tiny, 3, &tl).remove(0);
        spec.speed_deg_s = 5.0;
        spec.stop_deg = Some(8.0);
        let m = Motion::new(&spec, &tl, 0.5);
        assert_eq!(m.motion_start_s, 1.0);
        assert_eq!(m.theta(0.5), 0.0);
        let (s0, s1) = (m.stop_start_s.unwrap(), m.stop_end_s.unwrap());
        assert!((s1 - s0 - 0.5).abs() < 1e-12);
        assert!((m.theta(s0) - 8.0).abs() < 1e-9 && (m.theta(s1) - 8.0).abs() < 1e-9);
        assert!((m.theta(m.motion_end_s) - 20.0).abs() < 1e-9);
        assert!((m.theta(m.end_s) - 20.0).abs() < 1e-9);
        assert!((m.theta_dot(2.0) - 5.0).abs() < 1e-9);
        // 20 degrees at 5 deg/s plus one ramp (v / a) per move plus the stop.
        let expected = 1.0 + 4.0 + 2.0 * 5.0 / 200.0 + 0.5;
        assert!(
            (m.motion_end_s - expected).abs() < 1e-9,
            "{}",
            m.motion_end_s
        );
        assert_eq!(m.depth(0.0), -0.5);
        assert_eq!(m.depth(0.5), spec.depth_mm);
    }

    #[test]
    fn names_parse_back() {
        for p in Protocol::ALL {
            assert_eq!(p.name().parse::<Protocol>(), Ok(p));
        }
        for s in Scale::ALL {
            assert_eq!(s.name().parse::<Scale>(), Ok(s));
        }
        assert!("exp4".parse::<Protocol>().is_err());
    }
}
