//! The model bundle: a folder holding everything needed to use and reproduce a trained model.
//!
//! | file                | contents |
//! |---------------------|----------|
//! | `model.safetensors` | weights in PyTorch `nn.Linear` layout: `layers.{i}.weight` f32 `[out, in]` and `layers.{i}.bias` f32 `[out]` for `i = 0..4` (900-256-128-64-2, or 1800-256-128-64-2 for `stacked`); late fusion's under its branches' names (below); metadata `{"format": "pt"}` |
//! | `config.json`       | [`BundleConfig`]: format version, architecture, training config (with the seed), the [`Representation`] the features were built with (config, crop, how the samples were drawn), metrics |
//! | `mask.npy`          | optional no-contact mask, u8 `H x W` = the crop (absent when none was used) |
//! | `history.csv`       | one row per epoch: `epoch,train_loss,val_mae,val_mae_pitch,val_mae_roll,seconds` |
//!
//! In PyTorch the weights load into
//! `nn.Module` with `self.layers = nn.ModuleList([nn.Linear(900, 256), nn.Linear(256, 128),
//! nn.Linear(128, 64), nn.Linear(64, 2)])` (ReLU after all but the last; `nn.Linear(1800, 256)`
//! first for `stacked`) through `model.load_state_dict(safetensors.torch.load_file(path))`.
//!
//! A late-fusion model (`late`) is saved as the module that computes it, so that its state dict
//! loads the same way (the Python package ships it as `evtac.torch.LateFusion`):
//!
//! ```text
//! static_branch   nn.Linear(900, 128)    static_branch.weight [128, 900], static_branch.bias [128]
//! dynamic_branch  nn.Linear(900, 128)    dynamic_branch.weight, dynamic_branch.bias
//! head            nn.Sequential(nn.Linear(256, 128), nn.ReLU(), nn.Linear(128, 64), nn.ReLU(),
//!                               nn.Linear(64, 2))         head.0.*, head.2.*, head.4.*
//! forward(x):     x is [N, 1800], the static frame's 900 features then the dynamic frame's
//!     s = relu(static_branch(x[:, :900])); d = relu(dynamic_branch(x[:, 900:]))
//!     return head(torch.cat([s, d], dim=1))
//! ```
//!
//! The safetensors file depends only on the weights, so the same seed and data give the same
//! bytes; `history.csv` also records wall-clock times and differs between runs.
//!
//! Format 2 (written now) types `representation`. Format 1 bundles still load: their
//! `representation` was the writer's own JSON, either a bare representation config or
//! `{"config": ..., "frame": "240x240", "sampling": ..., "phases": ...}`; anything else is an
//! error that says which shapes are understood.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use evtac_events::output::write_atomic;
use ndarray::Array2;
use ndarray_npy::WriteNpyExt;
use safetensors::tensor::{Dtype, SafeTensors, TensorView};
use serde::{Deserialize, Serialize};

use evtac_repr::{CROP, Mask, ReprConfig};

use crate::architecture::{BRANCH, HIDDEN, INPUTS, MAX_INPUTS, OUTPUTS};
use crate::metrics::Mae;
use crate::model::{self, Architecture, LAYERS, LayerParameters, Parameters};
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
/// The bundle format written by this version.
pub const FORMAT_VERSION: u32 = 2;
/// The oldest bundle format this version still loads.
pub const OLDEST_FORMAT_VERSION: u32 = 1;
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
    #[error(
        "{path}: format_version {found} is not supported (this build reads \
         {OLDEST_FORMAT_VERSION} to {FORMAT_VERSION})"
    )]
    FormatVersion {
        /// The config file.
        path: PathBuf,
        /// The version found.
        found: u32,
    },
    /// `config.json`'s `representation` is not one this build understands.
    #[error(
        "{path}: `representation` is not an evtac representation (expected \
         {{\"config\": {{\"kind\": \"static\" | \"dynamic\" | \"combined\" | \"stacked\" | \"late\", ...}}, \
         \"frame\": \"240x240\"}}, or in format 1 a bare config): {reason}"
    )]
    Representation {
        /// The config file.
        path: PathBuf,
        /// Why it did not parse.
        reason: String,
    },
    /// The features were built on a crop other than the one evtac's 900 inputs come from.
    #[error("{path}: the model's features come from a {frame} crop; evtac's MLP takes {CROP}")]
    Frame {
        /// The config file.
        path: PathBuf,
        /// The crop the bundle names.
        frame: String,
    },
    /// `mask.npy` could not be read as a u8 2-D array of the crop's size.
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
    /// The weights are of another network than the representation needs (e.g. a late-fusion
    /// model's weights with a `stacked` representation).
    #[error(
        "{path}: the weights are a {} network but the representation `{kind}` needs {}",
        weights.describe(),
        needed.describe()
    )]
    Architecture {
        /// The bundle folder.
        path: PathBuf,
        /// The network the weights file holds.
        weights: Architecture,
        /// The representation's kind.
        kind: &'static str,
        /// The network it needs.
        needed: Architecture,
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

/// How many samples per trial the training set took from each phase (provenance: loading never
/// interprets it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SampleCounts {
    /// Points from each trial's motion phase.
    pub motion_points: usize,
    /// Points from each trial's stop phase (0: none).
    pub stop_points: usize,
}

/// What the model's inputs are (900 features, 1800 for `stacked` and `late`): everything needed
/// to compute the features again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Representation {
    /// The representation config.
    pub config: ReprConfig,
    /// The crop of the sensor the features are pooled from, centered (always [`CROP`]).
    #[serde(with = "resolution_text")]
    pub frame: evtac_events::Resolution,
    /// How the training samples were drawn, when the writer knows (provenance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling: Option<SampleCounts>,
    /// The trial phases trained on (`motion`, `stop`), when the writer knows (provenance).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<String>,
    /// The event filters the training recordings went through before the representation, as
    /// SPECs in order (`background-activity=10ms`); absent for unfiltered events, so bundles
    /// from before filters read the same. Features for this model must have gone through the
    /// same ([`crate::Model::feature_provenance`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filters: Vec<String>,
}

impl Representation {
    /// `config` on the paper's crop, with no provenance.
    pub fn new(config: ReprConfig) -> Self {
        Self {
            config,
            frame: CROP,
            sampling: None,
            phases: Vec::new(),
            filters: Vec::new(),
        }
    }
}

/// A resolution as `"240x240"`, the way people write it.
mod resolution_text {
    use evtac_events::Resolution;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(r: &Resolution, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(r)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Resolution, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// The contents of `config.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BundleConfig {
    /// Bundle format version ([`FORMAT_VERSION`] when written by this build).
    pub format_version: u32,
    /// Layer widths, input first, as stored (`[900, 256, 128, 64, 2]`, or 1800 inputs for
    /// `stacked` and `late`; informational: the network is the weights file's and the
    /// representation's, which must agree).
    pub architecture: Vec<usize>,
    /// The training recipe, including the seed.
    pub training: TrainConfig,
    /// What the inputs are.
    pub representation: Representation,
    /// Validation and evaluation results.
    pub metrics: BundleMetrics,
}

/// `config.json` with its representation in either shape it has had (which is allowed depends
/// on the version).
#[derive(Deserialize)]
struct RawConfig {
    format_version: u32,
    architecture: Vec<usize>,
    training: TrainConfig,
    #[serde(deserialize_with = "either_shape")]
    representation: Result<RawRepresentation, String>,
    metrics: BundleMetrics,
}

/// The representation as format 2 writes it, or a bare config (format 1 also wrote those: online
/// tests, hand-made bundles).
#[derive(Deserialize)]
#[serde(untagged)]
enum RawRepresentation {
    Typed(Representation),
    Bare(ReprConfig),
}

/// Reads the representation, keeping a shape that is neither as an error for
/// [`RawConfig::typed`] to name with the file (an untagged enum reads the whole value before
/// trying its shapes, so the rest of the file still parses).
fn either_shape<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Result<RawRepresentation, String>, D::Error> {
    Ok(RawRepresentation::deserialize(d)
        .map_err(|_| "neither the representation object nor a representation config".to_string()))
}

impl RawConfig {
    /// The typed config, reading format 1's representation shapes too.
    fn typed(self, path: &Path) -> Result<BundleConfig, Error> {
        let invalid = |reason: String| Error::Representation {
            path: path.to_path_buf(),
            reason,
        };
        let representation = match self.representation.map_err(invalid)? {
            RawRepresentation::Typed(r) => r,
            RawRepresentation::Bare(config) if self.format_version == 1 => {
                Representation::new(config)
            }
            RawRepresentation::Bare(_) => {
                return Err(invalid(format!(
                    "a bare config is format 1's; this file is format {}",
                    self.format_version
                )));
            }
        };
        if representation.frame != CROP {
            return Err(Error::Frame {
                path: path.to_path_buf(),
                frame: representation.frame.to_string(),
            });
        }
        Ok(BundleConfig {
            format_version: self.format_version,
            architecture: self.architecture,
            training: self.training,
            representation,
            metrics: self.metrics,
        })
    }
}

/// A trained model with its provenance (see the module docs for the folder layout).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelBundle {
    /// The weights.
    pub parameters: Parameters,
    /// The configuration and metrics.
    pub config: BundleConfig,
    /// The no-contact mask used by the representation, if any (the crop's size).
    pub mask: Option<Mask>,
    /// The training curve.
    pub history: Vec<EpochRecord>,
}

impl ModelBundle {
    /// A bundle from a training result, the config it was trained with, the representation
    /// and the mask.
    pub fn from_trained(
        trained: Trained,
        training: TrainConfig,
        representation: Representation,
        mask: Option<Mask>,
    ) -> Self {
        let architecture = trained.parameters.architecture.layer_sizes().to_vec();
        Self {
            parameters: trained.parameters,
            config: BundleConfig {
                format_version: FORMAT_VERSION,
                architecture,
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

    /// An untrained bundle: PyTorch's initial weights from `seed` for the representation's
    /// network, no training curve, zero metrics. For checking a pipeline end to end without
    /// training first (tests, benchmarks).
    pub fn untrained(seed: u64, representation: Representation, mask: Option<Mask>) -> Self {
        let zero = Mae {
            overall: 0.0,
            pitch: 0.0,
            roll: 0.0,
        };
        let architecture = Architecture::for_repr(&representation.config);
        let trained = Trained {
            parameters: Parameters::init_for(architecture, seed),
            best_epoch: 0,
            best_val: zero,
            history: Vec::new(),
        };
        let training = TrainConfig {
            seed,
            architecture,
            ..TrainConfig::default()
        };
        Self::from_trained(trained, training, representation, mask)
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
        write_atomic(&model_path, &bytes).map_err(io(&model_path))?;

        let config_path = dir.join(CONFIG_FILE);
        let mut json =
            serde_json::to_string_pretty(&self.config).map_err(|source| Error::Json {
                path: config_path.clone(),
                source,
            })?;
        json.push('\n');
        write_atomic(&config_path, json.as_bytes()).map_err(io(&config_path))?;

        let mask_path = dir.join(MASK_FILE);
        match &self.mask {
            Some(mask) => {
                let size = mask.resolution();
                let shape = (usize::from(size.height), usize::from(size.width));
                let array = Array2::from_shape_vec(shape, mask.pixels().to_vec())
                    .expect("a mask holds height x width pixels");
                let mut bytes = Vec::new();
                array.write_npy(&mut bytes).map_err(|e| Error::Mask {
                    path: mask_path.clone(),
                    message: e.to_string(),
                })?;
                write_atomic(&mask_path, &bytes).map_err(io(&mask_path))?
            }
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
        write_atomic(&history_path, csv.as_bytes()).map_err(io(&history_path))?;
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
        if !(OLDEST_FORMAT_VERSION..=FORMAT_VERSION).contains(&version.format_version) {
            return Err(Error::FormatVersion {
                path: config_path,
                found: version.format_version,
            });
        }
        let raw: RawConfig = serde_json::from_str(&text).map_err(|source| Error::Json {
            path: config_path.clone(),
            source,
        })?;
        let config = raw.typed(&config_path)?;
        let needed = Architecture::for_repr(&config.representation.config);
        let mut parameters = parameters;
        if !parameters.architecture.same_network(needed) {
            return Err(Error::Architecture {
                path: dir.to_path_buf(),
                weights: parameters.architecture,
                kind: config.representation.config.kind_name(),
                needed,
            });
        }
        // The file's weights do not tell a two-channel network from a stacked one.
        parameters.architecture = needed;

        let mask_path = dir.join(MASK_FILE);
        let mask = if mask_path.is_file() {
            Some(read_mask(&mask_path, config.representation.frame)?)
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

/// Reads `mask.npy` and checks that it covers `frame`.
fn read_mask(path: &Path, frame: evtac_events::Resolution) -> Result<Mask, Error> {
    let err = |message: String| Error::Mask {
        path: path.to_path_buf(),
        message,
    };
    let array = ndarray_npy::read_npy::<_, Array2<u8>>(path).map_err(|e| err(e.to_string()))?;
    let (height, width) = array.dim();
    if (width, height) != (usize::from(frame.width), usize::from(frame.height)) {
        return Err(err(format!(
            "the mask is {width}x{height} but the features' crop is {frame}"
        )));
    }
    let pixels: Vec<u8> = array.iter().copied().collect();
    Mask::from_pixels(frame, &pixels).map_err(|e| err(e.to_string()))
}

/// The linear layers of `architecture` as the safetensors file names them, input first, with
/// their `(in, out)` sizes: `layers.{i}` for the MLPs; for late fusion the two branches, then
/// the head (see the module docs).
fn linear_names(architecture: Architecture) -> Vec<(String, usize, usize)> {
    match architecture {
        Architecture::Mlp | Architecture::Stacked | Architecture::Channels(_) => {
            let sizes = architecture.layer_sizes();
            (0..LAYERS)
                .map(|i| (format!("layers.{i}"), sizes[i], sizes[i + 1]))
                .collect()
        }
        Architecture::Late => vec![
            ("static_branch".into(), INPUTS, BRANCH),
            ("dynamic_branch".into(), INPUTS, BRANCH),
            ("head.0".into(), HIDDEN[0], HIDDEN[1]),
            ("head.2".into(), HIDDEN[1], HIDDEN[2]),
            ("head.4".into(), HIDDEN[2], OUTPUTS),
        ],
    }
}

/// Reads and checks only the weights of `model.safetensors` (e.g. for prediction). The network
/// is the file's: late fusion by its branches' names, else the MLP whose first layer has the
/// file's input count (900 or 1800).
pub fn load_weights(path: &Path) -> Result<Parameters, Error> {
    let bytes = std::fs::read(path).map_err(io(path))?;
    let st = SafeTensors::deserialize(&bytes).map_err(|e| Error::SafeTensors {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let architecture = if st.tensor("static_branch.weight").is_ok() {
        Architecture::Late
    } else {
        match st.tensor("layers.0.weight").map(|v| v.shape().to_vec()) {
            Ok(shape) if shape == [HIDDEN[0], Architecture::Stacked.inputs()] => {
                Architecture::Stacked
            }
            // Three or more pooled frames: a real-valued kind's channels (two read as
            // `Stacked`, the same network).
            Ok(shape)
                if shape.len() == 2
                    && shape[0] == HIDDEN[0]
                    && shape[1].is_multiple_of(INPUTS)
                    && (3 * INPUTS..=MAX_INPUTS).contains(&shape[1]) =>
            {
                Architecture::Channels(shape[1] / INPUTS)
            }
            // Anything else is read as the paper's MLP, whose checks name what is wrong.
            _ => Architecture::Mlp,
        }
    };
    let read = |name: String, expected: Vec<usize>| -> Result<Vec<f32>, Error> {
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
    let mut linears = Vec::with_capacity(LAYERS + 1);
    for (name, fan_in, fan_out) in linear_names(architecture) {
        let weight = read(format!("{name}.weight"), vec![fan_out, fan_in])?;
        let bias = read(format!("{name}.bias"), vec![fan_out])?;
        linears.push(LayerParameters { weight, bias });
    }
    if architecture == Architecture::Late {
        let head = linears.split_off(2);
        let branches: [LayerParameters; 2] = [linears[0].clone(), linears[1].clone()];
        linears = std::iter::once(model::join_branches(&branches))
            .chain(head)
            .collect();
    }
    let parameters = Parameters {
        architecture,
        layers: linears,
    };
    parameters.validate().map_err(|source| Error::Model {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(parameters)
}

/// Serialises the weights as safetensors bytes (names and layout in the module docs).
fn weights_to_safetensors(params: &Parameters) -> Result<Vec<u8>, String> {
    let linears: Vec<LayerParameters> = match params.branches() {
        Some(branches) => branches
            .into_iter()
            .chain(params.layers[1..].iter().cloned())
            .collect(),
        None => params.layers.clone(),
    };
    let names = linear_names(params.architecture);
    let mut buffers: Vec<(String, Vec<usize>, Vec<u8>)> = Vec::with_capacity(2 * names.len());
    for ((name, fan_in, fan_out), layer) in names.into_iter().zip(&linears) {
        let le = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        buffers.push((
            format!("{name}.weight"),
            vec![fan_out, fan_in],
            le(&layer.weight),
        ));
        buffers.push((format!("{name}.bias"), vec![fan_out], le(&layer.bias)));
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
            validation_seconds: None,
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
                    validation_seconds: None,
                }],
            },
            TrainConfig {
                seed,
                ..TrainConfig::default()
            },
            Representation::new(ReprConfig::Static(Default::default())),
            mask.then(|| {
                let pixels: Vec<u8> = (0..CROP.pixels()).map(|i| u8::from(i % 7 == 0)).collect();
                Mask::from_pixels(CROP, &pixels).expect("the crop's size")
            }),
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

    /// The two-frame networks save under their names (late fusion as its branches and head),
    /// load back as the same weights, and a bundle whose weights are of another network than
    /// its representation's is refused, naming both.
    #[test]
    fn two_frame_networks_round_trip_and_must_match_the_representation() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (static_part, dynamic_part) = Default::default();
        let [stacked, late] = [evtac_repr::ReprKind::Stacked, evtac_repr::ReprKind::Late]
            .map(|k| k.config(static_part, dynamic_part));
        for config in [stacked, late] {
            let b = ModelBundle::untrained(3, Representation::new(config), None);
            assert_eq!(b.parameters.architecture, Architecture::for_repr(&config));
            b.save(dir.path()).expect("save");
            assert_eq!(ModelBundle::load(dir.path()).expect("load"), b);
        }
        let bytes = std::fs::read(dir.path().join(MODEL_FILE)).expect("read");
        let st = SafeTensors::deserialize(&bytes).expect("safetensors");
        let mut names: Vec<String> = st.names().into_iter().map(str::to_string).collect();
        names.sort();
        assert_eq!(
            names,
            [
                "dynamic_branch.bias",
                "dynamic_branch.weight",
                "head.0.bias",
                "head.0.weight",
                "head.2.bias",
                "head.2.weight",
                "head.4.bias",
                "head.4.weight",
                "static_branch.bias",
                "static_branch.weight",
            ]
        );
        assert_eq!(
            st.tensor("static_branch.weight").unwrap().shape(),
            [128, 900]
        );
        // Late weights with a stacked representation.
        with_config(
            dir.path(),
            FORMAT_VERSION,
            serde_json::to_value(Representation::new(stacked)).expect("json"),
        );
        let msg = ModelBundle::load(dir.path())
            .expect_err("mismatch")
            .to_string();
        assert!(
            msg.contains("2x(900-128)-256-128-64-2") && msg.contains("`stacked` needs 1800-256"),
            "{msg}"
        );
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

    /// Rewrites the saved `config.json`'s representation as `representation` and its version.
    fn with_config(dir: &Path, version: u32, representation: serde_json::Value) {
        let path = dir.join(CONFIG_FILE);
        let mut json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("json");
        json["format_version"] = version.into();
        json["representation"] = representation;
        std::fs::write(&path, json.to_string()).expect("write");
    }

    #[test]
    fn format_1_bundles_still_load() {
        let dir = tempfile::tempdir().expect("tempdir");
        let b = bundle(2, true);
        b.save(dir.path()).expect("save");
        let config =
            serde_json::json!({"kind": "dynamic", "window_ms": 640.0, "count_threshold": 0});
        // A bare config, as online tests and hand-made bundles wrote it.
        with_config(dir.path(), 1, config.clone());
        let loaded = ModelBundle::load(dir.path()).expect("bare config");
        let expected: ReprConfig = serde_json::from_value(config.clone()).expect("config");
        assert_eq!(loaded.config.representation, Representation::new(expected));
        assert_eq!(loaded.mask, b.mask);
        // The object evtac-experiments wrote.
        let wrapped = serde_json::json!({"config": config, "frame": "240x240",
            "sampling": {"motion_points": 50, "stop_points": 10}, "phases": ["motion", "stop"]});
        with_config(dir.path(), 1, wrapped);
        let r = ModelBundle::load(dir.path())
            .expect("wrapped")
            .config
            .representation;
        assert_eq!(r.config, expected);
        assert_eq!(r.sampling.map(|s| s.stop_points), Some(10));
        assert_eq!(r.phases, ["motion", "stop"]);
        // Format 2 does not take a bare config, and nothing takes another shape.
        with_config(dir.path(), 2, serde_json::json!({"kind": "dynamic"}));
        let e = ModelBundle::load(dir.path()).expect_err("bare in format 2");
        assert!(matches!(e, Error::Representation { .. }), "{e}");
        with_config(dir.path(), 1, serde_json::json!({"repr": "static"}));
        let e = ModelBundle::load(dir.path()).expect_err("unknown shape");
        assert!(
            e.to_string().contains("is not an evtac representation"),
            "{e}"
        );
    }

    #[test]
    fn another_crop_or_mask_size_is_an_error() {
        let dir = tempfile::tempdir().expect("tempdir");
        bundle(2, false).save(dir.path()).expect("save");
        let config =
            serde_json::json!({"kind": "dynamic", "window_ms": 640.0, "count_threshold": 0});
        with_config(
            dir.path(),
            2,
            serde_json::json!({"config": config, "frame": "320x240"}),
        );
        let e = ModelBundle::load(dir.path()).expect_err("frame");
        assert!(e.to_string().contains("320x240 crop"), "{e}");
        with_config(
            dir.path(),
            2,
            serde_json::json!({"config": config, "frame": "240x240"}),
        );
        ModelBundle::load(dir.path()).expect("the crop");
        let mask = Array2::<u8>::zeros((4, 3));
        ndarray_npy::write_npy(dir.path().join(MASK_FILE), &mask).expect("write mask");
        let e = ModelBundle::load(dir.path()).expect_err("mask size");
        assert!(e.to_string().contains("mask is 3x4"), "{e}");
    }

    #[test]
    fn history_errors_name_the_line() {
        let e = parse_history(Path::new("h.csv"), &format!("{HISTORY_HEADER}\n1,2,3\n"))
            .expect_err("short line");
        assert!(e.to_string().starts_with("h.csv:2:"), "{e}");
    }
}
