//! One trial from start to end: the commanded motion, the skin's lag behind it, the pins, the
//! event camera and the IMU.
//!
//! The skin does not follow the robot instantly: its tilt and depth follow the commanded ones
//! through a first-order lag with time constant `skin_tau_s` (integrated exactly for inputs that
//! are linear within a step). The lag of the tilt drives the shear of the contact patch (see
//! [`crate::sensor`]), so a stop makes the skin relax over a few time constants, a burst of
//! "elastic recoil" events that dies out, and then the sensor is quiet.
//!
//! A share `creep_fraction` of the skin's response follows with the much slower `creep_tau_s`
//! instead (silicone's creep and hysteresis): after a stop the skin keeps settling for a second
//! or so, at a trickle of events. The rig's per-trial errors ([`crate::rig`]) move the angles the
//! robot reaches, the indentation and where the patch sits, and the sensor's seating turns the
//! tilt's direction in its frame; the manifest keeps the commanded values and the ground truth
//! follows the robot's actual motion in the sensor's frame, as on a real rig.
//!
//! Steps are adaptive: each is as long as possible (up to `max_step_s`) such that no pin's image
//! moves more than `max_px_per_step` pixels.

use evtac_events::manifest::TrialMeta;
use evtac_events::{Event, ImuSample};
use evtac_labels::geometry::{Calibration, contact_angles};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::dvs::{Dvs, PixelArray, gaussian};
use crate::imu::simulate_imu;
use crate::params::SimParams;
use crate::protocol::{Motion, TrialSpec};
use crate::rig::{Seating, TrialErrors};
use crate::sensor::{Dome, Gains, PinImage, SkinPose};

/// One ground-truth sample: the pose the robot reached, in the sensor's frame (the seating's
/// turn included).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruthSample {
    /// Time, microseconds.
    pub t_us: i64,
    /// Commanded tilt magnitude, degrees.
    pub theta_deg: f64,
    /// Contact pitch, degrees.
    pub pitch_deg: f64,
    /// Contact roll, degrees.
    pub roll_deg: f64,
}

/// Everything one simulated trial produced, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialRecording {
    /// What the trial did.
    pub spec: TrialSpec,
    /// Events on the full 640x480 sensor, time-sorted.
    pub events: Vec<Event>,
    /// IMU samples at the IMU's rate.
    pub imu: Vec<ImuSample>,
    /// The pose reached, in the sensor's frame, at the truth rate.
    pub truth: Vec<TruthSample>,
    /// When the tilt starts, microseconds.
    pub motion_start_us: i64,
    /// When the final tilt is reached, microseconds.
    pub motion_end_us: i64,
    /// The stop's start and end, microseconds (Experiment 2).
    pub stop_us: Option<(i64, i64)>,
    /// Length of the recording, microseconds.
    pub duration_us: i64,
}

impl TrialRecording {
    /// The manifest row for this trial, given where its files are (relative to the dataset).
    pub fn meta(&self, file: &str, truth: Option<&str>, total_deg: f64) -> TrialMeta {
        TrialMeta {
            trial: self.spec.name.clone(),
            file: file.into(),
            truth: truth.map(Into::into),
            direction_deg: self.spec.direction_deg,
            speed_deg_s: self.spec.speed_deg_s,
            depth_mm: if self.spec.contact {
                self.spec.depth_mm
            } else {
                0.0
            },
            total_deg,
            motion_start_us: self.motion_start_us,
            motion_end_us: self.motion_end_us,
            stop_start_us: self.stop_us.map(|s| s.0),
            stop_end_us: self.stop_us.map(|s| s.1),
            stop_deg: self.spec.stop_deg,
            group: self.spec.group.clone(),
        }
    }
}

/// Random stream `k` of the trial with `seed`: each kind of draw has its own stream, so one
/// kind's parameters do not move another's draws.
fn trial_stream(seed: u64, k: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(k);
    rng
}

/// The simulator: one sensor (tip, camera with its fixed pattern, IMU mounting) that records
/// trials.
pub struct Simulator {
    params: SimParams,
    calibration: Calibration,
    dome: Dome,
    array: PixelArray,
}

impl Simulator {
    /// A sensor with these parameters; `camera_seed` draws the camera's fixed pattern
    /// (threshold mismatch, hot pixels), shared by all its trials.
    pub fn new(params: SimParams, camera_seed: u64) -> Self {
        let dome = Dome::new(&params.sensor, &params.contact, &params.camera);
        let array = PixelArray::new(&params.dvs, &params.camera, camera_seed);
        let calibration = Calibration {
            imu_to_sensor: params.imu.imu_to_sensor,
            tip_radius_mm: params.sensor.tip_radius_mm,
        };
        Self {
            params,
            calibration,
            dome,
            array,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &SimParams {
        &self.params
    }

    /// The sensor's calibration (what `calibration.json` holds).
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// The camera's fixed pattern.
    pub fn pixel_array(&self) -> &PixelArray {
        &self.array
    }

    /// Simulates one trial.
    pub fn simulate(&self, spec: &TrialSpec) -> TrialRecording {
        let gap = if spec.contact {
            self.params.contact.approach_gap_mm
        } else {
            self.params.contact.no_contact_gap_mm
        };
        let errors = self.errors(spec);
        let reached = [errors.stop_deg, errors.total_deg];
        let motion = Motion::reaching(spec, &self.params.timeline, gap, reached);
        self.run(spec, &motion, &errors)
    }

    /// The rig's errors in trial `spec` (none without contact: the robot does not move then).
    pub fn errors(&self, spec: &TrialSpec) -> TrialErrors {
        if !spec.contact {
            return TrialErrors::default();
        }
        let seed = rand::Rng::next_u64(&mut trial_stream(spec.seed, 4));
        TrialErrors::draw(&self.params.rig, self.params.sensor.tip_radius_mm, seed)
            .seated(&Seating::draw(&self.params.rig, spec.seating))
    }

    /// The `no_contact.aedat4` recording: the sensor at rest out of contact, noise only.
    pub fn simulate_rest(&self, seed: u64) -> TrialRecording {
        self.simulate_idle("no_contact", seed, self.params.timeline.no_contact_s)
    }

    /// The sensor at rest out of contact for `duration_s`, noise only: the no-contact recording,
    /// or a session's idle time between trials.
    pub fn simulate_idle(&self, name: &str, seed: u64, duration_s: f64) -> TrialRecording {
        let spec = TrialSpec {
            name: name.into(),
            direction_deg: 0.0,
            speed_deg_s: 0.0,
            depth_mm: 0.0,
            stop_deg: None,
            group: None,
            contact: false,
            seed,
            seating: 0,
        };
        let motion = Motion::rest(duration_s, self.params.contact.no_contact_gap_mm);
        self.run(&spec, &motion, &TrialErrors::default())
    }

    /// The camera's linear brightness image (row-major, full sensor) with the skin at `pose`:
    /// what a conventional camera inside the tip would see, for figures and checks.
    pub fn brightness_image(&self, pose: &SkinPose) -> Vec<f32> {
        let mut pins = Vec::new();
        self.dome.pins(pose, &Gains::default(), &mut pins);
        Dvs::new(&self.array, &self.params.dvs, &self.params.camera, &pins, 0).brightness_image()
    }

    fn run(&self, spec: &TrialSpec, motion: &Motion, errors: &TrialErrors) -> TrialRecording {
        let stream = |k: u64| trial_stream(spec.seed, k);
        let mut variation = stream(1);
        let v = self.params.contact.trial_variation;
        let mut gain = || (1.0 + v * gaussian(&mut variation)).max(0.1);
        let gains = Gains {
            normal: gain(),
            spread: gain(),
            shear: gain(),
        };
        let events = self.events(
            spec,
            motion,
            &gains,
            errors,
            rand::Rng::next_u64(&mut stream(2)),
        );
        // The direction in the sensor's frame: the commanded one turned by the seating.
        let direction_deg = errors.direction_deg(spec.direction_deg);
        let imu = simulate_imu(
            &self.params.imu,
            &self.calibration,
            motion,
            direction_deg,
            rand::Rng::next_u64(&mut stream(3)),
            rand::Rng::next_u64(&mut stream(5)),
        );
        let us = |t: f64| (t * 1e6).round() as i64;
        let duration_us = us(motion.end_s);
        let period = (1e6 / self.params.timeline.truth_rate_hz.max(1.0))
            .round()
            .max(1.0) as i64;
        let truth = (0..=duration_us / period)
            .map(|k| {
                let t_us = k * period;
                let theta = motion.theta(t_us as f64 * 1e-6);
                let (pitch, roll) = contact_angles(theta, direction_deg);
                TruthSample {
                    t_us,
                    theta_deg: theta,
                    pitch_deg: pitch,
                    roll_deg: roll,
                }
            })
            .collect();
        TrialRecording {
            spec: spec.clone(),
            events,
            imu,
            truth,
            motion_start_us: us(motion.motion_start_s),
            motion_end_us: us(motion.motion_end_s),
            stop_us: motion
                .stop_start_s
                .zip(motion.stop_end_s)
                .map(|(a, b)| (us(a), us(b))),
            duration_us,
        }
    }

    fn events(
        &self,
        spec: &TrialSpec,
        motion: &Motion,
        gains: &Gains,
        errors: &TrialErrors,
        seed: u64,
    ) -> Vec<Event> {
        let p = &self.params;
        let tau = p.contact.skin_tau_s.max(1e-6);
        let creep_tau = p.contact.creep_tau_s.max(1e-6);
        let creep = p.contact.creep_fraction.clamp(0.0, 1.0);
        let (max_px, min_dt, max_dt) = (
            p.dvs.max_px_per_step.max(1e-3) as f32,
            p.dvs.min_step_s.max(1e-7),
            p.dvs.max_step_s.max(p.dvs.min_step_s.max(1e-7)),
        );
        // The skin's pose from its fast and slow (creep) states, each `[tilt, depth]`; the rig's
        // errors move the indentation with the tilt and the patch on the dome.
        let pose = |fast: [f64; 2], slow: [f64; 2], t: f64| {
            let mix = |k: usize| (1.0 - creep) * fast[k] + creep * slow[k];
            let theta_s = mix(0);
            let (theta_deg, phi_deg) =
                errors.patch_tilt(theta_s, errors.direction_deg(spec.direction_deg));
            SkinPose {
                theta_deg,
                phi_deg,
                depth_mm: mix(1) + errors.depth_offset_mm(theta_s),
                lag_deg: motion.theta(t) - theta_s,
            }
        };
        // A lagged state: exact first-order response (time constant `tau`) to a linearly
        // changing input.
        let follow = |tau: f64, x0: f64, c0: f64, c1: f64, dt: f64| {
            let b = (c1 - c0) / dt;
            c1 - b * tau + (x0 - c0 + b * tau) * (-dt / tau).exp()
        };
        let mut fast = [motion.theta(0.0), motion.depth(0.0)];
        let mut slow = fast;
        let mut pins = Vec::new();
        self.dome.pins(&pose(fast, slow, 0.0), gains, &mut pins);
        let mut dvs = Dvs::new(&self.array, &p.dvs, &p.camera, &pins, seed);
        let mut next: Vec<PinImage> = Vec::new();
        let mut events = Vec::new();
        let (mut t, mut dt) = (0.0, min_dt);
        while t < motion.end_s {
            let (mut t1, mut fast1, mut slow1, mut disp);
            let mut tries = 0;
            loop {
                t1 = (t + dt).min(motion.end_s);
                let h = t1 - t;
                let (c0, c1) = (
                    [motion.theta(t), motion.depth(t)],
                    [motion.theta(t1), motion.depth(t1)],
                );
                fast1 = std::array::from_fn(|k| follow(tau, fast[k], c0[k], c1[k], h));
                slow1 = std::array::from_fn(|k| follow(creep_tau, slow[k], c0[k], c1[k], h));
                self.dome.pins(&pose(fast1, slow1, t1), gains, &mut next);
                disp = pins
                    .iter()
                    .zip(&next)
                    .map(|(a, b)| (a.x - b.x).abs().max((a.y - b.y).abs()))
                    .fold(0f32, f32::max);
                tries += 1;
                if disp <= max_px || dt <= min_dt || tries >= 6 {
                    break;
                }
                dt = (dt * 0.8 * f64::from(max_px / disp)).max(min_dt);
            }
            dvs.step(t1, &next, &mut events);
            std::mem::swap(&mut pins, &mut next);
            let used = t1 - t;
            (t, fast, slow) = (t1, fast1, slow1);
            // Next step: as long as the current pin speed allows, growing at most twofold.
            let ideal = if disp > 0.0 {
                used * f64::from(max_px / disp)
            } else {
                max_dt
            };
            dt = ideal.min(2.0 * used.max(min_dt)).clamp(min_dt, max_dt);
        }
        events
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::DvsParams;
    use crate::protocol::{Protocol, Scale, plan};

    fn spec(speed: f64, depth: f64) -> TrialSpec {
        let mut s = plan(Protocol::Exp1, Scale::Tiny, 1, &Default::default()).remove(0);
        s.speed_deg_s = speed;
        s.depth_mm = depth;
        s
    }

    fn quiet_sim() -> Simulator {
        let params = SimParams {
            dvs: DvsParams::noiseless(),
            ..SimParams::default()
        };
        Simulator::new(params, 1)
    }

    /// Events per second during the tilt.
    fn motion_rate(r: &TrialRecording) -> f64 {
        let n = r
            .events
            .iter()
            .filter(|e| e.t >= r.motion_start_us && e.t < r.motion_end_us)
            .count();
        n as f64 / ((r.motion_end_us - r.motion_start_us) as f64 * 1e-6)
    }

    #[test]
    fn the_seatings_turn_moves_the_truth_but_not_the_command() {
        // Only the seating's turn: the truth's direction is the command's plus the turn.
        let rig = crate::params::RigParams {
            reseat_rotation_sd_deg: 2.0,
            ..crate::params::RigParams::perfect()
        };
        let sim = Simulator::new(
            SimParams {
                rig: rig.clone(),
                ..SimParams::default()
            },
            1,
        );
        let spec = spec(8.0, 1.5);
        let turn = Seating::draw(&rig, spec.seating).rotation_deg;
        assert!(turn.abs() > 1e-3, "the draw is a turn: {turn}");
        let errors = sim.errors(&spec);
        assert_eq!(
            errors.direction_deg(spec.direction_deg),
            spec.direction_deg + turn
        );
        let r = sim.simulate(&spec);
        let last = r.truth.last().unwrap();
        let (pitch, roll) = contact_angles(last.theta_deg, spec.direction_deg + turn);
        assert!((last.pitch_deg - pitch).abs() < 1e-12 && (last.roll_deg - roll).abs() < 1e-12);
        assert_eq!(
            r.meta("t.aedat4", None, 20.0).direction_deg,
            spec.direction_deg
        );
        // Trials of one pass share a seating; the next pass has its own.
        let plan = crate::protocol::plan(Protocol::Exp1, Scale::Paper, 1, &Default::default());
        assert_eq!(plan[0].seating, plan[2].seating);
        assert_ne!(
            plan[0].seating, plan[1].seating,
            "two repeats, two seatings"
        );
    }

    #[test]
    fn same_seed_same_trial() {
        let sim = Simulator::new(SimParams::default(), 1);
        let s = spec(10.0, 2.0);
        let a = sim.simulate(&s);
        assert_eq!(a, sim.simulate(&s));
        assert!(a.events.windows(2).all(|w| w[0].t <= w[1].t));
        assert!(a.events.iter().all(|e| e.x < 640 && e.y < 480));
        assert_eq!(
            a.truth.last().map(|t| t.t_us),
            Some(a.duration_us / 1000 * 1000)
        );
    }

    /// Events in the last 100 ms before the tilt starts.
    fn settle_events(r: &TrialRecording) -> usize {
        r.events
            .iter()
            .filter(|e| e.t >= r.motion_start_us - 100_000 && e.t < r.motion_start_us)
            .count()
    }

    #[test]
    fn quiet_before_contact_busy_during_motion() {
        let r = quiet_sim().simulate(&spec(10.0, 2.0));
        let rate = motion_rate(&r);
        assert!(rate > 20_000.0, "{rate}");
        // The skin's fast response has settled by then: what moves is the creep, a trickle.
        let settle = settle_events(&r) as f64 / 0.1;
        assert!(
            settle < 0.05 * rate,
            "{settle} events/s at rest, {rate} moving"
        );
        // Without creep nothing moves at all.
        let mut params = quiet_sim().params().clone();
        params.contact.creep_fraction = 0.0;
        let r = Simulator::new(params, 1).simulate(&spec(10.0, 2.0));
        assert!(settle_events(&r) < 50, "{}", settle_events(&r));
    }

    #[test]
    fn the_skin_creeps_on_after_a_stop() {
        let mut s = plan(Protocol::Exp2, Scale::Tiny, 1, &Default::default()).remove(0);
        s.speed_deg_s = 10.0;
        let creeping = quiet_sim();
        let mut params = creeping.params().clone();
        params.contact.creep_fraction = 0.0;
        let elastic = Simulator::new(params, 1);
        // Events in the second half of the stop, after the fast recoil has died out.
        let late_stop = |r: &TrialRecording| {
            let (a, b) = r.stop_us.expect("a stop");
            r.events
                .iter()
                .filter(|e| e.t >= (a + b) / 2 && e.t < b)
                .count()
        };
        let (with, without) = (
            late_stop(&creeping.simulate(&s)),
            late_stop(&elastic.simulate(&s)),
        );
        assert!(
            with > 2 * without + 20,
            "{with} events with creep, {without} without"
        );
    }

    #[test]
    fn the_robot_reaches_its_targets_within_its_repeatability() {
        let sim = Simulator::new(SimParams::default(), 1);
        let s = plan(Protocol::Exp2, Scale::Tiny, 1, &Default::default()).remove(0);
        let r = sim.simulate(&s);
        let commanded = s.stop_deg.expect("a stop");
        let (a, b) = r.stop_us.expect("a stop");
        let at = |t: i64| {
            r.truth
                .iter()
                .find(|x| x.t_us >= t)
                .expect("inside")
                .theta_deg
        };
        let stop_error = at((a + b) / 2) - commanded;
        let final_error = r.truth.last().unwrap().theta_deg - sim.params().timeline.total_deg;
        let sd = sim.params().rig.angle_sd_deg;
        assert!(
            stop_error != 0.0 && stop_error.abs() < 5.0 * sd,
            "{stop_error}"
        );
        assert!(
            final_error != 0.0 && final_error.abs() < 5.0 * sd,
            "{final_error}"
        );
        // The manifest keeps the commands.
        let meta = r.meta("t.aedat4", None, sim.params().timeline.total_deg);
        assert_eq!(meta.stop_deg, Some(commanded));
    }
}
