//! A trained model ready to use: the bundle, its predictor, and what its inputs are.
//!
//! Every consumer of a model bundle (`evtac evaluate` and `predict`, the experiments, online
//! estimation) loads this one type, so what a bundle means (which representation, on which
//! crop, with which mask) is decided in one place: [`crate::bundle`].

use std::path::{Path, PathBuf};

use evtac_repr::{FeatureProvenance, Mask, ReprConfig};

use crate::bundle::{self, ModelBundle, Representation};
use crate::predictor::{self, Predictor};

/// A model bundle loaded for prediction.
#[derive(Debug, Clone)]
pub struct Model {
    /// The folder it was loaded from (for messages).
    pub dir: PathBuf,
    /// The bundle: weights, config, mask and training curve.
    pub bundle: ModelBundle,
    /// The MLP, ready for inference.
    pub predictor: Predictor,
}

impl Model {
    /// Loads the bundle in `dir` (see [`ModelBundle::load`] for what is checked).
    pub fn load(dir: &Path) -> Result<Self, bundle::Error> {
        Self::from_bundle(dir, ModelBundle::load(dir)?)
    }

    /// A model from a bundle already in memory (`dir` only names it in messages).
    pub fn from_bundle(dir: &Path, bundle: ModelBundle) -> Result<Self, bundle::Error> {
        let predictor = bundle.predictor()?;
        Ok(Self {
            dir: dir.to_path_buf(),
            bundle,
            predictor,
        })
    }

    /// What the model's inputs are.
    pub fn representation(&self) -> &Representation {
        &self.bundle.config.representation
    }

    /// The representation config the features must be computed with.
    pub fn repr_config(&self) -> ReprConfig {
        self.bundle.config.representation.config
    }

    /// The no-contact mask the static representation was masked with, if any.
    pub fn mask(&self) -> Option<&Mask> {
        self.bundle.mask.as_ref()
    }

    /// What the features this model reads are made of: its representation, crop and mask.
    /// Features whose [`FeatureProvenance`] differs are refused by `evtac predict` and the
    /// Python `Model.predict`.
    pub fn feature_provenance(&self) -> FeatureProvenance {
        FeatureProvenance::new(
            &self.repr_config(),
            self.representation().frame,
            self.mask(),
        )
        .with_filters(self.representation().filters.clone())
    }

    /// Predictions (pitch, roll) for `features`, `N x 900` row-major.
    pub fn predict(&self, features: &[f32]) -> Result<Vec<[f32; 2]>, predictor::Error> {
        crate::flush_denormals();
        self.predictor.predict(features)
    }
}
