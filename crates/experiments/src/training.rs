//! One training job: the features of a dataset's train and validation splits under one
//! representation config (from the cache), `evtac_learn::train`, and a saved model bundle with a
//! `done` marker. `evtac train` and `evtac reproduce` both run exactly this.

use crate::cache::{self, FeatureCache, LoadedSet};
use crate::dataset::{self, FRAME};
use crate::results::Mae;
use crate::sampling::{Phase, Sampling};
use crate::splits::{Split, Splits};
use evtac_learn::{EpochRecord, ModelBundle, Predictor, TrainConfig};
use evtac_repr::ReprConfig;
use ndarray::Array2;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Errors of a training or evaluation job.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Features or labels could not be produced.
    #[error(transparent)]
    Cache(#[from] cache::Error),
    /// The dataset could not be read.
    #[error(transparent)]
    Dataset(#[from] dataset::Error),
    /// Training failed.
    #[error("training {out}: {source}")]
    Train {
        /// The model folder.
        out: PathBuf,
        /// The cause.
        source: evtac_learn::training::Error,
    },
    /// The bundle could not be saved or loaded.
    #[error(transparent)]
    Bundle(#[from] evtac_learn::bundle::Error),
    /// Prediction failed.
    #[error("predicting with {model}: {source}")]
    Predict {
        /// The model folder.
        model: PathBuf,
        /// The cause.
        source: evtac_learn::predictor::Error,
    },
    /// The bundle's representation is not a representation config.
    #[error("{model}: the bundle's `representation` is not an evtac representation: {source}")]
    Representation {
        /// The model folder.
        model: PathBuf,
        /// The cause.
        source: serde_json::Error,
    },
    /// The job's marker could not be written.
    #[error(transparent)]
    Jobs(#[from] crate::jobs::Error),
    /// A split has no samples.
    #[error("the {split} split of {dataset} has no samples in phases {phases:?}")]
    EmptySplit {
        /// The split.
        split: &'static str,
        /// The dataset folder.
        dataset: PathBuf,
        /// The phases asked for.
        phases: Vec<Phase>,
    },
}

/// What the bundle's `representation` holds: everything needed to compute the features again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Representation {
    /// The representation config.
    pub config: ReprConfig,
    /// The crop the features are pooled from (`240x240`, centered on the sensor).
    pub frame: String,
    /// Samples per phase used for training.
    pub sampling: Sampling,
    /// Phases trained on.
    pub phases: Vec<Phase>,
}

/// One training job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainSpec {
    /// The representation.
    pub repr: ReprConfig,
    /// Seed of the initial weights and the shuffling.
    pub seed: u64,
    /// Epochs.
    pub epochs: usize,
    /// Sampling scheme of the dataset.
    pub sampling: Sampling,
    /// Phases of the samples to train and validate on.
    pub phases: Vec<Phase>,
}

/// The loaded train and validation sets of a job.
pub fn load_split(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    split: Split,
    repr: &ReprConfig,
    sampling: Sampling,
    phases: &[Phase],
) -> Result<LoadedSet, Error> {
    let ds = cache.dataset();
    let trials = ds.trials(splits.get(split))?;
    let set = cache.load(&trials, repr, sampling, phases)?;
    if set.samples.is_empty() {
        return Err(Error::EmptySplit {
            split: split.as_str(),
            dataset: ds.dir.clone(),
            phases: phases.to_vec(),
        });
    }
    Ok(set)
}

/// Trains `spec` on the dataset's train split, selects on its validation split, saves the
/// bundle into `out` and marks it done. Returns the best validation MAE.
pub fn train_job(
    cache: &FeatureCache<'_>,
    splits: &Splits,
    spec: &TrainSpec,
    out: &Path,
    on_epoch: impl FnMut(&EpochRecord),
) -> Result<Mae, Error> {
    evtac_learn::flush_denormals();
    let train = load_split(
        cache,
        splits,
        Split::Train,
        &spec.repr,
        spec.sampling,
        &spec.phases,
    )?;
    let val = load_split(
        cache,
        splits,
        Split::Val,
        &spec.repr,
        spec.sampling,
        &spec.phases,
    )?;
    let cfg = TrainConfig {
        epochs: spec.epochs,
        seed: spec.seed,
        ..TrainConfig::default()
    };
    let trained = evtac_learn::train(&train.set, &val.set, &cfg, on_epoch).map_err(|source| {
        Error::Train {
            out: out.to_path_buf(),
            source,
        }
    })?;
    let val_mae = Mae::from(trained.best_val);
    let mask = cache.mask(&spec.repr)?.and_then(|m| {
        Array2::from_shape_vec(
            (usize::from(FRAME.height), usize::from(FRAME.width)),
            m.pixels().to_vec(),
        )
        .ok()
    });
    let representation = Representation {
        config: spec.repr,
        frame: FRAME.to_string(),
        sampling: spec.sampling,
        phases: spec.phases.clone(),
    };
    let value = serde_json::to_value(&representation).unwrap_or(serde_json::Value::Null);
    let bundle = ModelBundle::from_trained(trained, cfg, value, mask);
    bundle.save(out)?;
    crate::jobs::mark_done(out)?;
    Ok(val_mae)
}

/// A loaded model: its predictor and representation.
pub struct Model {
    /// Where it was loaded from.
    pub dir: PathBuf,
    /// The bundle.
    pub bundle: ModelBundle,
    /// Its representation settings.
    pub representation: Representation,
    /// Its predictor.
    pub predictor: Predictor,
}

impl std::fmt::Debug for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("dir", &self.dir)
            .field("representation", &self.representation)
            .finish()
    }
}

impl Model {
    /// Loads the bundle in `dir`.
    pub fn load(dir: &Path) -> Result<Model, Error> {
        let bundle = ModelBundle::load(dir)?;
        let representation: Representation =
            serde_json::from_value(bundle.config.representation.clone()).map_err(|source| {
                Error::Representation {
                    model: dir.to_path_buf(),
                    source,
                }
            })?;
        let predictor = bundle.predictor()?;
        Ok(Model {
            dir: dir.to_path_buf(),
            bundle,
            representation,
            predictor,
        })
    }

    /// Predictions for every row of `set`.
    pub fn predict(&self, set: &LoadedSet) -> Result<Vec<[f32; 2]>, Error> {
        evtac_learn::flush_denormals();
        self.predictor
            .predict(&set.set.features)
            .map_err(|source| Error::Predict {
                model: self.dir.clone(),
                source,
            })
    }
}

/// Labels of a loaded set as rows.
pub fn label_rows(set: &LoadedSet) -> Vec<[f32; 2]> {
    set.set
        .labels
        .chunks_exact(2)
        .map(|c| [c[0], c[1]])
        .collect()
}

/// MAE of `pred` on the samples of `set` in `phase` (all samples when `None`).
pub fn mae_in(set: &LoadedSet, pred: &[[f32; 2]], phase: Option<Phase>) -> Mae {
    let labels = label_rows(set);
    let (mut p, mut l) = (Vec::new(), Vec::new());
    for ((s, a), b) in set.samples.iter().zip(pred).zip(&labels) {
        if phase.is_none_or(|ph| ph == s.phase) {
            p.push(*a);
            l.push(*b);
        }
    }
    Mae::of(&p, &l)
}

impl From<evtac_learn::Mae> for Mae {
    fn from(m: evtac_learn::Mae) -> Self {
        Mae {
            overall: m.overall,
            pitch: m.pitch,
            roll: m.roll,
        }
    }
}
