//! The rig's imperfections in one trial: what makes two trials of the same condition differ
//! beyond sensor noise, and what keeps the labels from matching the robot's commands exactly.
//!
//! A real rig never repeats itself: the robot reaches each commanded angle within its
//! repeatability, the plane's height and the rotation centre are known only to a calibration's
//! accuracy, and the contact patch sits a little differently on the dome each time. Between
//! passes over the conditions (the repeats) the sensor is taken off and seated again
//! ([`Seating`]): it sits turned a little about its axis, tilted a little in its mount, and a
//! little longer or shorter, so two repeats of one condition differ by more than the robot's
//! repeatability; trials of one pass share their seating. Without
//! these, simulated trials of one condition differed only by sensor noise and the skin's gain
//! variation, the labels matched the commanded stop angle to 0.001 deg (the paper validates its
//! labels to -0.01 +- 0.04 deg), and simulated errors were optimistic. Each error is drawn once
//! per trial from [`RigParams`] (see `docs/simulator.md` for the values and their sources), from
//! its own random stream, so the other draws of a trial do not move when one of these changes.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::dvs::gaussian;
use crate::params::RigParams;

/// The rig's errors in one trial.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrialErrors {
    /// Reached minus commanded tilt at the stop (Experiment 2), degrees.
    pub stop_deg: f64,
    /// Reached minus commanded final tilt, degrees.
    pub total_deg: f64,
    /// Error of the plane's height: added to the commanded indentation, millimetres.
    pub plane_height_mm: f64,
    /// Distance of the robot's rotation centre from the dome's centre along the sensor's axis
    /// (positive: farther from the plane), millimetres.
    pub rolling_centre_mm: f64,
    /// Where the contact patch sits on the dome at zero tilt, as a tilt offset (x, y) in
    /// degrees in the sensor frame.
    pub patch_offset_deg: [f64; 2],
    /// The sensor's turn about its own axis in the mount (its seating), degrees: the tilt's
    /// direction in the sensor's frame is the commanded one plus this. The labels, which
    /// project the gyroscope on the commanded rolling axis, do not see it.
    pub rotation_deg: f64,
}

/// How the sensor sits in its mount for one pass over the conditions: drawn once per seating
/// from [`RigParams`]'s `reseat_*` values, from its own seed, and added to each trial's errors
/// ([`TrialErrors::seated`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Seating {
    /// Turn about the sensor's axis, degrees.
    pub rotation_deg: f64,
    /// Tilt of the sensor's axis against the tool's (x, y), degrees: at zero commanded tilt the
    /// dome already meets the plane this much off its tip.
    pub tilt_deg: [f64; 2],
    /// How much farther the tip reaches than in the calibration, millimetres: added to every
    /// indentation.
    pub height_mm: f64,
}

impl Seating {
    /// Draws a seating from `params` with `seed`.
    pub fn draw(params: &RigParams, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut normal = |sd: f64| sd * gaussian(&mut rng);
        Self {
            rotation_deg: normal(params.reseat_rotation_sd_deg),
            tilt_deg: [
                normal(params.reseat_tilt_sd_deg),
                normal(params.reseat_tilt_sd_deg),
            ],
            height_mm: normal(params.reseat_height_sd_mm),
        }
    }
}

impl TrialErrors {
    /// Draws the errors of one trial from `params` with `seed`.
    pub fn draw(params: &RigParams, tip_radius_mm: f64, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut normal = |sd: f64| sd * gaussian(&mut rng);
        let stop_deg = normal(params.angle_sd_deg);
        let total_deg = normal(params.angle_sd_deg);
        let plane_height_mm = normal(params.plane_height_sd_mm);
        let rolling_centre_mm = normal(params.rolling_centre_sd_mm);
        // An offset of the patch by `s` millimetres along the dome's surface is a tilt of
        // `s / radius` radians.
        let to_deg = (1.0 / tip_radius_mm.max(1e-6)).to_degrees();
        let patch_offset_deg = [
            normal(params.patch_offset_sd_mm) * to_deg,
            normal(params.patch_offset_sd_mm) * to_deg,
        ];
        Self {
            stop_deg,
            total_deg,
            plane_height_mm,
            rolling_centre_mm,
            patch_offset_deg,
            rotation_deg: 0.0,
        }
    }

    /// These errors with the sensor seated as `seating`: its turn, its tilt added to the
    /// patch's offset and its reach to the plane's height error.
    pub fn seated(self, seating: &Seating) -> Self {
        Self {
            plane_height_mm: self.plane_height_mm + seating.height_mm,
            patch_offset_deg: [
                self.patch_offset_deg[0] + seating.tilt_deg[0],
                self.patch_offset_deg[1] + seating.tilt_deg[1],
            ],
            rotation_deg: self.rotation_deg + seating.rotation_deg,
            ..self
        }
    }

    /// The tilt's direction in the sensor's frame for a commanded direction `commanded_deg`.
    pub fn direction_deg(&self, commanded_deg: f64) -> f64 {
        commanded_deg + self.rotation_deg
    }

    /// Indentation added at tilt `theta_deg`: the plane's height error, less the rise of the
    /// dome's centre when the robot turns about a centre `rolling_centre_mm` above it
    /// (`e (1 - cos theta)`).
    pub fn depth_offset_mm(&self, theta_deg: f64) -> f64 {
        self.plane_height_mm - self.rolling_centre_mm * (1.0 - theta_deg.to_radians().cos())
    }

    /// The tilt (magnitude, direction) of the dome against the plane for a skin tilt of
    /// `theta_deg` towards `phi_deg`: the patch offset added as a tilt vector.
    pub fn patch_tilt(&self, theta_deg: f64, phi_deg: f64) -> (f64, f64) {
        if self.patch_offset_deg == [0.0, 0.0] {
            return (theta_deg, phi_deg);
        }
        let phi = phi_deg.to_radians();
        let x = theta_deg * phi.cos() + self.patch_offset_deg[0];
        let y = theta_deg * phi.sin() + self.patch_offset_deg[1];
        (x.hypot(y), y.atan2(x).to_degrees())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_errors_leave_the_pose_alone() {
        let e = TrialErrors::draw(&RigParams::perfect(), 20.0, 3);
        assert_eq!(e, TrialErrors::default());
        assert_eq!(e.patch_tilt(12.0, 135.0), (12.0, 135.0));
        assert_eq!(e.depth_offset_mm(20.0), 0.0);
    }

    /// The standard deviation of `values` (over n: the draws are the whole population here).
    fn population_sd(values: impl Iterator<Item = f64>) -> f64 {
        let v: Vec<f64> = values.collect();
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
    }

    /// Whether a measured spread `a` is within 6 % of the asked `b`.
    fn close(a: f64, b: f64) -> bool {
        (a / b - 1.0).abs() < 0.06
    }

    #[test]
    fn errors_have_the_given_spread() {
        let p = RigParams::default();
        let draws: Vec<TrialErrors> = (0..4000).map(|s| TrialErrors::draw(&p, 20.0, s)).collect();
        let sd = |f: &dyn Fn(&TrialErrors) -> f64| population_sd(draws.iter().map(f));
        assert!(close(sd(&|e| e.stop_deg), p.angle_sd_deg));
        assert!(close(sd(&|e| e.total_deg), p.angle_sd_deg));
        assert!(close(sd(&|e| e.plane_height_mm), p.plane_height_sd_mm));
        assert!(close(sd(&|e| e.rolling_centre_mm), p.rolling_centre_sd_mm));
        let patch_deg = (p.patch_offset_sd_mm / 20.0).to_degrees();
        assert!(close(sd(&|e| e.patch_offset_deg[0]), patch_deg));
    }

    #[test]
    fn a_seating_adds_to_every_trial_of_its_pass() {
        let p = RigParams::default();
        let seating = Seating::draw(&p, 11);
        assert_eq!(seating, Seating::draw(&p, 11));
        assert_ne!(seating, Seating::draw(&p, 12));
        let trial = TrialErrors::draw(&p, 20.0, 3);
        let seated = trial.seated(&seating);
        assert_eq!(seated.stop_deg, trial.stop_deg);
        assert_eq!(seated.rolling_centre_mm, trial.rolling_centre_mm);
        assert_eq!(
            seated.plane_height_mm,
            trial.plane_height_mm + seating.height_mm
        );
        assert_eq!(
            seated.patch_offset_deg[1],
            trial.patch_offset_deg[1] + seating.tilt_deg[1]
        );
        assert_eq!(seated.direction_deg(90.0), 90.0 + seating.rotation_deg);
        // Spread as asked.
        let draws: Vec<Seating> = (0..4000).map(|s| Seating::draw(&p, s)).collect();
        let sd = |f: &dyn Fn(&Seating) -> f64| population_sd(draws.iter().map(f));
        assert!(close(sd(&|s| s.rotation_deg), p.reseat_rotation_sd_deg));
        assert!(close(sd(&|s| s.tilt_deg[0]), p.reseat_tilt_sd_deg));
        assert!(close(sd(&|s| s.height_mm), p.reseat_height_sd_mm));
        // A perfect rig seats the sensor the same way every time.
        assert_eq!(Seating::draw(&RigParams::perfect(), 5), Seating::default());
    }

    #[test]
    fn a_rotation_centre_above_the_dome_lifts_it_as_it_tilts() {
        let e = TrialErrors {
            rolling_centre_mm: 2.0,
            ..TrialErrors::default()
        };
        assert_eq!(e.depth_offset_mm(0.0), 0.0);
        let lift = 2.0 * (1.0 - 20f64.to_radians().cos());
        assert!((e.depth_offset_mm(20.0) + lift).abs() < 1e-12);
    }

    #[test]
    fn the_patch_offset_adds_as_a_tilt_vector() {
        let e = TrialErrors {
            patch_offset_deg: [0.0, 1.0],
            ..TrialErrors::default()
        };
        let (theta, phi) = e.patch_tilt(0.0, 0.0);
        assert!((theta - 1.0).abs() < 1e-12 && (phi - 90.0).abs() < 1e-12);
        let (theta, phi) = e.patch_tilt(1.0, 0.0);
        assert!((theta - 2f64.sqrt()).abs() < 1e-12 && (phi - 45.0).abs() < 1e-12);
    }
}
