//! Training data in memory: feature rows and their (pitch, roll) labels, and the seeded
//! mini-batch order.

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

use crate::model::{INPUTS, MAX_INPUTS, OUTPUTS};

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The feature buffer is not a whole number of rows.
    #[error("{len} feature values is not a multiple of {width} (one row per sample)")]
    RaggedFeatures {
        /// Number of feature values.
        len: usize,
        /// Features per row.
        width: usize,
    },
    /// The row width is not a whole number of pooled frames (900 each), 1 to 8 of them.
    #[error(
        "{width} features per sample: evtac's networks read a multiple of {INPUTS} (one per \
         pooled frame or channel), at most {MAX_INPUTS}"
    )]
    Width {
        /// Features per row given.
        width: usize,
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

/// Samples for training or evaluation: `features` holds `N x width` f32 row-major (900 per
/// pooled frame: 900, or 1800 for the stacked and late representations), `labels` `N x 2`
/// (pitch, roll) in degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureSet {
    /// Feature rows, `N * width` values.
    pub features: Vec<f32>,
    /// Labels, `N * 2` values: pitch then roll of each sample.
    pub labels: Vec<f32>,
    /// Features per sample.
    pub width: usize,
}

impl Default for FeatureSet {
    /// An empty set of one-frame (900-feature) rows.
    fn default() -> Self {
        Self::empty(INPUTS)
    }
}

impl FeatureSet {
    /// A set of 900-feature rows from its two buffers, checked with [`FeatureSet::validate`].
    pub fn new(features: Vec<f32>, labels: Vec<f32>) -> Result<Self, Error> {
        Self::with_width(features, labels, INPUTS)
    }

    /// A set of `width`-feature rows from its two buffers, checked with
    /// [`FeatureSet::validate`].
    pub fn with_width(features: Vec<f32>, labels: Vec<f32>, width: usize) -> Result<Self, Error> {
        let set = Self {
            features,
            labels,
            width,
        };
        set.validate()?;
        Ok(set)
    }

    /// An empty set of `width`-feature rows.
    pub fn empty(width: usize) -> Self {
        Self {
            features: Vec::new(),
            labels: Vec::new(),
            width,
        }
    }

    /// Number of samples (feature rows).
    pub fn len(&self) -> usize {
        self.features.len() / self.width.max(1)
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.features.is_empty()
    }

    /// The features of sample `i` (`width` values). Panics when `i >= len()`.
    pub fn row(&self, i: usize) -> &[f32] {
        &self.features[i * self.width..(i + 1) * self.width]
    }

    /// Checks the width, the row structure and that every value is finite.
    pub fn validate(&self) -> Result<(), Error> {
        if self.width == 0 || !self.width.is_multiple_of(INPUTS) || self.width > MAX_INPUTS {
            return Err(Error::Width { width: self.width });
        }
        if !self.features.len().is_multiple_of(self.width) {
            return Err(Error::RaggedFeatures {
                len: self.features.len(),
                width: self.width,
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
                sample: i / self.width,
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
            Err(Error::RaggedFeatures { len: 901, .. })
        ));
        assert!(matches!(
            FeatureSet::with_width(vec![0.0; 10], vec![], 10),
            Err(Error::Width { width: 10 })
        ));
        let two_frames = FeatureSet::with_width(vec![0.0; 3600], vec![0.0; 4], 1800).unwrap();
        assert_eq!((two_frames.len(), two_frames.row(1).len()), (2, 1800));
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
