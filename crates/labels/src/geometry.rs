//! The one definition of evtac's angle conventions, used by the simulator, the labels and the
//! reports alike.
//!
//! # Frames
//! The **sensor frame** has its origin at the centre of the tip's sphere; `z` runs along the
//! dome's axis from the camera towards the tip, and `x`, `y` are parallel to the camera's image
//! axes (`x` to the right, `y` downwards). The IMU has its own frame; the calibrated extrinsic
//! rotation [`Calibration::imu_to_sensor`] maps IMU vectors into the sensor frame.
//!
//! # Tilt
//! The robot tilts the sensor by the **tilt magnitude** `theta` in the **tilt direction** `phi`
//! (azimuth in the sensor's `x`-`y` plane, measured from `+x` towards `+y`). Seen from the sensor,
//! the direction from the sphere's centre to the contact point (the inward normal of the plane) is
//!
//! ```text
//! d = (sin(theta) cos(phi), sin(theta) sin(phi), cos(theta))
//! ```
//!
//! which is the `+z` axis turned by `theta` about the **rolling axis**
//! `a = (-sin(phi), cos(phi), 0)`. The sensor itself turns the other way in the world, so its
//! gyroscope (in the sensor frame) reads `omega = -theta_dot * a`: see [`sensor_angular_velocity`]
//! and [`axial_rate`].
//!
//! # Contact angles
//! The sensor-to-plane contact angles are the plane's inclination seen in the sensor's two
//! principal planes:
//!
//! ```text
//! pitch = atan2(d_x, d_z)      (tilt in the x-z plane, positive towards +x)
//! roll  = atan2(d_y, d_z)      (tilt in the y-z plane, positive towards +y)
//! ```
//!
//! so `phi = 0` gives `(pitch, roll) = (theta, 0)` and `phi = 90 deg` gives `(0, theta)`.
//! Angles are in degrees at every public function here.

use serde::{Deserialize, Serialize};

/// The calibrated geometry of one sensor: what turns IMU readings and tilt into contact angles.
/// Datasets store it as `calibration.json` beside `trials.csv`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// Rotation (row-major 3x3) taking vectors from the IMU frame into the sensor frame:
    /// `v_sensor = imu_to_sensor * v_imu`.
    pub imu_to_sensor: [[f64; 3]; 3],
    /// Outer radius of the tip's hemisphere in millimetres.
    pub tip_radius_mm: f64,
}

impl Default for Calibration {
    /// The identity extrinsics and the NeuroTac's 20 mm tip.
    fn default() -> Self {
        Self {
            imu_to_sensor: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            tip_radius_mm: 20.0,
        }
    }
}

impl Calibration {
    /// Maps a vector from the IMU frame into the sensor frame.
    pub fn imu_to_sensor(&self, v: [f64; 3]) -> [f64; 3] {
        let m = &self.imu_to_sensor;
        std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
    }

    /// Maps a vector from the sensor frame into the IMU frame (the transpose of the rotation).
    pub fn sensor_to_imu(&self, v: [f64; 3]) -> [f64; 3] {
        let m = &self.imu_to_sensor;
        std::array::from_fn(|i| m[0][i] * v[0] + m[1][i] * v[1] + m[2][i] * v[2])
    }
}

/// The rolling axis `a = (-sin(phi), cos(phi), 0)` for tilt direction `phi_deg`, in the sensor frame.
pub fn rolling_axis(phi_deg: f64) -> [f64; 3] {
    let phi = phi_deg.to_radians();
    [-phi.sin(), phi.cos(), 0.0]
}

/// The inward plane normal `d` seen from the sensor at tilt `theta_deg` in direction `phi_deg`.
pub fn contact_direction(theta_deg: f64, phi_deg: f64) -> [f64; 3] {
    let (theta, phi) = (theta_deg.to_radians(), phi_deg.to_radians());
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

/// The contact angles `(pitch_deg, roll_deg)` for tilt `theta_deg` in direction `phi_deg`.
pub fn contact_angles(theta_deg: f64, phi_deg: f64) -> (f64, f64) {
    let d = contact_direction(theta_deg, phi_deg);
    (d[0].atan2(d[2]).to_degrees(), d[1].atan2(d[2]).to_degrees())
}

/// The sensor's angular velocity (deg/s, sensor frame) while its tilt grows at `theta_dot_deg_s`
/// in direction `phi_deg`: `-theta_dot * a`.
pub fn sensor_angular_velocity(theta_dot_deg_s: f64, phi_deg: f64) -> [f64; 3] {
    rolling_axis(phi_deg).map(|c| -theta_dot_deg_s * c)
}

/// The tilt rate (deg/s) that a sensor-frame angular velocity `omega_deg_s` carries about the
/// rolling axis of direction `phi_deg`: the inverse of [`sensor_angular_velocity`].
pub fn axial_rate(omega_deg_s: [f64; 3], phi_deg: f64) -> f64 {
    let a = rolling_axis(phi_deg);
    -(omega_deg_s[0] * a[0] + omega_deg_s[1] * a[1] + omega_deg_s[2] * a[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn principal_directions() {
        let (p, r) = contact_angles(12.0, 0.0);
        assert!(close(p, 12.0) && close(r, 0.0));
        let (p, r) = contact_angles(12.0, 90.0);
        assert!(close(p, 0.0) && close(r, 12.0));
        let (p, r) = contact_angles(12.0, 180.0);
        assert!(close(p, -12.0) && close(r, 0.0));
        let (p, r) = contact_angles(0.0, 37.0);
        assert!(close(p, 0.0) && close(r, 0.0));
    }

    #[test]
    fn axial_rate_inverts_angular_velocity() {
        for phi in [0.0, 18.0, 123.0, 271.5] {
            let w = sensor_angular_velocity(6.5, phi);
            assert!(close(axial_rate(w, phi), 6.5));
        }
    }

    #[test]
    fn extrinsics_round_trip() {
        let c = 30f64.to_radians();
        let s = 30f64.to_radians().sin();
        let cal = Calibration {
            imu_to_sensor: [[c.cos(), -s, 0.0], [s, c.cos(), 0.0], [0.0, 0.0, 1.0]],
            tip_radius_mm: 20.0,
        };
        let v = [0.3, -1.2, 0.7];
        let back = cal.sensor_to_imu(cal.imu_to_sensor(v));
        for i in 0..3 {
            assert!((back[i] - v[i]).abs() < 1e-12);
        }
    }
}
