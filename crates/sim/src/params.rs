//! Every parameter of the simulator, with the values it uses by default and why.
//!
//! [`SimParams`] is saved beside each dataset as `simulator.json`, so a dataset always says how it
//! was made. Lengths are in millimetres, angles in degrees, times in seconds unless a field's name
//! says otherwise.

use serde::{Deserialize, Serialize};

/// All simulator parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct SimParams {
    /// The tip and its pins.
    pub sensor: SensorParams,
    /// The contact between the tip and the flat plane.
    pub contact: ContactParams,
    /// The camera inside the tip and the image it sees.
    pub camera: CameraParams,
    /// The event camera's pixel model (v2e's names).
    pub dvs: DvsParams,
    /// The inertial measurement unit beside the camera.
    pub imu: ImuParams,
    /// The robot's motion and the timing of a trial.
    pub timeline: TimelineParams,
    /// The rig's imperfections: robot repeatability, calibration errors, patch position.
    pub rig: RigParams,
}

/// The hemispherical tip and its internal pins.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorParams {
    /// Outer radius of the tip's hemisphere (the NeuroTac's 20 mm).
    pub tip_radius_mm: f64,
    /// Thickness of the silicone skin.
    pub skin_mm: f64,
    /// Length of a pin from the inside of the skin to its white tip (what the camera sees).
    pub pin_length_mm: f64,
    /// Number of hexagonal rings around the centre pin: ring `i` holds `6 i` pins, so 10 rings
    /// give 331 pins (the default) and 6 rings 127.
    pub rings: u32,
    /// Polar angle of the outermost ring from the dome's axis; pins are spaced evenly in arc
    /// length up to it.
    pub outer_ring_deg: f64,
    /// Radius of a pin's bright tip (the Gaussian blob's standard deviation in millimetres).
    pub pin_sigma_mm: f64,
}

impl Default for SensorParams {
    fn default() -> Self {
        Self {
            tip_radius_mm: 20.0,
            skin_mm: 1.25,
            pin_length_mm: 1.0,
            rings: 10,
            outer_ring_deg: 55.0,
            pin_sigma_mm: 0.35,
        }
    }
}

impl SensorParams {
    /// Number of pins: `1 + 3 rings (rings + 1)`.
    pub fn pin_count(&self) -> usize {
        let r = self.rings as usize;
        1 + 3 * r * (r + 1)
    }
}

/// The contact with a rigid flat plane, and the skin's dynamics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactParams {
    /// How much of the skin's penetration into the plane moves a pin tip along the plane normal
    /// (the rest is taken up by the silicone's compression).
    pub normal_gain: f64,
    /// Lateral spreading of pins away from the patch centre, in millimetres per millimetre of
    /// penetration at a polar distance of `spread_ref_deg` from the patch centre. It includes
    /// the pins' lever action: a pin tip moves farther than the skin it stands on when the skin
    /// tilts, which is what makes the NeuroTac's pins sensitive.
    pub spread_gain: f64,
    /// Polar distance from the patch centre at which `spread_gain` applies (spread grows
    /// linearly with the distance's sine).
    pub spread_ref_deg: f64,
    /// Length over which the deformation fades outside the geometric contact patch: the
    /// effective penetration is `fade * ln(1 + exp(p / fade))` of the geometric one `p`.
    pub fade_mm: f64,
    /// Time constant of the skin's first-order (viscoelastic) lag behind the commanded pose;
    /// after a stop the skin relaxes over a few of these ("elastic recoil").
    pub skin_tau_s: f64,
    /// Shear of the stuck contact patch against the direction of motion, in millimetres per
    /// degree that the skin lags behind the commanded tilt.
    pub shear_mm_per_deg: f64,
    /// Penetration at which a pin counts as fully stuck for the shear (weight `1 - exp(-w/this)`).
    pub shear_grip_mm: f64,
    /// Per-trial relative spread of the skin's stiffness-like gains (normal, spread, shear): real
    /// trials are never quite identical.
    pub trial_variation: f64,
    /// Share of the skin's response that follows the commanded pose slowly, with time constant
    /// `creep_tau_s` (the rest follows with `skin_tau_s`): silicone creeps on under a held
    /// indentation or tilt, and its loading and unloading paths differ (hysteresis). A
    /// two-term Prony series, the usual model of a viscoelastic solid.
    pub creep_fraction: f64,
    /// Time constant of the slow (creep) share of the skin's response.
    pub creep_tau_s: f64,
    /// Where the plane starts before the indentation, as a negative depth (a gap).
    pub approach_gap_mm: f64,
    /// Where the plane stays in the no-contact protocol and recording (far out of reach).
    pub no_contact_gap_mm: f64,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            normal_gain: 0.9,
            spread_gain: 1.5,
            spread_ref_deg: 20.0,
            fade_mm: 0.3,
            skin_tau_s: 0.06,
            shear_mm_per_deg: 1.2,
            shear_grip_mm: 0.3,
            trial_variation: 0.03,
            creep_fraction: 0.02,
            creep_tau_s: 1.0,
            approach_gap_mm: 0.5,
            no_contact_gap_mm: 10.0,
        }
    }
}

/// The camera inside the tip and the scene's brightness.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraParams {
    /// Sensor width in pixels (DVXplorer: 640).
    pub width: u16,
    /// Sensor height in pixels (DVXplorer: 480).
    pub height: u16,
    /// Distance of the pinhole below the sphere's centre along the axis.
    pub behind_centre_mm: f64,
    /// Image radius in pixels of the outermost ring at rest; sets the focal length so that the
    /// centered 240x240 crop just covers the pin array.
    pub outer_ring_px: f64,
    /// Brightness of the dark background (linear, 1 = full scale).
    pub background: f64,
    /// Peak brightness a pin adds (linear).
    pub pin_brightness: f64,
    /// Relative brightness lost towards the image corners (a soft vignette of the LED lighting).
    pub vignetting: f64,
    /// Pixels farther than this many blob sigmas from a pin are not lit by it; the blob's value
    /// at this radius is subtracted so that its edge is continuous (no spurious events when a
    /// pin's reach moves over a pixel).
    pub blob_cutoff_sigmas: f64,
}

impl Default for CameraParams {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            behind_centre_mm: 6.0,
            outer_ring_px: 108.0,
            background: 0.03,
            pin_brightness: 0.8,
            vignetting: 0.3,
            blob_cutoff_sigmas: 3.0,
        }
    }
}

/// The DVS pixel model, with the names and meaning of v2e's (Hu, Liu and Delbruck, 2021) options.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DvsParams {
    /// Nominal ON threshold in log intensity.
    pub pos_thres: f64,
    /// Nominal OFF threshold in log intensity.
    pub neg_thres: f64,
    /// Standard deviation of the per-pixel threshold mismatch.
    pub sigma_thres: f64,
    /// Smallest threshold a mismatched pixel may get.
    pub min_thres: f64,
    /// Photoreceptor low-pass 3 dB cutoff at full brightness; dimmer pixels are slower, as in
    /// v2e (`(255 I + 20) / 275` times this).
    pub cutoff_hz: f64,
    /// Refractory period after an event, during which the pixel cannot fire.
    pub refractory_period_s: f64,
    /// Rate of leak (ON) noise events per pixel.
    pub leak_rate_hz: f64,
    /// Rate of shot noise events (ON and OFF together) per pixel.
    pub shot_noise_rate_hz: f64,
    /// Number of hot pixels (fixed per camera).
    pub hot_pixels: u32,
    /// Lowest and highest event rate of a hot pixel.
    pub hot_pixel_rate_hz: [f64; 2],
    /// Offset added before the log, so that black pixels have a finite log intensity (v2e's
    /// linear-log region plays the same role).
    pub log_eps: f64,
    /// Largest image motion of any pin per simulation step, in pixels.
    pub max_px_per_step: f64,
    /// A pin is redrawn once its image moved this far (pixels) since it was last drawn; slower
    /// pins are not redrawn every step.
    pub redraw_px: f64,
    /// Longest simulation step.
    pub max_step_s: f64,
    /// Shortest simulation step.
    pub min_step_s: f64,
}

impl Default for DvsParams {
    fn default() -> Self {
        Self {
            pos_thres: 0.2,
            neg_thres: 0.2,
            sigma_thres: 0.03,
            min_thres: 0.01,
            cutoff_hz: 300.0,
            refractory_period_s: 0.0005,
            leak_rate_hz: 0.01,
            shot_noise_rate_hz: 0.02,
            hot_pixels: 12,
            hot_pixel_rate_hz: [20.0, 100.0],
            log_eps: 0.01,
            max_px_per_step: 0.5,
            redraw_px: 0.1,
            max_step_s: 0.005,
            min_step_s: 0.00002,
        }
    }
}

impl DvsParams {
    /// The default pixels without background activity (no leak or shot noise, no hot pixels):
    /// the events a contact causes, and nothing else.
    pub fn noiseless() -> Self {
        Self {
            leak_rate_hz: 0.0,
            shot_noise_rate_hz: 0.0,
            hot_pixels: 0,
            ..Self::default()
        }
    }

    /// These pixels with their background activity scaled by `factor`: the leak and shot noise
    /// rates multiplied, the number of hot pixels multiplied and rounded (the camera's first hot
    /// pixels stay where they were, as they are drawn first). 0 gives [`Self::noiseless`]'s noise,
    /// 1 these pixels.
    pub fn with_noise_scaled(&self, factor: f64) -> Self {
        let factor = factor.max(0.0);
        Self {
            leak_rate_hz: self.leak_rate_hz * factor,
            shot_noise_rate_hz: self.shot_noise_rate_hz * factor,
            hot_pixels: (f64::from(self.hot_pixels) * factor).round() as u32,
            ..self.clone()
        }
    }
}

/// The IMU: gyroscope and accelerometer with the usual error terms.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImuParams {
    /// Sample rate (the DVXplorer's default 800 Hz).
    pub rate_hz: f64,
    /// Standard deviation of the per-trial gyroscope bias per axis, deg/s.
    pub gyro_bias_deg_s: f64,
    /// Standard deviation of the per-axis gyroscope scale error (relative).
    pub gyro_scale_error: f64,
    /// Standard deviation of the gyroscope's white noise per sample, deg/s.
    pub gyro_noise_deg_s: f64,
    /// The gyroscope bias's random walk (rate random walk), deg/s per square root of a second:
    /// the bias measured before onset drifts away during the trial.
    pub gyro_bias_walk_deg_s_per_sqrt_s: f64,
    /// Standard deviation of the per-trial offset between the IMU's timestamps and the events'
    /// clock, microseconds (positive: IMU stamps late).
    pub clock_offset_sd_us: f64,
    /// Standard deviation of each IMU timestamp's jitter, microseconds.
    pub clock_jitter_us: f64,
    /// Gyroscope resolution (one LSB), deg/s: 1000 dps full scale over 16 bits.
    pub gyro_lsb_deg_s: f64,
    /// Standard deviation of the per-trial accelerometer bias per axis, g.
    pub accel_bias_g: f64,
    /// Standard deviation of the accelerometer's white noise per sample, g.
    pub accel_noise_g: f64,
    /// Accelerometer resolution (one LSB), g: 4 g full scale over 16 bits.
    pub accel_lsb_g: f64,
    /// Temperature reported with every sample.
    pub temperature_c: f64,
    /// The IMU's mounting: rotation (row-major) from the IMU frame into the sensor frame,
    /// written to `calibration.json`. By default the IMU is turned 90 degrees about `z` against
    /// the camera, so that labels must apply the calibration to be right.
    pub imu_to_sensor: [[f64; 3]; 3],
}

impl Default for ImuParams {
    fn default() -> Self {
        Self {
            rate_hz: 800.0,
            gyro_bias_deg_s: 0.3,
            gyro_scale_error: 0.01,
            gyro_noise_deg_s: 0.05,
            gyro_bias_walk_deg_s_per_sqrt_s: 0.005,
            clock_offset_sd_us: 300.0,
            clock_jitter_us: 20.0,
            gyro_lsb_deg_s: 1000.0 / 32768.0,
            accel_bias_g: 0.005,
            accel_noise_g: 0.002,
            accel_lsb_g: 4.0 / 32768.0,
            temperature_c: 30.0,
            imu_to_sensor: [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }
}

/// The timing of a trial and the robot's motion profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TimelineParams {
    /// Time from the start of the recording to full indentation (a smooth cosine ramp from the
    /// approach gap to the trial's depth).
    pub indent_s: f64,
    /// Rest at full indentation before the tilt starts (the gyroscope's bias is visible here).
    pub settle_s: f64,
    /// Rest after the final tilt is reached, before the recording ends.
    pub hold_s: f64,
    /// The robot's angular acceleration at the start and end of every move, deg/s^2.
    pub accel_deg_s2: f64,
    /// Duration of Experiment 2's stop.
    pub stop_s: f64,
    /// Range of the commanded tilt at which Experiment 2 stops (uniformly drawn).
    pub stop_range_deg: [f64; 2],
    /// Commanded final tilt.
    pub total_deg: f64,
    /// Length of the `no_contact.aedat4` recording.
    pub no_contact_s: f64,
    /// Rate of the ground-truth CSV.
    pub truth_rate_hz: f64,
}

impl Default for TimelineParams {
    fn default() -> Self {
        Self {
            indent_s: 0.4,
            settle_s: 0.6,
            hold_s: 0.3,
            accel_deg_s2: 200.0,
            stop_s: 0.5,
            stop_range_deg: [4.0, 16.0],
            total_deg: 20.0,
            no_contact_s: 2.0,
            truth_rate_hz: 1000.0,
        }
    }
}

/// The ABB IRB 120's position repeatability (ISO 9283 RP), millimetres: its product
/// specification's figure. The paper's robot.
pub const IRB120_RP_MM: f64 = 0.01;

/// The lever from the robot's wrist to the sensor's tip, millimetres (assumed: the NeuroTac's
/// length plus its mount), over which a position error becomes a tilt error.
pub const WRIST_TO_TIP_MM: f64 = 150.0;

/// The rig's imperfections, drawn per trial ([`crate::rig::TrialErrors`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RigParams {
    /// Standard deviation of the tilt the robot reaches against the one commanded (each stop
    /// and the final tilt), degrees.
    pub angle_sd_deg: f64,
    /// Standard deviation of the plane's height against the commanded indentation, millimetres.
    pub plane_height_sd_mm: f64,
    /// Standard deviation of the robot's rotation centre from the dome's centre along the axis
    /// (a tool-centre-point calibration error), millimetres.
    pub rolling_centre_sd_mm: f64,
    /// Standard deviation of the contact patch's position on the dome per axis, millimetres
    /// along the surface.
    pub patch_offset_sd_mm: f64,
    /// Standard deviation of the sensor's turn about its axis each time it is seated in its
    /// mount (once per pass over the conditions, [`crate::rig::Seating`]), degrees.
    pub reseat_rotation_sd_deg: f64,
    /// Standard deviation of the sensor's tilt in its mount per seating, per axis, degrees.
    pub reseat_tilt_sd_deg: f64,
    /// Standard deviation of the sensor's reach (its length in the mount) per seating,
    /// millimetres.
    pub reseat_height_sd_mm: f64,
}

impl Default for RigParams {
    /// The robot's figures from the paper's robot's specification, not tuned to any result:
    /// the ABB IRB 120's position repeatability is 0.01 mm (ISO 9283 RP, which is about three
    /// standard deviations), so one standard deviation is 0.0033 mm of height, and over the
    /// ~150 mm from the wrist to the tip 0.0033 / 150 rad = 0.0013 deg of tilt (both rounded
    /// to two figures, as `docs/simulator.md` states them; the test `rig_from_the_irb120`
    /// checks the rounding against [`IRB120_RP_MM`] and [`WRIST_TO_TIP_MM`]).
    fn default() -> Self {
        Self {
            angle_sd_deg: 0.0013,
            plane_height_sd_mm: 0.0033,
            rolling_centre_sd_mm: 0.5,
            patch_offset_sd_mm: 0.02,
            // Assumed, not measured (no NeuroTac's mount is characterised): a sensor screwed
            // into a printed mount again sits within about a degree of its turn (0.5 SD),
            // a few tenths of a degree of its tilt (0.1 SD per axis), and a few hundredths of
            // a millimetre of its reach (0.02 SD).
            reseat_rotation_sd_deg: 0.5,
            reseat_tilt_sd_deg: 0.1,
            reseat_height_sd_mm: 0.02,
        }
    }
}

impl RigParams {
    /// A rig that does exactly what it is told (every error zero).
    pub fn perfect() -> Self {
        Self {
            angle_sd_deg: 0.0,
            plane_height_sd_mm: 0.0,
            rolling_centre_sd_mm: 0.0,
            patch_offset_sd_mm: 0.0,
            reseat_rotation_sd_deg: 0.0,
            reseat_tilt_sd_deg: 0.0,
            reseat_height_sd_mm: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn rig_from_the_irb120() {
        let sd_mm = IRB120_RP_MM / 3.0;
        let sd_deg = (sd_mm / WRIST_TO_TIP_MM).to_degrees();
        let rig = RigParams::default();
        let two_figures = |v: f64| {
            let scale = 10f64.powf(1.0 - v.log10().floor());
            (v * scale).round() / scale
        };
        assert_eq!(rig.plane_height_sd_mm, two_figures(sd_mm));
        assert_eq!(rig.angle_sd_deg, two_figures(sd_deg));
    }
    use super::*;

    #[test]
    fn pin_counts_follow_hexagonal_rings() {
        let mut s = SensorParams::default();
        assert_eq!(s.pin_count(), 331);
        s.rings = 6;
        assert_eq!(s.pin_count(), 127);
    }

    #[test]
    fn noise_scales_leak_shot_and_hot_pixels_together() {
        let d = DvsParams::default();
        assert_eq!(d.with_noise_scaled(1.0), d);
        assert_eq!(d.with_noise_scaled(0.0), DvsParams::noiseless());
        let x3 = d.with_noise_scaled(3.0);
        assert_eq!(x3.leak_rate_hz, 3.0 * d.leak_rate_hz);
        assert_eq!(x3.shot_noise_rate_hz, 3.0 * d.shot_noise_rate_hz);
        assert_eq!(x3.hot_pixels, 3 * d.hot_pixels);
        assert_eq!(x3.hot_pixel_rate_hz, d.hot_pixel_rate_hz);
        assert_eq!(x3.pos_thres, d.pos_thres);
    }

    #[test]
    fn json_round_trip_and_partial_files_take_defaults() {
        let p = SimParams::default();
        let text = serde_json::to_string(&p).unwrap();
        assert_eq!(serde_json::from_str::<SimParams>(&text).unwrap(), p);
        let partial: SimParams = serde_json::from_str(r#"{"dvs": {"pos_thres": 0.3}}"#).unwrap();
        assert_eq!(partial.dvs.pos_thres, 0.3);
        assert_eq!(partial.dvs.neg_thres, 0.2);
    }
}
