//! Training data in memory: feature rows and their (pitch, roll) labels, and the seeded
//! mini-batch order.

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

use crate::model::{INPUTS, OUTPUTS};

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The feature buffer is not a whole number of 900-value rows.
    #[error("{len} feature values is not a multiple of {INPUTS} (one row per sample)")]
    RaggedFeatures {
        /// Number of feature values.
        len: usize,
    },
    /// Labels and features describe different sample counts.
    #[error("{features} feature rows but {labels} label values (expected {expected}: 2 per row)")]
    LabelCount {
        /// Number of feature rows.
        features: usize,
        /// Number of label values.
        labels: usize,
        /// Number of label values expected.
        expected: usize,
    },
    /// A feature or label is NaN or infinite.
    #[error("{what} of sample {sample} is not finite")]
    NonFinite {
        /// `"features"` or `"labels"`.
        what: &'static str,
        /// Sample (row) index.
        sample: usize,
    },
}

/// Samples for training or evaluation: `features` holds `N x 900` f32 row-major, `labels`
/// `N x 2` (pitch, roll) in degrees.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FeatureSet {
    /// Feature rows, `N * 900` values.
    pub features: Vec<f32>,
    /// Labels, `N * 2` values: pitch then roll of each sample.
    pub labels: Vec<f32>,
}

impl FeatureSet {
    /// A set from its two buffers, checked with [`FeatureSet::validate`].
    pub fn new(features: Vec<f32>, labels: Vec<f32>) -> Result<Self, Error> {
        let set = Self { features, labels };
        set.validate()?;
        Ok(set)
    }

    /// Number of samples (feature rows).
    pub fn len(&self) -> usize {
        self.features.len() / INPUTS
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.features.is_empty()
    }

    /// The features of sample `i` (900 values). Panics when `i >= len()`.
    pub fn row(&self, i: usize) -> &[f32] {
        &self.features[i * INPUTS..(i + 1) * INPUTS]
    }

    /// Checks the row structure and that every value is finite.
    pub fn validate(&self) -> Result<(), Error> {
        if !self.features.len().is_multiple_of(INPUTS) {
            return Err(Error::RaggedFeatures {
                len: self.features.len(),
            });
        }
        let n = self.len();
        if self.labels.len() != n * OUTPUTS {
            return Err(Error::LabelCount {
                features: n,
                labels: self.labels.len(),
                expected: n * OUTPUTS,
            });
        }
        if let Some(i) = self.features.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "features",
                sample: i / INPUTS,
            });
        }
        if let Some(i) = self.labels.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "labels",
                sample: i / OUTPUTS,
            });
        }
        Ok(())
    }

    /// Copies the rows `indices` into `features` / `labels` (cleared first): one mini-batch.
    pub fn gather(&self, indices: &[usize], features: &mut Vec<f32>, labels: &mut Vec<f32>) {
        features.clear();
        labels.clear();
        for &i in indices {
            features.extend_from_slice(self.row(i));
            labels.extend_from_slice(&self.labels[i * OUTPUTS..(i + 1) * OUTPUTS]);
        }
    }
}

/// The sample order of every epoch: a fresh permutation of `0..n` per epoch from one
/// `ChaCha8Rng` seeded once, as PyTorch's `DataLoader(shuffle=True)` does with its generator.
#[derive(Debug, Clone)]
pub struct Shuffler {
    rng: ChaCha8Rng,
    order: Vec<usize>,
}

impl Shuffler {
    /// A shuffler over `n` samples seeded with `seed`.
    pub fn new(n: usize, seed: u64) -> Self {
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
            order: (0..n).collect(),
        }
    }

    /// The next epoch's order (reshuffled from the previous one).
    pub fn next_epoch(&mut self) -> &[usize] {
        self.order.shuffle(&mut self.rng);
        &self.order
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_problem() {
        assert!(matches!(
            FeatureSet::new(vec![0.0; 901], vec![]),
            Err(Error::RaggedFeatures { len: 901 })
        ));
        assert!(matches!(
            FeatureSet::new(vec![0.0; 900], vec![0.0]),
            Err(Error::LabelCount { expected: 2, .. })
        ));
        let mut f = vec![0.0; 1800];
        f[1000] = f32::NAN;
        assert!(matches!(
            FeatureSet::new(f, vec![0.0; 4]),
            Err(Error::NonFinite {
                what: "features",
                sample: 1
            })
        ));
    }

    #[test]
    fn shuffles_are_seeded_permutations() {
        let a: Vec<Vec<usize>> = {
            let mut s = Shuffler::new(50, 7);
            (0..3).map(|_| s.next_epoch().to_vec()).collect()
        };
        let mut s = Shuffler::new(50, 7);
        for epoch in &a {
            assert_eq!(s.next_epoch(), epoch.as_slice());
            let mut sorted = epoch.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..50).collect::<Vec<_>>());
        }
        assert_ne!(a[0], a[1]);
        assert_ne!(Shuffler::new(50, 8).next_epoch(), a[0].as_slice());
    }
}
