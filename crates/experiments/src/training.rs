//! One training job: the features of a dataset's train and validation splits under one
//! representation config (from the cache), `evtac_learn::train`, and a saved model bundle with a
//! `done` marker. `evtac train` and `evtac reproduce` both run exactly this.

use crate::cache::{self, FeatureCache, LoadedSet};
use crate::dataset::{self, Dataset};
use crate::job::TrainJob;
use crate::results::Mae;
use crate::sampling::{Phase, Sampling};
use crate::splits::{Split, Splits};
use evtac_learn::bundle::SampleCounts;
use evtac_learn::{EpochRecord, Model, ModelBundle, Representation, TrainConfig};
use evtac_repr::ReprConfig;
use std::path::{Path, PathBuf};

pub use crate::job::TrainSpec;

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

/// Seeds the label noise apart from the weights and the shuffling, which the same `seed`
/// drives: a noisy-label run shares its clean twin's initial weights and batches.
const LABEL_NOISE_STREAM: u64 = 0x6c61_6265_6c5f_6e6f;

/// `labels` with Gaussian noise of standard deviation `sd` (degrees) added to each, drawn from
/// a ChaCha8 stream of `seed` (same seed, same noise), rounded once to `f32`.
pub fn noisy_labels(labels: &mut [f32], sd: f64, seed: u64) {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let Ok(normal) = Normal::new(0.0, sd) else {
        return;
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ LABEL_NOISE_STREAM);
    for label in labels {
        *label = (f64::from(*label) + normal.sample(&mut rng)) as f32;
    }
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
    let mut train = train;
    if spec.label_noise_deg > 0.0 {
        noisy_labels(&mut train.set.labels, spec.label_noise_deg, spec.seed);
    }
    let cfg = TrainConfig {
        epochs: spec.epochs,
        seed: spec.seed,
        architecture: evtac_learn::Architecture::for_repr(&spec.repr),
        ..TrainConfig::default()
    };
    let trained = evtac_learn::train(&train.set, &val.set, &cfg, on_epoch).map_err(|source| {
        Error::Train {
            out: out.to_path_buf(),
            source,
        }
    })?;
    let val_mae = Mae::from(trained.best_val);
    let mask = cache.mask(&spec.repr)?;
    let representation = Representation {
        sampling: Some(SampleCounts {
            motion_points: spec.sampling.motion_points,
            stop_points: spec.sampling.stop_points,
        }),
        phases: spec.phases.iter().map(|p| p.as_str().to_string()).collect(),
        filters: cache
            .dataset()
            .inputs
            .filters
            .iter()
            .map(|f| f.to_string())
            .collect(),
        ..Representation::new(spec.repr)
    };
    let bundle = ModelBundle::from_trained(trained, cfg, representation, mask);
    bundle.save(out)?;
    crate::jobs::mark_done(out)?;
    Ok(val_mae)
}

/// Runs `job` on its own (`evtac train`, or a task of a jobs file): opens the dataset, makes its
/// splits when missing and the features the job needs (`on_trial(reused)` after each trial),
/// then trains (`on_epoch` after each epoch). Returns the best validation MAE. The local
/// pipeline, which runs many jobs over one opened dataset, calls [`train_job`] instead.
pub fn run_job(
    job: &TrainJob,
    on_trial: &(dyn Fn(bool) + Sync),
    on_epoch: impl FnMut(&EpochRecord),
) -> Result<Mae, Error> {
    let ds = Dataset::open(&job.dataset, job.inputs.clone())?;
    let splits = ds.splits(job.splits_seed)?;
    let cache = FeatureCache::new(&ds)?;
    let trials: Vec<_> = ds.manifest.trials.iter().collect();
    cache.ensure(
        &trials,
        std::slice::from_ref(&job.spec.repr),
        job.spec.sampling,
        on_trial,
    )?;
    train_job(&cache, &splits, &job.spec, &job.out, on_epoch)
}

/// Loads the model bundle a training job wrote into `dir`.
pub fn load_model(dir: &Path) -> Result<Model, Error> {
    Ok(Model::load(dir)?)
}

/// Predictions of `model` for every row of `set`.
pub fn predict(model: &Model, set: &LoadedSet) -> Result<Vec<[f32; 2]>, Error> {
    model
        .predict(&set.set.features)
        .map_err(|source| Error::Predict {
            model: model.dir.clone(),
            source,
        })
}

/// Labels of a loaded set as rows.
pub fn label_rows(set: &LoadedSet) -> Vec<[f32; 2]> {
    set.set
        .labels
        .chunks_exact(2)
        .map(|c| [c[0], c[1]])
        .collect()
}

/// MAE of `pred` against the labels on the samples of `set` in `phase` (all samples when
/// `None`).
pub fn mae_in(set: &LoadedSet, pred: &[[f32; 2]], phase: Option<Phase>) -> Mae {
    crate::truth::mae_against(set, pred, &label_rows(set), |p| {
        phase.is_none_or(|ph| ph == p)
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn label_noise_is_seeded_centred_and_of_the_asked_spread() {
        let clean = vec![1.5f32; 20_000];
        let noisy = |seed| {
            let mut labels = clean.clone();
            noisy_labels(&mut labels, 0.04, seed);
            labels
        };
        let (a, b) = (noisy(7), noisy(8));
        assert!(a == noisy(7), "same seed, different noise");
        assert!(a != b, "different seeds, same noise");
        let d: Vec<f64> = a.iter().map(|&x| f64::from(x) - 1.5).collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt();
        // 20,000 draws: the mean within 4 standard errors, the SD within 3 %.
        assert!(
            mean.abs() < 4.0 * 0.04 / (d.len() as f64).sqrt(),
            "mean {mean}"
        );
        assert!((sd / 0.04 - 1.0).abs() < 0.03, "sd {sd}");
        let mut untouched = clean.clone();
        noisy_labels(&mut untouched, 0.0, 7);
        assert!(
            untouched == clean,
            "a standard deviation of 0 changed the labels"
        );
    }
}
