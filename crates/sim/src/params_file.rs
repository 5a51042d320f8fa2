//! A simulator parameter file read back (`evtac simulate --params`, or what `evtac stats
//! --sim-params` wrote): JSON of [`SimParams`], missing fields taking their defaults.
//!
//! A file that would simulate something other than what it says is refused rather than
//! half-used: a misspelt field (the default would silently stand in for it), a value of the
//! wrong type, or a noise, IMU or camera value outside what the model can draw from. Each error
//! names the file and the field (`dvs.leak_rate_hz`).

use std::path::{Path, PathBuf};

use crate::params::SimParams;

/// A parameter file that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ParamsError {
    /// The file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not JSON of the parameters (a misspelt field, a wrong type).
    #[error("{}: field `{field}`: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// The field's path (`dvs.leak_rate_hz`), `.` for the whole file.
        field: String,
        /// What is wrong, with the line and column.
        message: String,
    },
    /// A value the model cannot use.
    #[error("{}: field `{field}` = {value}: {limit}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The field's path.
        field: &'static str,
        /// The value found.
        value: String,
        /// The limit it breaks.
        limit: &'static str,
    },
}

/// Reads the parameter file at `path` and checks its values.
pub fn read_params(path: &Path) -> Result<SimParams, ParamsError> {
    let text = std::fs::read_to_string(path).map_err(|source| ParamsError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_params(&text, path)
}

/// Parses `text` as the parameter file `path` (for its messages) and checks its values.
pub fn parse_params(text: &str, path: &Path) -> Result<SimParams, ParamsError> {
    let de = &mut serde_json::Deserializer::from_str(text);
    let params: SimParams =
        serde_path_to_error::deserialize(de).map_err(|e| ParamsError::Parse {
            path: path.to_path_buf(),
            // serde_path_to_error names the top level `?` (or `.`) when nothing was entered yet.
            field: match e.path().to_string() {
                root if root == "?" => ".".to_string(),
                field => field,
            },
            message: e.inner().to_string(),
        })?;
    check(&params).map_err(|(field, value, limit)| ParamsError::Invalid {
        path: path.to_path_buf(),
        field,
        value,
        limit,
    })?;
    Ok(params)
}

/// The first value of `p` the model cannot use: (field, value, limit). Covers the values
/// `evtac stats` measures and the sizes everything else depends on; the contact model's gains
/// are free.
fn check(p: &SimParams) -> Result<(), (&'static str, String, &'static str)> {
    let non_negative: [(&'static str, f64); 10] = [
        ("dvs.leak_rate_hz", p.dvs.leak_rate_hz),
        ("dvs.shot_noise_rate_hz", p.dvs.shot_noise_rate_hz),
        ("dvs.hot_pixel_rate_hz[0]", p.dvs.hot_pixel_rate_hz[0]),
        ("imu.gyro_bias_deg_s", p.imu.gyro_bias_deg_s),
        ("imu.gyro_scale_error", p.imu.gyro_scale_error),
        ("imu.gyro_noise_deg_s", p.imu.gyro_noise_deg_s),
        ("imu.gyro_lsb_deg_s", p.imu.gyro_lsb_deg_s),
        ("imu.accel_bias_g", p.imu.accel_bias_g),
        ("imu.accel_noise_g", p.imu.accel_noise_g),
        ("imu.accel_lsb_g", p.imu.accel_lsb_g),
    ];
    for (field, v) in non_negative {
        if !(v.is_finite() && v >= 0.0) {
            return Err((field, v.to_string(), "must be finite and at least 0"));
        }
    }
    let [lo, hi] = p.dvs.hot_pixel_rate_hz;
    if !(hi.is_finite() && hi >= lo) {
        return Err((
            "dvs.hot_pixel_rate_hz[1]",
            hi.to_string(),
            "must be finite and at least the lowest rate (dvs.hot_pixel_rate_hz[0])",
        ));
    }
    let rate = p.imu.rate_hz;
    if !(rate.is_finite() && rate >= 1.0) {
        return Err((
            "imu.rate_hz",
            rate.to_string(),
            "must be finite and at least 1 Hz",
        ));
    }
    for (field, v) in [
        ("camera.width", p.camera.width),
        ("camera.height", p.camera.height),
    ] {
        if v == 0 {
            return Err((field, v.to_string(), "must be at least 1 pixel"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<SimParams, ParamsError> {
        parse_params(text, Path::new("p.json"))
    }

    #[test]
    fn a_partial_file_takes_the_defaults() {
        let p = parse(r#"{"dvs": {"leak_rate_hz": 0.5}}"#).unwrap();
        assert_eq!(p.dvs.leak_rate_hz, 0.5);
        assert_eq!(p.imu, SimParams::default().imu);
    }

    #[test]
    fn bad_files_name_the_file_and_the_field() {
        let err = |text: &str| parse(text).unwrap_err().to_string();
        let typo = err(r#"{"dvs": {"leak_rate": 0.5}}"#);
        assert!(
            typo.starts_with("p.json: field `dvs.leak_rate`: unknown field `leak_rate`"),
            "{typo}"
        );
        let wrong = err(r#"{"imu": {"gyro_noise_deg_s": "high"}}"#);
        assert!(
            wrong.starts_with("p.json: field `imu.gyro_noise_deg_s`: invalid type"),
            "{wrong}"
        );
        let negative = err(r#"{"dvs": {"shot_noise_rate_hz": -1}}"#);
        assert_eq!(
            negative,
            "p.json: field `dvs.shot_noise_rate_hz` = -1: must be finite and at least 0"
        );
        let range = err(r#"{"dvs": {"hot_pixel_rate_hz": [50, 10]}}"#);
        assert!(
            range.contains("field `dvs.hot_pixel_rate_hz[1]` = 10"),
            "{range}"
        );
        let not_json = err("{");
        assert!(not_json.starts_with("p.json: field `.`: EOF"), "{not_json}");
    }
}
