//! The simulator parameters the sensitivity study varies, as data: each one's name, what it is
//! and the fields of `simulator.json` it scales. Its own file so that the study's error type
//! ([`crate::error::PerturbError`], which names them) and the study that scales them share the
//! table without importing each other.

use evtac_sim::SimParams;

/// One simulator parameter the study varies: one or more fields of [`SimParams`] scaled
/// together.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parameter {
    /// Short name, also the point's folder (`points/<name>/`).
    pub name: &'static str,
    /// What it is, for the table.
    pub what: &'static str,
    /// The fields, as `section.field` of `simulator.json`.
    pub fields: &'static [&'static str],
}

/// Every parameter of the simulator that no measurement of a NeuroTac sets, in the order of
/// `simulator.json`. The rest are either the paper's (tip radius, the protocol's speeds, depths
/// and timeline, the camera's resolution), the rig's specification (the IRB 120's
/// repeatability), or only shape the image without a physical meaning of their own
/// (brightness, vignetting; the pins' count and size are varied instead).
pub const PARAMETERS: [Parameter; 19] = [
    Parameter {
        name: "pin_rings",
        what: "rings of pins (pin spacing: more rings, closer pins)",
        fields: &["sensor.rings"],
    },
    Parameter {
        name: "pin_size",
        what: "radius of a pin's bright tip",
        fields: &["sensor.pin_sigma_mm"],
    },
    Parameter {
        name: "normal_gain",
        what: "contact: pin motion along the normal per mm of penetration",
        fields: &["contact.normal_gain"],
    },
    Parameter {
        name: "spread_gain",
        what: "contact: lateral spread of pins per mm of penetration",
        fields: &["contact.spread_gain"],
    },
    Parameter {
        name: "skin_tau",
        what: "skin's time constant (viscoelastic lag)",
        fields: &["contact.skin_tau_s"],
    },
    Parameter {
        name: "shear",
        what: "shear of the stuck patch per degree of lag",
        fields: &["contact.shear_mm_per_deg"],
    },
    Parameter {
        name: "trial_variation",
        what: "per-trial spread of the skin's gains",
        fields: &["contact.trial_variation"],
    },
    Parameter {
        name: "creep",
        what: "share of the skin's slow (creep) response",
        fields: &["contact.creep_fraction"],
    },
    Parameter {
        name: "on_threshold",
        what: "DVS ON threshold (log intensity)",
        fields: &["dvs.pos_thres"],
    },
    Parameter {
        name: "off_threshold",
        what: "DVS OFF threshold (log intensity)",
        fields: &["dvs.neg_thres"],
    },
    Parameter {
        name: "threshold_mismatch",
        what: "DVS thresholds' pixel-to-pixel spread",
        fields: &["dvs.sigma_thres"],
    },
    Parameter {
        name: "cutoff",
        what: "DVS photoreceptor cutoff frequency",
        fields: &["dvs.cutoff_hz"],
    },
    Parameter {
        name: "refractory",
        what: "DVS refractory period",
        fields: &["dvs.refractory_period_s"],
    },
    Parameter {
        name: "leak_rate",
        what: "DVS leak event rate",
        fields: &["dvs.leak_rate_hz"],
    },
    Parameter {
        name: "shot_noise",
        what: "DVS shot-noise event rate",
        fields: &["dvs.shot_noise_rate_hz"],
    },
    Parameter {
        name: "hot_pixels",
        what: "number of hot pixels",
        fields: &["dvs.hot_pixels"],
    },
    Parameter {
        name: "imu_noise",
        what: "IMU's gyroscope and accelerometer white noise",
        fields: &["imu.gyro_noise_deg_s", "imu.accel_noise_g"],
    },
    Parameter {
        name: "rig_calibration",
        what: "rig: the rolling centre's and the contact patch's offsets (tool-centre calibration)",
        fields: &["rig.rolling_centre_sd_mm", "rig.patch_offset_sd_mm"],
    },
    Parameter {
        name: "seating",
        what: "rig: the sensor's turn, tilt and reach each time it is seated in its mount",
        fields: &[
            "rig.reseat_rotation_sd_deg",
            "rig.reseat_tilt_sd_deg",
            "rig.reseat_height_sd_mm",
        ],
    },
];

/// The parameter named `name`.
pub fn parameter(name: &str) -> Option<Parameter> {
    PARAMETERS.iter().copied().find(|p| p.name == name)
}

/// Every parameter's name, comma-separated (for messages).
pub fn names() -> String {
    PARAMETERS.map(|p| p.name).join(", ")
}

/// A number of [`SimParams`] that a parameter scales.
pub(crate) enum Slot<'a> {
    /// A real number.
    Real(&'a mut f64),
    /// A count (pin rings, hot pixels): rounded to the nearest when scaled.
    Count(&'a mut u32),
}

/// The number `field` (`section.field`, as `simulator.json` names it) is in `params`, for the
/// fields of [`PARAMETERS`]; `None` for any other. Typed fields rather than `simulator.json`'s
/// untyped tree: the study's tests check, through that tree, that each parameter scales exactly
/// the fields it names, so a name here cannot drift from `simulator.json`'s.
pub(crate) fn slot<'a>(params: &'a mut SimParams, field: &str) -> Option<Slot<'a>> {
    use Slot::{Count, Real};
    Some(match field {
        "sensor.rings" => Count(&mut params.sensor.rings),
        "sensor.pin_sigma_mm" => Real(&mut params.sensor.pin_sigma_mm),
        "contact.normal_gain" => Real(&mut params.contact.normal_gain),
        "contact.spread_gain" => Real(&mut params.contact.spread_gain),
        "contact.skin_tau_s" => Real(&mut params.contact.skin_tau_s),
        "contact.shear_mm_per_deg" => Real(&mut params.contact.shear_mm_per_deg),
        "contact.trial_variation" => Real(&mut params.contact.trial_variation),
        "contact.creep_fraction" => Real(&mut params.contact.creep_fraction),
        "dvs.pos_thres" => Real(&mut params.dvs.pos_thres),
        "dvs.neg_thres" => Real(&mut params.dvs.neg_thres),
        "dvs.sigma_thres" => Real(&mut params.dvs.sigma_thres),
        "dvs.cutoff_hz" => Real(&mut params.dvs.cutoff_hz),
        "dvs.refractory_period_s" => Real(&mut params.dvs.refractory_period_s),
        "dvs.leak_rate_hz" => Real(&mut params.dvs.leak_rate_hz),
        "dvs.shot_noise_rate_hz" => Real(&mut params.dvs.shot_noise_rate_hz),
        "dvs.hot_pixels" => Count(&mut params.dvs.hot_pixels),
        "imu.gyro_noise_deg_s" => Real(&mut params.imu.gyro_noise_deg_s),
        "imu.accel_noise_g" => Real(&mut params.imu.accel_noise_g),
        "rig.rolling_centre_sd_mm" => Real(&mut params.rig.rolling_centre_sd_mm),
        "rig.patch_offset_sd_mm" => Real(&mut params.rig.patch_offset_sd_mm),
        "rig.reseat_rotation_sd_deg" => Real(&mut params.rig.reseat_rotation_sd_deg),
        "rig.reseat_tilt_sd_deg" => Real(&mut params.rig.reseat_tilt_sd_deg),
        "rig.reseat_height_sd_mm" => Real(&mut params.rig.reseat_height_sd_mm),
        _ => return None,
    })
}
