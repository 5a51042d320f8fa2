//! [`StreamingPredictor`]: one estimate after another from a stream of pooled features, with the
//! first layer updated from the cells that changed.
//!
//! Between two estimates a millisecond apart only a few of the 900 pooled cells change (a median
//! of 50-85 at 3 M events/s in the online latency benchmark's stream, 12-22 at 300 k).
//! Recomputing the first layer reads all of its 0.9 MB of weights, which costs more than the
//! rest of the forward pass and, worse, pushes the representation's state out of the cache for
//! the next millisecond's events. The exact fixed-point first layer ([`crate::cell_layer`])
//! makes an update from the changed cells give the same bits as a fresh sum, so a
//! [`StreamingPredictor`] returns exactly what [`Predictor::predict_one`] does for the same
//! features, touching about 1 KB of weights per changed cell.

use crate::cell_layer::CellSums;
use crate::predictor::Predictor;

/// A [`Predictor`] for a sequence of samples: the same results as
/// [`Predictor::predict_one`] on each, faster when consecutive samples differ in few cells.
///
/// ```
/// use evtac_learn::{Parameters, Predictor, StreamingPredictor};
/// let predictor = Predictor::new(&Parameters::init(0)).unwrap();
/// let mut stream = StreamingPredictor::new(predictor.clone());
/// let mut features = [0.0_f32; 900];
/// for step in 0..10 {
///     features[step * 7] = 3.0 / 64.0; // one cell changes per sample
///     assert_eq!(stream.predict(&features), predictor.predict_one(&features));
/// }
/// ```
#[derive(Debug, Clone)]
pub struct StreamingPredictor {
    predictor: Predictor,
    state: CellSums,
}

impl StreamingPredictor {
    /// A stream starting from all-zero features.
    pub fn new(predictor: Predictor) -> Self {
        Self {
            predictor,
            state: CellSums::new(),
        }
    }

    /// The predictor behind the stream.
    pub fn predictor(&self) -> &Predictor {
        &self.predictor
    }

    /// (pitch, roll) in degrees for the next sample: bit for bit
    /// [`Predictor::predict_one`]`(features)`. Allocation-free. Features that are not pooled
    /// (a value off the 1/64 grid) take the float32 path and leave the stream's state as it
    /// was.
    ///
    /// # Panics
    /// When `features.len() != 900`, as [`Predictor::predict_one`].
    pub fn predict(&mut self, features: &[f32]) -> [f32; 2] {
        self.predictor.predict_streaming(&mut self.state, features)
    }

    /// Back to all-zero features (the next sample is summed from scratch).
    pub fn reset(&mut self) {
        self.state = CellSums::new();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Parameters;
    use crate::model::{Architecture, MAX_INPUTS};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Any sequence of samples, pooled or not, gives what the predictor gives each alone,
        /// for each network (the two-frame ones read 1800 cells, the widest `MAX_INPUTS`).
        #[test]
        fn a_stream_predicts_what_each_sample_alone_does(
            seed in 0u64..4,
            architecture in prop_oneof![
                Just(Architecture::Mlp),
                Just(Architecture::Stacked),
                Just(Architecture::Late),
                Just(Architecture::Channels(3)),
                Just(Architecture::Channels(MAX_INPUTS / crate::model::INPUTS)),
            ],
            steps in proptest::collection::vec(
                (proptest::collection::vec((0usize..MAX_INPUTS, 0u8..=64), 0..120), any::<bool>()),
                1..12,
            ),
        ) {
            let params = Parameters::init_for(architecture, seed);
            let predictor = Predictor::new(&params).expect("valid");
            let mut stream = StreamingPredictor::new(predictor.clone());
            let inputs = architecture.inputs();
            let mut features = vec![0.0_f32; inputs];
            for (changes, off_grid) in steps {
                for (cell, count) in changes {
                    features[cell % inputs] = f32::from(count) / 64.0;
                }
                let mut sample = features.clone();
                if off_grid {
                    sample[0] = 0.3;
                }
                prop_assert_eq!(stream.predict(&sample), predictor.predict_one(&sample));
            }
            stream.reset();
            prop_assert_eq!(stream.predict(&features), predictor.predict_one(&features));
        }
    }
}
