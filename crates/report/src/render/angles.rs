//! The angles panel's data: a trained model's pitch and roll estimates over the rendered span,
//! and beside them the trial's IMU labels and the simulator's truth when there are some.
//!
//! The estimates are the offline prediction's: the features come from a
//! [`FeatureExtractor`] with the model's representation and mask, sampled at the estimate
//! times as the feature cache samples a trial, and go through [`Model::predict`], as
//! `evtac predict` sends a features file, so an estimate here equals `evtac predict`'s on the
//! features `evtac represent` writes at the same time.

use super::Error;
use super::frames::Timing;
use evtac_events::Event;
use evtac_labels::series::LabelSeries;
use evtac_learn::Model;
use evtac_repr::{CROP, FeatureExtractor, ReprKind};

/// The longest time between two estimates: frame intervals are divided so that the curve
/// shows the motion between frames (a 200 ms frame would draw it as a few straight lines).
const MAX_STEP_US: i64 = 10_000;

/// Rows predicted at once: the features of a long recording are never all in memory.
const BATCH: usize = 1024;

/// Estimated and reference angles at the same times, for the angles panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Angles {
    /// The times, microseconds, increasing; every frame's end is one of them.
    pub t_us: Vec<i64>,
    /// The model's (pitch, roll) at each time, degrees.
    pub estimates: Vec<[f32; 2]>,
    /// The trial's IMU labels (pitch, roll) at each time, degrees, for a dataset trial.
    pub labels: Option<Vec<[f64; 2]>>,
    /// The simulator's true (pitch, roll) at each time, degrees, when the dataset has them.
    pub truth: Option<Vec<[f64; 2]>>,
    /// The model's representation, naming its curve.
    pub model_repr: ReprKind,
}

impl Angles {
    /// The estimates of `model` on `events` (cropped to [`CROP`], time order) at
    /// [`estimate_times`] of `timing`, without references.
    pub fn estimate(events: &[Event], model: &Model, timing: &Timing) -> Result<Angles, Error> {
        let t_us = estimate_times(timing);
        let config = model.repr_config();
        let mut fx = FeatureExtractor::new_with_masks(&[config], CROP, &[model.mask()])?;
        let mut estimates = Vec::with_capacity(t_us.len());
        let width = model.predictor.inputs();
        let mut batch: Vec<f32> = Vec::with_capacity(BATCH * width);
        let mut failed = None;
        let mut flush = |batch: &mut Vec<f32>, estimates: &mut Vec<[f32; 2]>| {
            match model.predict(batch) {
                Ok(rows) => estimates.extend(rows),
                Err(e) => {
                    failed.get_or_insert(Error::Predict {
                        model: model.dir.clone(),
                        message: e.to_string(),
                    });
                }
            }
            batch.clear();
        };
        fx.run(events, &t_us, |_, fx| {
            batch.extend_from_slice(fx.features(0));
            if batch.len() == BATCH * width {
                flush(&mut batch, &mut estimates);
            }
        })?;
        if !batch.is_empty() {
            flush(&mut batch, &mut estimates);
        }
        if let Some(e) = failed {
            return Err(e);
        }
        Ok(Angles {
            t_us,
            estimates,
            labels: None,
            truth: None,
            model_repr: config.kind(),
        })
    }

    /// `series` (IMU labels or truth) at these times, interpolated as the training labels are.
    pub fn sample(&self, series: &LabelSeries) -> Vec<[f64; 2]> {
        self.t_us
            .iter()
            .map(|&t| {
                let (pitch, roll) = series.at(t);
                [pitch, roll]
            })
            .collect()
    }

    /// The estimates as CSV: `t_us,pitch_deg,roll_deg`, one row per time, the floats printed
    /// as Rust prints an `f32` (the shortest text that reads back to the same value).
    pub fn estimates_csv(&self) -> String {
        let mut text = String::from("t_us,pitch_deg,roll_deg\n");
        for (t, [p, r]) in self.t_us.iter().zip(&self.estimates) {
            text.push_str(&format!("{t},{p},{r}\n"));
        }
        text
    }
}

/// The estimate times of `timing`: each frame interval divided into the fewest equal steps of
/// at most 10 ms, the last of them at the frame's end (so the cursor sits on an estimate).
pub fn estimate_times(timing: &Timing) -> Vec<i64> {
    let parts = ((timing.step_us + MAX_STEP_US - 1) / MAX_STEP_US).max(1);
    (0..timing.count)
        .flat_map(|k| {
            let start = timing.end_us(k) - timing.step_us;
            (1..=parts).map(move |j| start + j * timing.step_us / parts)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ends_are_estimate_times_at_most_10_ms_apart() {
        let timing = Timing {
            start_us: 1_000,
            step_us: 25_000,
            count: 3,
            fps: 40.0,
            speed: 1.0,
        };
        let t = estimate_times(&timing);
        assert_eq!(t.len(), 9);
        for k in 0..3 {
            assert_eq!(t[3 * k + 2], timing.end_us(k));
        }
        assert!(
            t.windows(2)
                .all(|w| w[1] > w[0] && w[1] - w[0] <= MAX_STEP_US)
        );
        assert_eq!(t[0], 1_000 + 25_000 / 3);
    }
}
