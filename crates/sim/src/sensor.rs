//! The tip: where the pins are, how the contact with a flat plane moves them, and where the camera
//! inside sees them.
//!
//! # Geometry
//! The sensor frame of [`evtac_labels::geometry`]: origin at the centre of the tip's sphere, `z`
//! along the dome's axis towards the tip, `x`/`y` along the image axes. Pin `i` sits on the
//! sphere of radius `R - skin - pin_length` at the unit direction `n_i`; the directions come from
//! a hexagonal grid (centre pin plus `6 k` pins in ring `k`) whose planar radius is mapped
//! linearly to the polar angle, the outermost ring's corners at `outer_ring_deg`.
//!
//! # Contact
//! The plane's inward normal is `d = contact_direction(theta, phi)` and the plane lies at distance
//! `R - depth` from the centre. The undeformed skin at `n_i` penetrates it by
//! `p_i = depth - R (1 - n_i . d)` (positive inside the contact patch); the effective penetration
//! `w_i = fade * ln(1 + exp(p_i / fade))` equals `p_i` deep inside the patch and fades smoothly to
//! zero outside it. Each pin tip moves by
//!
//! ```text
//! normal:  -normal_gain * w_i * d                               (pushed in along the normal)
//! spread:  +spread_gain * w_i * t_i / sin(spread_ref)           (t_i = n_i - (n_i . d) d: away
//!                                                                from the patch centre)
//! shear:   -shear_mm_per_deg * lag * (1 - exp(-w_i / grip)) * m (against the motion: the stuck
//!                                                                patch trails the pose)
//! ```
//!
//! where `m = d(d)/d(theta)` is the direction the contact point travels in and `lag` is how far
//! (degrees) the skin's tilt trails the commanded tilt (see [`crate::trial`]). Pins pushed towards
//! the camera appear farther from the image centre and larger, so the contact patch shows as a
//! region of spread, swollen blobs.
//!
//! # Camera
//! A pinhole on the axis `behind_centre_mm` below the centre, looking along `+z`; its focal
//! length puts the outermost ring's corners at `outer_ring_px` from the image centre at rest, so
//! the centered 240x240 crop covers the array. A pin renders as a Gaussian blob with standard
//! deviation `f * pin_sigma_mm / distance` pixels.

use evtac_labels::geometry::contact_direction;

use crate::params::{CameraParams, ContactParams, SensorParams};

/// One pin as the camera sees it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PinImage {
    /// Column of the blob's centre on the full sensor (pixels, may be fractional).
    pub x: f32,
    /// Row of the blob's centre (pixels, `y` downwards).
    pub y: f32,
    /// Blob standard deviation in pixels.
    pub sigma: f32,
}

/// The skin's pose: what the deformation depends on at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SkinPose {
    /// The skin's tilt magnitude, degrees.
    pub theta_deg: f64,
    /// The tilt direction, degrees.
    pub phi_deg: f64,
    /// The skin's indentation depth, millimetres (negative: a gap, no contact).
    pub depth_mm: f64,
    /// How far the skin's tilt trails the commanded tilt, degrees (drives the shear).
    pub lag_deg: f64,
}

/// Per-trial multipliers of the contact gains (real trials differ a little).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// Multiplies [`ContactParams::normal_gain`].
    pub normal: f64,
    /// Multiplies [`ContactParams::spread_gain`].
    pub spread: f64,
    /// Multiplies [`ContactParams::shear_mm_per_deg`].
    pub shear: f64,
}

impl Default for Gains {
    fn default() -> Self {
        Self {
            normal: 1.0,
            spread: 1.0,
            shear: 1.0,
        }
    }
}

/// The tip's pins and the camera model: turns a [`SkinPose`] into pin images.
#[derive(Debug, Clone)]
pub struct Dome {
    sensor: SensorParams,
    contact: ContactParams,
    /// Unit directions of the pins in the sensor frame.
    directions: Vec<[f64; 3]>,
    /// Radius of the sphere the pin tips lie on.
    tip_sphere_mm: f64,
    focal_px: f64,
    centre: [f64; 2],
    camera_z: f64,
}

impl Dome {
    /// Builds the pin layout and the camera for these parameters.
    pub fn new(sensor: &SensorParams, contact: &ContactParams, camera: &CameraParams) -> Self {
        let rings = sensor.rings as i64;
        let mut directions = Vec::with_capacity(sensor.pin_count());
        let alpha_max = sensor.outer_ring_deg.to_radians();
        // Axial hexagon coordinates (q, r) within `rings` steps of the centre, in a fixed order.
        for q in -rings..=rings {
            for r in (-rings).max(-q - rings)..=rings.min(-q + rings) {
                let (x, y) = (q as f64 + r as f64 / 2.0, r as f64 * 3f64.sqrt() / 2.0);
                let rho = x.hypot(y);
                let alpha = if rings == 0 {
                    0.0
                } else {
                    rho / rings as f64 * alpha_max
                };
                let beta = y.atan2(x);
                directions.push([
                    alpha.sin() * beta.cos(),
                    alpha.sin() * beta.sin(),
                    alpha.cos(),
                ]);
            }
        }
        let tip_sphere_mm = sensor.tip_radius_mm - sensor.skin_mm - sensor.pin_length_mm;
        let camera_z = -camera.behind_centre_mm;
        let outer = tip_sphere_mm * alpha_max.sin() / (tip_sphere_mm * alpha_max.cos() - camera_z);
        let focal_px = if outer > 0.0 {
            camera.outer_ring_px / outer
        } else {
            camera.outer_ring_px
        };
        Self {
            sensor: sensor.clone(),
            contact: contact.clone(),
            directions,
            tip_sphere_mm,
            focal_px,
            centre: [
                f64::from(camera.width) / 2.0 - 0.5,
                f64::from(camera.height) / 2.0 - 0.5,
            ],
            camera_z,
        }
    }

    /// Number of pins.
    pub fn pin_count(&self) -> usize {
        self.directions.len()
    }

    /// The camera's focal length in pixels.
    pub fn focal_px(&self) -> f64 {
        self.focal_px
    }

    /// Writes the image of every pin at `pose` into `out` (resized to the pin count).
    pub fn pins(&self, pose: &SkinPose, gains: &Gains, out: &mut Vec<PinImage>) {
        out.clear();
        let c = &self.contact;
        let d = contact_direction(pose.theta_deg, pose.phi_deg);
        let (th, ph) = (pose.theta_deg.to_radians(), pose.phi_deg.to_radians());
        let m = [th.cos() * ph.cos(), th.cos() * ph.sin(), -th.sin()];
        let radius = self.sensor.tip_radius_mm;
        let fade = c.fade_mm.max(1e-6);
        let spread = c.spread_gain * gains.spread / c.spread_ref_deg.to_radians().sin().max(1e-6);
        let shear = c.shear_mm_per_deg * gains.shear * pose.lag_deg;
        for n in &self.directions {
            let cos = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
            let pen = pose.depth_mm - radius * (1.0 - cos);
            let w = softplus(pen / fade) * fade;
            let grip = 1.0 - (-w / c.shear_grip_mm.max(1e-6)).exp();
            let p: [f64; 3] = std::array::from_fn(|k| {
                self.tip_sphere_mm * n[k] - c.normal_gain * gains.normal * w * d[k]
                    + spread * w * (n[k] - cos * d[k])
                    - shear * grip * m[k]
            });
            let depth = (p[2] - self.camera_z).max(1e-3);
            let s = self.focal_px / depth;
            out.push(PinImage {
                x: (self.centre[0] + s * p[0]) as f32,
                y: (self.centre[1] + s * p[1]) as f32,
                sigma: (s * self.sensor.pin_sigma_mm) as f32,
            });
        }
    }
}

/// `ln(1 + exp(x))` without overflow.
fn softplus(x: f64) -> f64 {
    if x > 30.0 { x } else { x.exp().ln_1p() }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dome() -> Dome {
        Dome::new(
            &SensorParams::default(),
            &ContactParams::default(),
            &CameraParams::default(),
        )
    }

    fn rest() -> SkinPose {
        SkinPose {
            depth_mm: -2.0,
            ..SkinPose::default()
        }
    }

    #[test]
    fn pin_array_fits_the_centered_crop() {
        let d = dome();
        assert_eq!(d.pin_count(), 331);
        let mut pins = Vec::new();
        d.pins(&rest(), &Gains::default(), &mut pins);
        for p in &pins {
            assert!(
                (200.0..440.0).contains(&p.x) && (120.0..360.0).contains(&p.y),
                "{p:?}"
            );
            assert!(p.sigma > 1.0 && p.sigma < 5.0, "{p:?}");
        }
        let max_r = pins
            .iter()
            .map(|p| (p.x - 319.5).hypot(p.y - 239.5))
            .fold(0f32, f32::max);
        assert!((max_r - 108.0).abs() < 0.01, "{max_r}");
    }

    #[test]
    fn contact_moves_pins_in_the_patch_only() {
        let d = dome();
        let (mut free, mut pressed) = (Vec::new(), Vec::new());
        d.pins(&rest(), &Gains::default(), &mut free);
        let pose = SkinPose {
            theta_deg: 15.0,
            phi_deg: 0.0,
            depth_mm: 2.0,
            lag_deg: 0.0,
        };
        d.pins(&pose, &Gains::default(), &mut pressed);
        let moved = |i: usize| (pressed[i].x - free[i].x).hypot(pressed[i].y - free[i].y);
        // The patch is centred at +x: pins there move by pixels, pins on the far side do not.
        let (near, far): (Vec<usize>, Vec<usize>) = (0..free.len())
            .filter(|&i| (free[i].x - 319.5).abs() > 40.0)
            .partition(|&i| free[i].x > 319.5);
        let near_max = near.iter().map(|&i| moved(i)).fold(0f32, f32::max);
        let far_max = far.iter().map(|&i| moved(i)).fold(0f32, f32::max);
        assert!(near_max > 3.0, "{near_max}");
        assert!(far_max < 0.05, "{far_max}");
    }

    #[test]
    fn deeper_indentation_moves_pins_more() {
        let d = dome();
        let mut free = Vec::new();
        d.pins(&rest(), &Gains::default(), &mut free);
        let total = |depth: f64| {
            let mut pins = Vec::new();
            let pose = SkinPose {
                depth_mm: depth,
                ..SkinPose::default()
            };
            d.pins(&pose, &Gains::default(), &mut pins);
            pins.iter()
                .zip(&free)
                .map(|(a, b)| (a.x - b.x).hypot(a.y - b.y))
                .sum::<f32>()
        };
        assert!(total(1.0) < total(2.0) && total(2.0) < total(3.0));
    }
}
