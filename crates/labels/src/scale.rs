//! Gyroscope scale calibration from the commanded motion.
//!
//! A MEMS gyroscope's scale factor is off by a few percent, and the error grows linearly with the
//! angle turned. The robot's commands fix what the true motion was, so one of them calibrates the
//! scale and the others stay free to validate it:
//!
//! - [`ScaleMethod::TotalRotation`] (the default): scale so that the rate integrated over the
//!   motion window equals the commanded total rotation (`theta` goes from 0 to `total_deg`).
//!   This also absorbs any bias left over, since at constant speed a bias error and a scale error
//!   both grow with time. Left for validation: the stop angle (Experiment 2).
//! - [`ScaleMethod::CommandedSpeed`]: scale so that the median rate over the motion window (the
//!   stop excluded) equals the commanded speed. Left for validation: the stop angle and the
//!   final angle.
//! - [`ScaleMethod::None`]: trust the gyroscope's datasheet scale.
//!
//! Either way the factor must stay within a tolerance of 1: a factor far from 1, or negative,
//! means the tilt direction or the extrinsics are wrong, not that the gyroscope is.

use serde::{Deserialize, Serialize};

/// Which commanded quantity calibrates the gyroscope's scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum ScaleMethod {
    /// Integrated rotation over the motion equals the commanded total rotation.
    #[default]
    TotalRotation,
    /// Median rate over the motion (stop excluded) equals the commanded speed.
    CommandedSpeed,
    /// No calibration: factor 1.
    None,
}

/// Why the scale could not be calibrated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ScaleError {
    /// The measured quantity is zero or not finite, so no factor maps it onto the command.
    #[error("measured {what} is {measured}: nothing to scale onto the commanded {commanded}")]
    Degenerate {
        /// What was measured ("rotation (deg)" or "speed (deg/s)").
        what: &'static str,
        /// The measured value.
        measured: f64,
        /// The commanded value.
        commanded: f64,
    },
    /// The factor is implausibly far from 1.
    #[error(
        "measured {what} {measured} against a commanded {commanded} gives scale {factor}, \
         outside 1 +- {tolerance}: check the tilt direction and the calibration's extrinsics"
    )]
    OutOfRange {
        /// What was measured.
        what: &'static str,
        /// The measured value.
        measured: f64,
        /// The commanded value.
        commanded: f64,
        /// The factor `commanded / measured`.
        factor: f64,
        /// The largest accepted `|factor - 1|`.
        tolerance: f64,
    },
}

/// The factor that maps the measured onto the commanded quantity: `commanded / measured`,
/// checked to lie within `1 +- tolerance`. `what` names the quantity in errors.
pub fn factor(
    what: &'static str,
    measured: f64,
    commanded: f64,
    tolerance: f64,
) -> Result<f64, ScaleError> {
    if measured == 0.0 || !measured.is_finite() || !commanded.is_finite() {
        return Err(ScaleError::Degenerate {
            what,
            measured,
            commanded,
        });
    }
    let factor = commanded / measured;
    // A NaN factor or tolerance fails too.
    let within = (factor - 1.0).abs() <= tolerance;
    if !within {
        return Err(ScaleError::OutOfRange {
            what,
            measured,
            commanded,
            factor,
            tolerance,
        });
    }
    Ok(factor)
}

/// The median of `values` (the mean of the middle two for an even count), `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_measured_onto_commanded() {
        let f = factor("rotation (deg)", 19.2, 20.0, 0.25).unwrap();
        assert!((f * 19.2 - 20.0).abs() < 1e-12);
    }

    #[test]
    fn refuses_implausible_factors() {
        // A wrong direction turns the measured rotation negative.
        let err = factor("rotation (deg)", -20.0, 20.0, 0.25).unwrap_err();
        assert!(matches!(err, ScaleError::OutOfRange { factor, .. } if factor == -1.0));
        assert!(
            err.to_string().contains("check the tilt direction"),
            "{err}"
        );
        assert!(matches!(
            factor("speed (deg/s)", 0.0, 4.0, 0.25),
            Err(ScaleError::Degenerate { .. })
        ));
        assert!(matches!(
            factor("speed (deg/s)", f64::NAN, 4.0, 0.25),
            Err(ScaleError::Degenerate { .. })
        ));
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
