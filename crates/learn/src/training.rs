//! The training loop: seeded initialisation and shuffling, SmoothL1 (Huber, beta 1) loss,
//! AdamW as PyTorch computes it, validation MAE after every epoch and the best-validation
//! checkpoint.
//!
//! [`train`] runs the paper's recipe end to end; [`Trainer`] exposes single steps on given
//! batches (used by the PyTorch comparison test and available for custom loops).

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::adamw::{AdamW, AdamWConfig};
use crate::backprop::{self, MAX_BATCH, Network, Scratch};
use crate::data::{FeatureSet, Shuffler};
use crate::metrics::{self, Mae};
use crate::model::{self, Architecture, OUTPUTS, Parameters};

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The training or validation set is malformed.
    #[error("{set} set: {source}")]
    Data {
        /// `"training"` or `"validation"`.
        set: &'static str,
        /// What is wrong with it.
        source: crate::data::Error,
    },
    /// A set needed for training is empty.
    #[error("the {set} set is empty")]
    Empty {
        /// `"training"` or `"validation"`.
        set: &'static str,
    },
    /// A configuration value is out of range.
    #[error("invalid training config: {field} = {value} ({why})")]
    Config {
        /// Field name in [`TrainConfig`].
        field: &'static str,
        /// The value given.
        value: f64,
        /// The limit it breaks.
        why: &'static str,
    },
    /// A batch passed to [`Trainer::step`] is malformed (or over 65,535 samples).
    #[error(
        "batch of {features} feature values and {labels} labels is not n x {inputs} and n x 2 with 1 <= n <= 65535"
    )]
    Batch {
        /// Number of feature values.
        features: usize,
        /// Features per sample the network reads.
        inputs: usize,
        /// Number of label values.
        labels: usize,
    },
    /// A set's features do not have the width the network reads.
    #[error(
        "the {set} set has {width} features per sample but the {} network reads {}",
        architecture.name(),
        architecture.inputs()
    )]
    Width {
        /// `"training"` or `"validation"`.
        set: &'static str,
        /// Its features per sample.
        width: usize,
        /// The network.
        architecture: Architecture,
    },
    /// The loss became NaN or infinite (diverged).
    #[error("the training loss is not finite at epoch {epoch}, step {step}")]
    Diverged {
        /// Epoch (1-based; 0 for [`Trainer::step`]).
        epoch: usize,
        /// Optimiser step (1-based).
        step: u64,
    },
    /// The weights do not fit the architecture.
    #[error(transparent)]
    Model(#[from] model::Error),
    /// Computing the validation MAE failed.
    #[error(transparent)]
    Metrics(#[from] metrics::Error),
}

/// The training recipe. Defaults are the paper's: 100 epochs, batch 32, SmoothL1 with beta 1,
/// AdamW lr 5e-3 and weight decay 1e-4 (betas 0.9 / 0.999 and eps 1e-8 as PyTorch).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrainConfig {
    /// Number of passes over the training set.
    pub epochs: usize,
    /// Samples per optimiser step (the last batch of an epoch may be smaller, as PyTorch's
    /// `DataLoader` without `drop_last`).
    pub batch_size: usize,
    /// SmoothL1 threshold between the quadratic and linear parts (degrees).
    pub huber_beta: f64,
    /// Optimiser settings.
    pub optimizer: AdamWConfig,
    /// Seed of the initial weights (`ChaCha8Rng` stream 0) and the shuffling (stream 1).
    pub seed: u64,
    /// The network: the paper's MLP, or one of the two-frame networks for the `stacked` and
    /// `late` representations ([`Architecture::for_repr`]). Absent in bundles written before
    /// they existed, which are all the paper's MLP.
    pub architecture: Architecture,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            epochs: 100,
            batch_size: 32,
            huber_beta: 1.0,
            optimizer: AdamWConfig::default(),
            seed: 0,
            architecture: Architecture::Mlp,
        }
    }
}

impl TrainConfig {
    /// Checks every value's range.
    pub fn validate(&self) -> Result<(), Error> {
        let o = &self.optimizer;
        let checks: [(&'static str, f64, bool, &'static str); 8] = [
            ("epochs", self.epochs as f64, self.epochs >= 1, "at least 1"),
            (
                "batch_size",
                self.batch_size as f64,
                (1..=MAX_BATCH).contains(&self.batch_size),
                "from 1 to 65535",
            ),
            (
                "huber_beta",
                self.huber_beta,
                self.huber_beta > 0.0 && self.huber_beta.is_finite(),
                "positive",
            ),
            (
                "optimizer.learning_rate",
                o.learning_rate,
                o.learning_rate > 0.0 && o.learning_rate.is_finite(),
                "positive",
            ),
            (
                "optimizer.weight_decay",
                o.weight_decay,
                o.weight_decay >= 0.0 && o.weight_decay.is_finite(),
                "non-negative",
            ),
            (
                "optimizer.beta1",
                o.beta1,
                (0.0..1.0).contains(&o.beta1),
                "in [0, 1)",
            ),
            (
                "optimizer.beta2",
                o.beta2,
                (0.0..1.0).contains(&o.beta2),
                "in [0, 1)",
            ),
            (
                "optimizer.epsilon",
                o.epsilon,
                o.epsilon > 0.0 && o.epsilon.is_finite(),
                "positive",
            ),
        ];
        for (field, value, ok, why) in checks {
            if !ok {
                return Err(Error::Config { field, value, why });
            }
        }
        Ok(())
    }
}

/// What one epoch achieved.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EpochRecord {
    /// Epoch number, 1-based.
    pub epoch: usize,
    /// Mean SmoothL1 loss over the epoch's training samples (each batch's loss weighted by its
    /// size), measured before each step's update.
    pub train_loss: f64,
    /// Validation MAE after the epoch (mean of pitch and roll), degrees.
    pub val_mae: f64,
    /// Validation pitch MAE, degrees.
    pub val_mae_pitch: f64,
    /// Validation roll MAE, degrees.
    pub val_mae_roll: f64,
    /// Wall-clock seconds of the epoch (training and validation).
    pub seconds: f64,
    /// Of those, the validation's (the rest are the training steps). `None` for epochs read
    /// back from a `history.csv`, which keeps the epoch's total only.
    pub validation_seconds: Option<f64>,
}

/// The result of [`train`].
#[derive(Debug, Clone)]
pub struct Trained {
    /// Weights of the epoch with the lowest validation MAE (the earliest on ties).
    pub parameters: Parameters,
    /// That epoch (1-based).
    pub best_epoch: usize,
    /// Its validation MAE.
    pub best_val: Mae,
    /// Every epoch's record, in order.
    pub history: Vec<EpochRecord>,
}

/// Trains the MLP on `train`, validating on `val` after every epoch, and returns the
/// best-validation weights with the history. `on_epoch` sees each epoch's record as it ends
/// (for progress bars). Deterministic: the same inputs and config give the same bytes.
///
/// Calls [`crate::flush_denormals`] on this thread (training runs on it alone).
pub fn train(
    train: &FeatureSet,
    val: &FeatureSet,
    cfg: &TrainConfig,
    mut on_epoch: impl FnMut(&EpochRecord),
) -> Result<Trained, Error> {
    cfg.validate()?;
    train.validate().map_err(|source| Error::Data {
        set: "training",
        source,
    })?;
    val.validate().map_err(|source| Error::Data {
        set: "validation",
        source,
    })?;
    if train.is_empty() {
        return Err(Error::Empty { set: "training" });
    }
    if val.is_empty() {
        return Err(Error::Empty { set: "validation" });
    }
    let inputs = cfg.architecture.inputs();
    for (set, data) in [("training", train), ("validation", val)] {
        if data.width != inputs {
            return Err(Error::Width {
                set,
                width: data.width,
                architecture: cfg.architecture,
            });
        }
    }
    let mut trainer = Trainer::new(&Parameters::init_for(cfg.architecture, cfg.seed), cfg)?;
    let mut shuffler = Shuffler::new(train.len(), cfg.seed);
    let (mut xb, mut yb) = (Vec::new(), Vec::new());
    let mut history = Vec::with_capacity(cfg.epochs);
    let mut best: Option<(Mae, usize, Parameters)> = None;
    for epoch in 1..=cfg.epochs {
        let started = Instant::now();
        let mut loss_sum = 0.0;
        for batch in shuffler.next_epoch().chunks(cfg.batch_size) {
            train.gather(batch, &mut xb, &mut yb);
            let loss = trainer.step(&xb, &yb)?;
            if !loss.is_finite() {
                return Err(Error::Diverged {
                    epoch,
                    step: trainer.steps(),
                });
            }
            loss_sum += f64::from(loss) * batch.len() as f64;
        }
        let validating = Instant::now();
        let mae = metrics::mae(&trainer.predict(&val.features)?, &val.labels)?;
        let validation_seconds = Some(validating.elapsed().as_secs_f64());
        let record = EpochRecord {
            epoch,
            train_loss: loss_sum / train.len() as f64,
            val_mae: mae.overall,
            val_mae_pitch: mae.pitch,
            val_mae_roll: mae.roll,
            seconds: started.elapsed().as_secs_f64(),
            validation_seconds,
        };
        // Strictly lower only: ties keep the earlier epoch, and a NaN never replaces a number.
        let improved = best
            .as_ref()
            .is_none_or(|(b, _, _)| mae.overall < b.overall);
        if improved {
            best = Some((mae, epoch, trainer.parameters()?));
        }
        history.push(record);
        on_epoch(&record);
    }
    // `epochs >= 1` was validated and the first epoch always sets `best`.
    let (best_val, best_epoch, parameters) = best.ok_or(Error::Empty { set: "validation" })?;
    Ok(Trained {
        parameters,
        best_epoch,
        best_val,
        history,
    })
}

/// A model being trained: its weights in the training layout, the AdamW state and the step's
/// buffers (see `backprop.rs`).
#[derive(Debug)]
pub struct Trainer {
    net: Network,
    optimizer: AdamW,
    beta: f32,
    scratch: Scratch,
}

impl Trainer {
    /// A trainer starting from `params` with `cfg`'s loss and optimiser settings (its `epochs`,
    /// `batch_size`, `seed` and `architecture` are not used here: `params` is the network). Flushes subnormals on this thread.
    pub fn new(params: &Parameters, cfg: &TrainConfig) -> Result<Self, Error> {
        cfg.validate()?;
        params.validate()?;
        crate::ftz::flush_denormals();
        Ok(Self {
            net: Network::new(params),
            optimizer: AdamW::new(cfg.optimizer),
            beta: cfg.huber_beta as f32,
            scratch: Scratch::default(),
        })
    }

    /// The number of optimiser steps taken.
    pub fn steps(&self) -> u64 {
        self.optimizer.steps()
    }

    /// One AdamW step on a batch (`features` n x inputs, `labels` n x 2, flat); returns the
    /// batch's mean SmoothL1 loss before the update.
    pub fn step(&mut self, features: &[f32], labels: &[f32]) -> Result<f32, Error> {
        let n = labels.len() / OUTPUTS;
        let inputs = self.net.inputs();
        if n == 0 || n > MAX_BATCH || features.len() != n * inputs || labels.len() != n * OUTPUTS {
            return Err(Error::Batch {
                features: features.len(),
                inputs,
                labels: labels.len(),
            });
        }
        let (net, optimizer, scratch) = (&mut self.net, &mut self.optimizer, &mut self.scratch);
        Ok(backprop::step(
            net, optimizer, scratch, features, labels, self.beta,
        ))
    }

    /// Predictions for `features` (n x inputs, flat) with the current weights.
    pub fn predict(&self, features: &[f32]) -> Result<Vec<[f32; 2]>, Error> {
        let inputs = self.net.inputs();
        if !features.len().is_multiple_of(inputs) {
            return Err(Error::Batch {
                features: features.len(),
                inputs,
                labels: 0,
            });
        }
        Ok(self.net.predict(features))
    }

    /// The current weights in PyTorch layout.
    pub fn parameters(&self) -> Result<Parameters, Error> {
        let params = self.net.parameters();
        params.validate()?;
        Ok(params)
    }
}
