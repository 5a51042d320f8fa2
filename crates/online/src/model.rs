//! A trained model as the online estimator needs it: predictor, representation settings and
//! no-contact mask, read from an `evtac-learn` model bundle folder.

use crate::estimator::{self, CROP_SIZE, Estimator};
use evtac_events::Resolution;
use evtac_learn::{ModelBundle, Predictor};
use evtac_repr::{Mask, ReprConfig};
use std::path::{Path, PathBuf};

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The bundle could not be read.
    #[error("reading the model bundle {dir}: {source}")]
    Bundle {
        /// The bundle folder.
        dir: PathBuf,
        /// What failed.
        #[source]
        source: Box<evtac_learn::bundle::Error>,
    },
    /// `config.json`'s `representation` is neither a representation config nor an object
    /// holding one under `config`.
    #[error(
        "{dir}/config.json: `representation` is not a representation config \
         (expected {{\"kind\": \"static\" | \"dynamic\" | \"combined\", ...}} or \
         {{\"config\": {{\"kind\": ...}}, \"frame\": \"240x240\"}}): {reason}"
    )]
    Representation {
        /// The bundle folder.
        dir: PathBuf,
        /// Why it did not parse.
        reason: String,
    },
    /// The representation was built on a crop other than the 240x240 one online uses.
    #[error(
        "{dir}: the model was trained on a {frame} crop; online estimation uses {CROP_SIZE}x{CROP_SIZE}"
    )]
    Frame {
        /// The bundle folder.
        dir: PathBuf,
        /// The crop the bundle names.
        frame: String,
    },
    /// `mask.npy` does not fit the crop.
    #[error("{dir}/mask.npy: {source}")]
    Mask {
        /// The bundle folder.
        dir: PathBuf,
        /// What is wrong.
        #[source]
        source: evtac_repr::ReprError,
    },
}

/// Everything online estimation needs from a trained model.
#[derive(Debug, Clone)]
pub struct Model {
    /// The bundle folder it came from (for messages).
    pub dir: PathBuf,
    /// The representation the model was trained on.
    pub representation: ReprConfig,
    /// The no-contact mask applied to the static representation, if one was used.
    pub mask: Option<Mask>,
    /// The MLP.
    pub predictor: Predictor,
}

/// The shape `evtac-experiments` stores: the config plus how it was sampled.
#[derive(serde::Deserialize)]
struct Wrapped {
    config: ReprConfig,
    #[serde(default)]
    frame: Option<String>,
}

impl Model {
    /// Reads the bundle in `dir`: weights (`model.safetensors`), the representation from
    /// `config.json` (`representation`: a representation config, or an object with it under
    /// `config` and the crop under `frame`), and `mask.npy` when present.
    pub fn load(dir: &Path) -> Result<Self, Error> {
        let bundle = ModelBundle::load(dir).map_err(|source| Error::Bundle {
            dir: dir.to_path_buf(),
            source: Box::new(source),
        })?;
        Self::from_bundle(dir, &bundle)
    }

    /// As [`Model::load`], from a bundle already in memory (`dir` only names it in messages).
    pub fn from_bundle(dir: &Path, bundle: &ModelBundle) -> Result<Self, Error> {
        let value = &bundle.config.representation;
        let representation = match serde_json::from_value::<ReprConfig>(value.clone()) {
            Ok(config) => config,
            Err(direct) => {
                let wrapped = serde_json::from_value::<Wrapped>(value.clone()).map_err(|w| {
                    Error::Representation {
                        dir: dir.to_path_buf(),
                        reason: format!("{direct}; as an object with `config`: {w}"),
                    }
                })?;
                if let Some(frame) = wrapped.frame {
                    let crop = Resolution::new(CROP_SIZE, CROP_SIZE);
                    if frame.parse::<Resolution>().ok() != Some(crop) {
                        return Err(Error::Frame {
                            dir: dir.to_path_buf(),
                            frame,
                        });
                    }
                }
                wrapped.config
            }
        };
        let mask = bundle
            .mask
            .as_ref()
            .map(|m| {
                let (h, w) = m.dim();
                let resolution = Resolution::new(
                    u16::try_from(w).unwrap_or(u16::MAX),
                    u16::try_from(h).unwrap_or(u16::MAX),
                );
                let crop = Resolution::new(CROP_SIZE, CROP_SIZE);
                if resolution != crop {
                    return Err(evtac_repr::ReprError::MaskSize {
                        mask_width: resolution.width,
                        mask_height: resolution.height,
                        width: crop.width,
                        height: crop.height,
                    });
                }
                let pixels: Vec<u8> = m.iter().copied().collect();
                Mask::from_pixels(crop, &pixels)
            })
            .transpose()
            .map_err(|source| Error::Mask {
                dir: dir.to_path_buf(),
                source,
            })?;
        let predictor = bundle.predictor().map_err(|source| Error::Bundle {
            dir: dir.to_path_buf(),
            source: Box::new(source),
        })?;
        Ok(Self {
            dir: dir.to_path_buf(),
            representation,
            mask,
            predictor,
        })
    }

    /// An [`Estimator`] for a sensor of `sensor` pixels estimating every `interval_us`.
    pub fn estimator(
        &self,
        sensor: Resolution,
        interval_us: i64,
    ) -> Result<Estimator, estimator::Error> {
        Estimator::new(
            &self.representation,
            self.mask.as_ref(),
            self.predictor.clone(),
            sensor,
            interval_us,
        )
    }
}
