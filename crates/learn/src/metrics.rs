//! Mean absolute errors of (pitch, roll) predictions, as the paper reports them.

use serde::{Deserialize, Serialize};

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Predictions and labels do not describe the same number of samples.
    #[error("{predictions} predictions for {labels} labels")]
    LengthMismatch {
        /// Number of predictions.
        predictions: usize,
        /// Number of label pairs.
        labels: usize,
    },
    /// There is nothing to average.
    #[error("no samples: the mean absolute error is undefined")]
    Empty,
}

/// Mean absolute error in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mae {
    /// Mean of the pitch and roll MAEs: evtac's reading of the paper's "overall" (not defined
    /// there; its table's overall values are the means of its pitch and roll ones, to rounding).
    pub overall: f64,
    /// Pitch MAE.
    pub pitch: f64,
    /// Roll MAE.
    pub roll: f64,
}

/// MAE of `predictions` (one `[pitch, roll]` per sample) against `labels` (flat, `N x 2`,
/// pitch then roll), accumulated in f64.
///
/// ```
/// let m = evtac_learn::metrics::mae(&[[1.0, 2.0], [3.0, 5.0]], &[0.0, 0.0, 3.0, 1.0]).unwrap();
/// assert_eq!((m.pitch, m.roll, m.overall), (0.5, 3.0, 1.75));
/// ```
pub fn mae(predictions: &[[f32; 2]], labels: &[f32]) -> Result<Mae, Error> {
    if labels.len() != predictions.len() * 2 {
        return Err(Error::LengthMismatch {
            predictions: predictions.len(),
            labels: labels.len() / 2,
        });
    }
    if predictions.is_empty() {
        return Err(Error::Empty);
    }
    let (mut pitch, mut roll) = (0.0_f64, 0.0_f64);
    for (p, l) in predictions.iter().zip(labels.chunks_exact(2)) {
        pitch += (f64::from(p[0]) - f64::from(l[0])).abs();
        roll += (f64::from(p[1]) - f64::from(l[1])).abs();
    }
    let n = predictions.len() as f64;
    let (pitch, roll) = (pitch / n, roll / n);
    Ok(Mae {
        overall: 0.5 * (pitch + roll),
        pitch,
        roll,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_mismatched_and_empty_inputs() {
        assert!(matches!(
            mae(&[[0.0, 0.0]], &[0.0]),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(mae(&[], &[]), Err(Error::Empty)));
    }
}
