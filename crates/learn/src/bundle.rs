//! The model bundle: a folder holding everything needed to use and reproduce a trained model.
//!
//! | file                | contents |
//! |---------------------|----------|
//! | `model.safetensors` | weights in PyTorch `nn.Linear` layout: `layers.{i}.weight` f32 `[out, in]` and `layers.{i}.bias` f32 `[out]` for `i = 0..4` (900-256-128-64-2); metadata `{"format": "pt"}` |
//! | `config.json`       | [`BundleConfig`]: format version, architecture, training config (with the seed), the caller's representation config, metrics |
//! | `mask.npy`          | optional no-contact mask, u8 `H x W` (absent when none was used) |
//! | `history.csv`       | one row per epoch: `epoch,train_loss,val_mae,val_mae_pitch,val_mae_roll,seconds` |
//!
//! In PyTorch the weights load into
//! `nn.Module` with `self.layers = nn.ModuleList([nn.Linear(900, 256), nn.Linear(256, 128),
//! nn.Linear(128, 64), nn.Linear(64, 2)])` (ReLU after all but the last) through
//! `model.load_state_dict(safetensors.torch.load_file(path))`.
//!
//! The safetensors file depends only on the weights, so the same seed and data give the same
//! bytes; `history.csv` also records wall-clock times and differs between runs.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use ndarray::Array2;
use safetensors::tensor::{Dtype, SafeTensors, TensorView};
use serde::{Deserialize, Serialize};

use crate::metrics::Mae;
use crate::model::{self, LAYER_SIZES, LAYERS, LayerParameters, Parameters};
use crate::predictor::{self, Predictor};
use crate::training::{EpochRecord, TrainConfig, Trained};

/// The weights file inside a bundle.
pub const MODEL_FILE: &str = "model.safetensors";
/// The configuration file inside a bundle.
pub const CONFIG_FILE: &str = "config.json";
/// The optional mask file inside a bundle.
pub const MASK_FILE: &str = "mask.npy";
/// The training-curve file inside a bundle.
pub const HISTORY_FILE: &str = "history.csv";
/// The bundle format written by this version; loading rejects other versions.
pub const FORMAT_VERSION: u32 = 1;
/// Header of `history.csv`.
const HISTORY_HEADER: &str = "epoch,train_loss,val_mae,val_mae_pitch,val_mae_roll,seconds";

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The safetensors file could not be parsed or written.
    #[error("{path}: {message}")]
    SafeTensors {
        /// The file.
        path: PathBuf,
        /// What the safetensors crate reported.
        message: String,
    },
    /// A tensor is missing from the safetensors file.
    #[error("{path}: tensor {name} is missing")]
    MissingTensor {
        /// The file.
        path: PathBuf,
        /// The tensor's name.
        name: String,
    },
    /// A tensor has the wrong dtype or shape.
    #[error("{path}: tensor {name} is {dtype} {shape:?}, expected F32 {expected:?}")]
    TensorLayout {
        /// The file.
        path: PathBuf,
        /// The tensor's name.
        name: String,
        /// Its dtype.
        dtype: String,
        /// Its shape.
        shape: Vec<usize>,
        /// The shape required.
        expected: Vec<usize>,
    },
    /// The weights do not fit the architecture or are not finite.
    #[error("{path}: {source}")]
    Model {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: model::Error,
    },
    /// `config.json` is not a valid bundle configuration.
    #[error("{path}: {source}")]
    Json {
        /// The file.
        path: PathBuf,
        /// The parse error (with line and column).
        source: serde_json::Error,
    },
    /// The bundle was written by an incompatible format version.
    #[error("{path}: format_version {found} is not supported (this build reads {FORMAT_VERSION})")]
    FormatVersion {
        /// The config file.
        path: PathBuf,
        /// The version found.
        found: u32,
    },
    /// `mask.npy` could not be read as a u8 2-D array.
    #[error("{path}: {message}")]
    Mask {
        /// The file.
        path: PathBuf,
        /// What failed.
        message: String,
    },
    /// A `history.csv` line is malformed.
    #[error("{path}:{line}: {message}")]
    History {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Building the predictor failed.
    #[error(transparent)]
    Predictor(#[from] predictor::Error),
}

/// Metrics stored in `config.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BundleMetrics {
    /// The epoch whose weights were kept (1-based).
    pub best_epoch: usize,
    /// Validation MAE of those weights.
    pub validation: Mae,
    /// Further evaluations keyed by a name the caller chooses (e.g. `"test"`).
    #[serde(default)]
    pub evaluations: BTreeMap<String, Mae>,
}

/// The contents of `config.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BundleConfig {
    /// Bundle format version ([`FORMAT_VERSION`]).
    pub format_version: u32,
    /// Layer widths, input first (always `[900, 256, 128, 64, 2]`; informational).
    pub architecture: Vec<usize>,
    /// The training recipe, including the seed.
    pub training: TrainConfig,
    /// The representation settings needed to compute the features again, as the caller's own
    /// serde value (this crate does not interpret it).
    pub representation: serde_json::Value,
    /// Validation and evaluation results.
    pub metrics: BundleMetrics,
}

/// A trained model with its provenance (see the module docs for the folder layout).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelBundle {
    /// The weights.
    pub parameters: Parameters,
    /// The configuration and metrics.
    pub config: BundleConfig,
    /// The no-contact mask used by the representation, if any (u8, `H x W`).
    pub mask: Option<Array2<u8>>,
    /// The training curve.
    pub history: Vec<EpochRecord>,
}

impl ModelBundle {
    /// A bundle from a training result, the config it was trained with, the caller's
    /// representation settings and the mask.
    pub fn from_trained(
        trained: Trained,
        training: TrainConfig,
        representation: serde_json::Value,
        mask: Option<Array2<u8>>,
    ) -> Self {
        Self {
            parameters: trained.parameters,
            config: BundleConfig {
                format_version: FORMAT_VERSION,
                architecture: LAYER_SIZES.to_vec(),
                training,
                representation,
                metrics: BundleMetrics {
                    best_epoch: trained.best_epoch,
                    validation: trained.best_val,
                    evaluations: BTreeMap::new(),
                },
            },
            mask,
            history: trained.history,
        }
    }

    /// A [`Predictor`] for these weights.
    pub fn predictor(&self) -> Result<Predictor, Error> {
        Ok(Predictor::new(&self.parameters)?)
    }

    /// Writes the bundle into `dir` (created if needed; existing bundle files are replaced and
    /// a stale `mask.npy` is removed when this bundle has none).
    pub fn save(&self, dir: &Path) -> Result<(), Error> {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let model_path = dir.join(MODEL_FILE);
        let bytes =
            weights_to_safetensors(&self.parameters).map_err(|message| Error::SafeTensors {
                path: model_path.clone(),
                message,
            })?;
        std::fs::write(&model_path, bytes).map_err(io(&model_path))?;

        let config_path = dir.join(CONFIG_FILE);
        let mut json =
            serde_json::to_string_pretty(&self.config).map_err(|source| Error::Json {
                path: config_path.clone(),
                source,
            })?;
        json.push('\n');
        std::fs::write(&config_path, json).map_err(io(&config_path))?;

        let mask_path = dir.join(MASK_FILE);
        match &self.mask {
            Some(mask) => ndarray_npy::write_npy(&mask_path, mask).map_err(|e| Error::Mask {
                path: mask_path.clone(),
                message: e.to_string(),
            })?,
            None => match std::fs::remove_file(&mask_path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(io(&mask_path)(e));
                }
                _ => {}
            },
        }

        let history_path = dir.join(HISTORY_FILE);
        let mut csv = String::from(HISTORY_HEADER);
        csv.push('\n');
        for r in &self.history {
            csv.push_str(&format!(
                "{},{},{},{},{},{}\n",
                r.epoch, r.train_loss, r.val_mae, r.val_mae_pitch, r.val_mae_roll, r.seconds
            ));
        }
        std::fs::write(&history_path, csv).map_err(io(&history_path))?;
        Ok(())
    }

    /// Reads a bundle folder written by [`ModelBundle::save`] (or by PyTorch tools following the
    /// same layout; `mask.npy` and `history.csv` may be absent).
    pub fn load(dir: &Path) -> Result<Self, Error> {
        let parameters = load_weights(&dir.join(MODEL_FILE))?;

        let config_path = dir.join(CONFIG_FILE);
        let text = std::fs::read_to_string(&config_path).map_err(io(&config_path))?;
        // Check the version first so a future format fails with a clear message.
        #[derive(Deserialize)]
        struct Version {
            format_version: u32,
        }
        let version: Version = serde_json::from_str(&text).map_err(|source| Error::Json {
            path: config_path.clone(),
            source,
        })?;
        if version.format_version != FORMAT_VERSION {
            return Err(Error::FormatVersion {
                path: config_path,
                found: version.format_version,
            });
        }
        let config: BundleConfig = serde_json::from_str(&text).map_err(|source| Error::Json {
            path: config_path.clone(),
            source,
        })?;

        let mask_path = dir.join(MASK_FILE);
        let mask = if mask_path.is_file() {
            Some(
                ndarray_npy::read_npy::<_, Array2<u8>>(&mask_path).map_err(|e| Error::Mask {
                    path: mask_path.clone(),
                    message: e.to_string(),
                })?,
            )
        } else {
            None
        };

        let history_path = dir.join(HISTORY_FILE);
        let history = if history_path.is_file() {
            parse_history(
                &history_path,
                &std::fs::read_to_string(&history_path).map_err(io(&history_path))?,
            )?
        } else {
            Vec::new()
        };
        Ok(Self {
            parameters,
            config,
            mask,
            history,
        })
    }
}

/// Reads and checks only the weights of `model.safetensors` (e.g. for prediction).
pub fn load_weights(path: &Path) -> Result<Parameters, Error> {
    let bytes = std::fs::read(path).map_err(io(path))?;
    let st = SafeTensors::deserialize(&bytes).map_err(|e| Error::SafeTensors {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let mut layers = Vec::with_capacity(LAYERS);
    for (i, w) in LAYER_SIZES.windows(2).enumerate() {
        let (fan_in, fan_out) = (w[0], w[1]);
        let read = |suffix: &str, expected: Vec<usize>| -> Result<Vec<f32>, Error> {
            let name = format!("layers.{i}.{suffix}");
            let view = st.tensor(&name).map_err(|_| Error::MissingTensor {
                path: path.to_path_buf(),
                name: name.clone(),
            })?;
            if view.dtype() != Dtype::F32 || view.shape() != expected.as_slice() {
                return Err(Error::TensorLayout {
                    path: path.to_path_buf(),
                    name,
                    dtype: format!("{:?}", view.dtype()),
                    shape: view.shape().to_vec(),
                    expected,
                });
            }
            // safetensors stores little-endian values; the length was checked by the parser
            // against the shape, so `chunks_exact(4)` covers every byte.
            Ok(view
                .data()
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect())
        };
        let weight = read("weight", vec![fan_out, fan_in])?;
        let bias = read("bias", vec![fan_out])?;
        layers.push(LayerParameters { weight, bias });
    }
    let parameters = Parameters { layers };
    parameters.validate().map_err(|source| Error::Model {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(parameters)
}

/// Serialises the weights as safetensors bytes (names and layout in the module docs).
fn weights_to_safetensors(params: &Parameters) -> Result<Vec<u8>, String> {
    let mut buffers: Vec<(String, Vec<usize>, Vec<u8>)> = Vec::with_capacity(2 * LAYERS);
    for (i, (layer, w)) in params.layers.iter().zip(LAYER_SIZES.windows(2)).enumerate() {
        let le = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        buffers.push((
            format!("layers.{i}.weight"),
            vec![w[1], w[0]],
            le(&layer.weight),
        ));
        buffers.push((format!("layers.{i}.bias"), vec![w[1]], le(&layer.bias)));
    }
    let views = buffers
        .iter()
        .map(|(name, shape, data)| {
            TensorView::new(Dtype::F32, shape.clone(), data)
                .map(|view| (name.clone(), view))
                .map_err(|e| e.to_string())
        })
        .collect::<Result<Vec<_>, String>>()?;
    // PyTorch's `safetensors.torch.save_file` writes the same metadata.
    let metadata = HashMap::from([("format".to_string(), "pt".to_string())]);
    safetensors::serialize(views, Some(metadata)).map_err(|e| e.to_string())
}

/// Parses `history.csv`.
fn parse_history(path: &Path, text: &str) -> Result<Vec<EpochRecord>, Error> {
    let err = |line: usize, message: String| Error::History {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, header)) if header.trim() == HISTORY_HEADER => {}
        other => {
            return Err(err(
                1,
                format!(
                    "header is {:?}, expected {HISTORY_HEADER:?}",
                    other.map(|(_, h)| h).unwrap_or("")
                ),
            ));
        }
    }
    let mut out = Vec::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != 6 {
            return Err(err(i + 1, format!("{} fields, expected 6", fields.len())));
        }
        let epoch = fields[0]
            .trim()
            .parse::<usize>()
            .map_err(|e| err(i + 1, format!("epoch {:?}: {e}", fields[0])))?;
        let mut v = [0.0_f64; 5];
        for (k, slot) in v.iter_mut().enumerate() {
            *slot = fields[k + 1]
                .trim()
                .parse::<f64>()
                .map_err(|e| err(i + 1, format!("field {} {:?}: {e}", k + 2, fields[k + 1])))?;
        }
        out.push(EpochRecord {
            epoch,
            train_loss: v[0],
            val_mae: v[1],
            val_mae_pitch: v[2],
            val_mae_roll: v[3],
            seconds: v[4],
        });
    }
    Ok(out)
}

/// Maps an I/O error to [`Error::Io`] naming `path`.
fn io(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bundle(seed: u64, mask: bool) -> ModelBundle {
        let mae = Mae {
            overall: 1.5,
            pitch: 1.0,
            roll: 2.0,
        };
        ModelBundle::from_trained(
            Trained {
                parameters: Parameters::init(seed),
                best_epoch: 2,
                best_val: mae,
                history: vec![EpochRecord {
                    epoch: 1,
                    train_loss: 0.25,
                    val_mae: 1.5,
                    val_mae_pitch: 1.0,
                    val_mae_roll: 2.0,
                    seconds: 0.125,
                }],
            },
            TrainConfig {
                seed,
                ..TrainConfig::default()
            },
            serde_json::json!({"static": {"tau_ms": 1000}}),
            mask.then(|| Array2::from_shape_fn((4, 3), |(y, x)| u8::from(x == y))),
        )
    }

    #[test]
    fn save_load_round_trip() {
        let dir = tempfile::tempdir().expect("tempdir");
        for mask in [true, false] {
            let b = bundle(5, mask);
            b.save(dir.path()).expect("save");
            assert_eq!(ModelBundle::load(dir.path()).expect("load"), b);
        }
    }

    #[test]
    fn rejects_other_format_versions_and_bad_tensors() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut b = bundle(1, false);
        b.config.format_version = 9;
        b.save(dir.path()).expect("save");
        let msg = ModelBundle::load(dir.path())
            .expect_err("version")
            .to_string();
        assert!(msg.contains("format_version 9"), "{msg}");

        std::fs::write(dir.path().join(MODEL_FILE), b"not safetensors").expect("write");
        assert!(matches!(
            load_weights(&dir.path().join(MODEL_FILE)),
            Err(Error::SafeTensors { .. })
        ));
    }

    #[test]
    fn history_errors_name_the_line() {
        let e = parse_history(Path::new("h.csv"), &format!("{HISTORY_HEADER}\n1,2,3\n"))
            .expect_err("short line");
        assert!(e.to_string().starts_with("h.csv:2:"), "{e}");
    }
}
