//! The MLP contact-angle regressor of the paper: model, training loop, checkpoints, prediction
//! and metrics.
//!
//! - [`model`]: the 900 -> 256 -> 128 -> 64 -> 2 ReLU MLP as plain weights in PyTorch
//!   `nn.Linear` layout ([`Parameters`]), initialised as PyTorch does from a
//!   seeded `ChaCha8Rng`; [`architecture`]: the networks for two frames side by side
//!   (`stacked`, and `late` fusion's two branches), stored and run as the same four layers.
//! - [`data`]: in-memory [`FeatureSet`]s and the seeded epoch shuffling.
//! - [`training`]: [`train`] with SmoothL1 (beta 1) and AdamW as PyTorch computes it
//!   ([`adamw`]), batch 32, 100 epochs, validation MAE per epoch, best checkpoint kept.
//! - [`bundle`]: the [`ModelBundle`] folder (`model.safetensors`, `config.json`, `mask.npy`,
//!   `history.csv`).
//! - [`Model`]: a bundle loaded for use (predictor, representation, mask): what every consumer
//!   of a trained model loads.
//! - [`predictor`]: allocation-free single-sample inference ([`Predictor`]).
//! - [`cell_layer`]: the first layer computed exactly on pooled cell counts, and
//!   [`streaming`]: [`StreamingPredictor`], which updates it from the cells that changed
//!   between consecutive samples (what a live estimator needs).
//! - [`metrics`]: MAE overall / pitch / roll.
//! - [`ftz`]: [`flush_denormals`], to call on every thread that trains or infers.
//!
//! Training runs a hand-written forward and backward pass (`backprop.rs`, on the panel layout of
//! `panels.rs` that inference shares) that skips zero inputs, one thread per training run
//! (parallelism comes from running several runs side by side). burn, a dev-dependency, is the
//! independent reference its gradients are tested against (`burn_reference.rs`, tests only).
//!
//! ```no_run
//! use evtac_learn::{FeatureSet, Model, ModelBundle, Representation, TrainConfig, train};
//! use evtac_repr::ReprConfig;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let (train_set, val_set) = (FeatureSet::default(), FeatureSet::default());
//! let cfg = TrainConfig { seed: 7, ..TrainConfig::default() };
//! let trained = train(&train_set, &val_set, &cfg, |r| {
//!     eprintln!("epoch {} loss {:.4} val MAE {:.3}", r.epoch, r.train_loss, r.val_mae)
//! })?;
//! let representation = Representation::new(ReprConfig::Static(Default::default()));
//! let bundle = ModelBundle::from_trained(trained, cfg, representation, None);
//! bundle.save("model".as_ref())?;
//! let model = Model::load("model".as_ref())?;
//! let [pitch, roll] = model.predictor.predict_one(&[0.0; 900]);
//! # Ok(()) }
//! ```

pub mod adamw;
pub mod architecture;
mod backprop;
pub mod bundle;
#[cfg(test)]
mod burn_reference;
pub mod cell_layer;
pub mod data;
pub mod ftz;
#[cfg(target_arch = "x86_64")]
mod gradient_tile;
#[cfg(target_arch = "x86_64")]
mod grouped_tile;
pub mod metrics;
pub mod model;
mod panels;
pub mod predictor;
pub mod streaming;
mod trained_model;
pub mod training;

pub use adamw::AdamWConfig;
pub use architecture::Architecture;
pub use bundle::{BundleConfig, BundleMetrics, ModelBundle, Representation};
pub use data::FeatureSet;
pub use ftz::flush_denormals;
pub use metrics::{Mae, mae};
pub use model::{INPUTS, MAX_INPUTS, OUTPUTS, Parameters};
pub use predictor::Predictor;
pub use streaming::StreamingPredictor;
pub use trained_model::Model;
pub use training::{EpochRecord, TrainConfig, Trained, Trainer, train};
