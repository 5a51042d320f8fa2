//! A dataset folder: `trials.csv` (the manifest), the trial recordings, `calibration.json`,
//! `no_contact.aedat4` (for the static representation's mask), and what evtac adds to it:
//! `labels/<trial>.csv` (computed from the IMU when missing), `splits.json` and `cache/`.
//! Opening one takes the [`Inputs`] to use: a missing calibration or no-contact recording is an
//! error unless they opt out of it.

use crate::sampling::{SampleTime, Sampling};
use crate::splits::{self, Splits, Stratum};
use evtac_events::IoError;
use evtac_events::layout::{LABELS_DIR, NO_CONTACT_FILE, SIMULATOR_FILE};
use evtac_events::manifest::{Manifest, TrialMeta};
use evtac_events::output::write_atomic;
use evtac_events::{Event, Resolution, Roi};
use evtac_filters::FilterSpec;
use evtac_import::inputs::{Inputs, MaskSource, NO_MASK_FLAG};
use evtac_labels::geometry::Calibration;
use evtac_labels::{LabelConfig, LabelSeries, LabelSource};
use evtac_repr::{CROP, Mask, ReprConfig};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Errors opening or reading a dataset.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// `trials.csv` could not be read.
    #[error(transparent)]
    Manifest(#[from] evtac_events::manifest::ManifestError),
    /// A file could not be read or written.
    #[error(transparent)]
    Io(#[from] IoError),
    /// `calibration.json` is missing or not a calibration, or `label_source.json` does not
    /// read.
    #[error(transparent)]
    Calibration(evtac_labels::Error),
    /// `no_contact.aedat4` is missing and the mask was not opted out of.
    #[error(
        "{path} is missing: add a recording without contact there (for the static \
         representation's mask), or pass --{NO_MASK_FLAG} to run without a mask"
    )]
    MissingNoContact {
        /// The file that is missing.
        path: PathBuf,
    },
    /// A recording could not be decoded.
    #[error("{path}: {source}")]
    Recording {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: evtac_formats::Error,
    },
    /// A recording is smaller than the 240 x 240 crop.
    #[error("{path}: sensor {sensor} is smaller than the {CROP} crop")]
    SensorTooSmall {
        /// The file.
        path: PathBuf,
        /// The sensor's resolution.
        sensor: Resolution,
    },
    /// Labels could not be computed or read.
    #[error("labels of trial `{trial}`: {message}")]
    Labels {
        /// The trial.
        trial: String,
        /// What went wrong.
        message: String,
    },
    /// The splits file is broken or does not match the manifest.
    #[error(transparent)]
    Splits(#[from] splits::Error),
    /// A recording's events could not go through the dataset's filters (a SPEC that does not
    /// fit its sensor, `hot-pixels=auto` with nothing to learn from).
    #[error(transparent)]
    Filter(evtac_import::sensor_stats::StatsError),
    /// The mask could not be built.
    #[error("{path}: mask: {source}")]
    Mask {
        /// The no-contact file.
        path: PathBuf,
        /// The cause.
        source: evtac_repr::ReprError,
    },
    /// `simulator.json` is not a simulator record (protocol, scale, seed, params).
    #[error("{path}: not a simulator record: {source}")]
    Simulator {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: serde_json::Error,
    },
    /// A trial name is not in the manifest.
    #[error("{dir}: no trial `{trial}` in trials.csv")]
    UnknownTrial {
        /// The dataset folder.
        dir: PathBuf,
        /// The name.
        trial: String,
    },
}

/// What `simulator.json` says about a simulated dataset (the fields evtac reads back).
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct Simulated {
    /// The protocol simulated.
    pub protocol: evtac_sim::Protocol,
    /// Its scale.
    pub scale: evtac_sim::Scale,
    /// The dataset seed.
    pub seed: u64,
    /// Every simulator parameter.
    pub params: evtac_sim::SimParams,
    /// Passes over the conditions (absent from older files: the scale's).
    #[serde(default)]
    pub repeats: Option<usize>,
}

impl Simulated {
    /// The configuration that simulates this dataset again with seed `seed`: the same
    /// protocol, scale, repeats and parameters.
    pub fn config(&self, seed: u64) -> evtac_sim::DatasetConfig {
        evtac_sim::DatasetConfig {
            params: self.params.clone(),
            repeats: self.repeats,
            ..evtac_sim::DatasetConfig::new(self.protocol, self.scale, seed)
        }
    }
}

/// An opened dataset folder.
#[derive(Debug, Clone)]
pub struct Dataset {
    /// The folder.
    pub dir: PathBuf,
    /// Its trials.
    pub manifest: Manifest,
    /// Its sensor calibration (`calibration.json`, or the identity when opted out).
    pub calibration: Calibration,
    /// Where the calibration and the mask come from.
    pub inputs: Inputs,
    /// Where its labels come from (`label_source.json`: the IMU unless it says otherwise).
    pub label_source: LabelSource,
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::Io(IoError::at(path)(e))
}

/// Reads a recording's events (any format evtac reads) on the full sensor, with the sensor's resolution (the
/// crop size when the header has none, i.e. the recording is taken as already cropped).
pub fn read_full(path: &Path) -> Result<(Resolution, Vec<Event>), Error> {
    let rec = evtac_formats::read_recording(path).map_err(|source| Error::Recording {
        path: path.to_path_buf(),
        source,
    })?;
    Ok((rec.resolution.unwrap_or(CROP), rec.events))
}

/// The centered [`CROP`] crop of `sensor`.
fn crop_of(sensor: Resolution, path: &Path) -> Result<Roi, Error> {
    evtac_repr::centered_crop(sensor).map_err(|_| Error::SensorTooSmall {
        path: path.to_path_buf(),
        sensor,
    })
}

/// Reads a recording's events, cropped to the centered [`CROP`], in time order.
pub fn read_cropped(path: &Path) -> Result<Vec<Event>, Error> {
    Ok(read_in_crop(path, &[])?.1)
}

/// [`read_cropped`] of the recording's events through `filters` on the full sensor, before the
/// crop (so a region, a circle or a neighbourhood means on the sensor what it means in
/// `evtac filter`).
pub fn read_filtered_cropped(path: &Path, filters: &[FilterSpec]) -> Result<Vec<Event>, Error> {
    Ok(read_in_crop(path, filters)?.1)
}

/// A recording's centered [`CROP`] on its sensor, and its events through `filters`, cropped
/// to it.
fn read_in_crop(path: &Path, filters: &[FilterSpec]) -> Result<(Roi, Vec<Event>), Error> {
    let (sensor, events) = read_full(path)?;
    let roi = crop_of(sensor, path)?;
    let (events, _, _) = evtac_import::filtering::filter_events(path, sensor, filters, events)
        .map_err(Error::Filter)?;
    let mut cropped = Vec::with_capacity(events.len());
    roi.crop_into(&events, &mut cropped);
    Ok((roi, cropped))
}

/// A dataset's no-contact recording, read and cropped once for every config's mask.
#[derive(Debug, Clone, PartialEq)]
pub struct NoContact {
    /// The crop of the sensor the events were cut to (what `Mask::from_recording` cuts).
    pub roi: Roi,
    /// The events in the crop, crop coordinates, time order: the background the
    /// representations see.
    pub cropped: Vec<Event>,
}

impl Dataset {
    /// Opens the dataset at `dir` with `inputs`: reads `trials.csv` and the calibration, and
    /// checks that `no_contact.aedat4` exists when the mask is built from it.
    pub fn open(dir: &Path, inputs: Inputs) -> Result<Dataset, Error> {
        let manifest = Manifest::read(dir)?;
        let calibration = evtac_labels::dataset_calibration(dir, inputs.calibration)
            .map_err(Error::Calibration)?;
        let label_source = LabelSource::of(dir).map_err(Error::Calibration)?;
        let no_contact = dir.join(NO_CONTACT_FILE);
        if inputs.mask == MaskSource::NoContact && !no_contact.is_file() {
            return Err(Error::MissingNoContact { path: no_contact });
        }
        Ok(Dataset {
            dir: dir.to_path_buf(),
            manifest,
            calibration,
            inputs,
            label_source,
        })
    }

    /// The trial called `name`.
    pub fn trial(&self, name: &str) -> Result<&TrialMeta, Error> {
        self.manifest.get(name).ok_or_else(|| Error::UnknownTrial {
            dir: self.dir.clone(),
            trial: name.to_string(),
        })
    }

    /// The trials called `names`, in that order.
    pub fn trials(&self, names: &[String]) -> Result<Vec<&TrialMeta>, Error> {
        names.iter().map(|n| self.trial(n)).collect()
    }

    /// Every trial's conditions, for splitting.
    pub fn strata(&self) -> Vec<Stratum> {
        Stratum::of_manifest(&self.manifest)
    }

    /// The dataset's splits: `splits.json`, made (with `seed`) and written when missing.
    pub fn splits(&self, seed: u64) -> Result<Splits, Error> {
        Ok(Splits::read_or_make(&self.dir, &self.strata(), seed)?)
    }

    /// Whether any trial has a stop phase.
    pub fn has_stops(&self) -> bool {
        self.manifest
            .trials
            .iter()
            .any(|t| t.stop_start_us.is_some() && t.stop_end_us.is_some())
    }

    /// How the simulator made the dataset (`simulator.json`), or `None` for recorded data (no
    /// such file).
    pub fn simulator(&self) -> Result<Option<Simulated>, Error> {
        let path = self.dir.join(SIMULATOR_FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(io_err(&path)(e)),
        };
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|source| Error::Simulator { path, source })
    }

    /// The labels file of `trial`.
    pub fn labels_path(&self, trial: &str) -> PathBuf {
        self.dir.join(LABELS_DIR).join(format!("{trial}.csv"))
    }

    /// The file beside `labels/<trial>.csv` that says what the labels were computed with.
    pub fn labels_key_path(&self, trial: &str) -> PathBuf {
        self.dir.join(LABELS_DIR).join(format!("{trial}.key.json"))
    }

    /// A short name for what labels depend on (the first 12 hex digits of the SHA-256 of the
    /// calibration and the label settings), for caches that hold labels.
    pub fn labels_id(&self) -> String {
        let digest = Sha256::digest(self.labels_key().as_bytes());
        digest[..6].iter().map(|b| format!("{b:02x}")).collect()
    }

    /// What labels depend on besides the trial: the calibration this dataset was opened with
    /// (the file's, or the identity when opted out) and the label settings; and for labels from
    /// the commanded motion, that source (named only then, so that the IMU labels of every
    /// dataset written before the choice existed keep their key and their cache).
    fn labels_key(&self) -> String {
        let mut key = serde_json::json!({
            "calibration": self.calibration,
            "config": LabelConfig::default(),
        });
        if self.label_source != LabelSource::Imu {
            key["source"] = serde_json::json!(self.label_source);
        }
        key.to_string()
    }

    /// The labels of `meta`: `labels/<trial>.csv` when `labels/<trial>.key.json` says it was
    /// computed with this calibration and these settings; otherwise computed from the trial's
    /// IMU and written, with its key (labels from another calibration, or from `evtac labels`
    /// without a key, are never taken for these).
    pub fn labels(&self, meta: &TrialMeta) -> Result<LabelSeries, Error> {
        let path = self.labels_path(&meta.trial);
        let key_path = self.labels_key_path(&meta.trial);
        let key = self.labels_key();
        let lab = |message: String| Error::Labels {
            trial: meta.trial.clone(),
            message,
        };
        let cached = std::fs::read_to_string(&key_path).is_ok_and(|k| k == key) && path.is_file();
        if !cached {
            let labels = self.compute_labels(meta)?;
            std::fs::create_dir_all(self.dir.join(LABELS_DIR)).map_err(io_err(&path))?;
            // The labels first, then their key: a crash between the two leaves labels without
            // their key, which are computed again.
            let tmp = crate::jobs::tmp_path(&path);
            labels
                .labels
                .write_csv(&tmp)
                .map_err(|e| lab(e.to_string()))?;
            std::fs::rename(&tmp, &path).map_err(io_err(&path))?;
            // In the labels folder, made above.
            write_atomic(&key_path, key.as_bytes()).map_err(io_err(&key_path))?;
            return Ok(labels.labels);
        }
        LabelSeries::read_csv(&path).map_err(|e| lab(e.to_string()))
    }

    /// Labels `meta` from its recording's IMU stream with the default label settings (what
    /// `evtac labels` does for one trial).
    fn compute_labels(&self, meta: &TrialMeta) -> Result<evtac_labels::TrialLabels, Error> {
        evtac_labels::label_trial(&self.dir, meta, &self.calibration, &LabelConfig::default())
            .map_err(|e| Error::Labels {
                trial: meta.trial.clone(),
                message: e.to_string(),
            })
    }

    /// The sample times of `meta` under `sampling`.
    pub fn sample_times(&self, meta: &TrialMeta, sampling: Sampling) -> Vec<SampleTime> {
        let stop = meta.stop_start_us.zip(meta.stop_end_us);
        sampling.times((meta.motion_start_us, meta.motion_end_us), stop)
    }

    /// The events of `meta`'s recording through the dataset's filters, cropped to [`CROP`].
    pub fn events(&self, meta: &TrialMeta) -> Result<Vec<Event>, Error> {
        read_filtered_cropped(&self.dir.join(&meta.file), &self.inputs.filters)
    }

    /// The no-contact recording, or `None` when the dataset was opened without a mask.
    pub fn no_contact(&self) -> Result<Option<NoContact>, Error> {
        if self.inputs.mask == MaskSource::Unmasked {
            return Ok(None);
        }
        let (roi, cropped) = read_in_crop(&self.dir.join(NO_CONTACT_FILE), &self.inputs.filters)?;
        Ok(Some(NoContact { roi, cropped }))
    }

    /// The no-contact mask for `config` (built with its static part's settings: evtac's choice,
    /// the paper does not say which settings its no-contact frame used), or `None` for a dynamic
    /// config or a dataset opened without a mask.
    pub fn mask_for(
        &self,
        config: &ReprConfig,
        no_contact: Option<&NoContact>,
    ) -> Result<Option<Mask>, Error> {
        let (Some(s), Some(no_contact)) = (config.static_part(), no_contact) else {
            return Ok(None);
        };
        // Cropped once for every config (`Mask::from_recording` would crop again each time).
        Mask::from_no_contact(no_contact.roi.size, s, &no_contact.cropped)
            .map(Some)
            .map_err(|source| Error::Mask {
                path: self.dir.join(NO_CONTACT_FILE),
                source,
            })
    }
}

/// A short identity of a mask for cache keys: `nomask` or the first 12 hex digits of the
/// SHA-256 of its pixels.
pub fn mask_id(mask: Option<&Mask>) -> String {
    match mask {
        None => "nomask".to_string(),
        Some(m) => {
            let digest = Sha256::digest(m.pixels());
            let hex: String = digest.iter().take(6).map(|b| format!("{b:02x}")).collect();
            format!("mask{hex}")
        }
    }
}

/// A short identity of the filters for cache keys: `None` without filters (so the keys of
/// unfiltered features are what they were before filters existed), else `f` and the first 12
/// hex digits of the SHA-256 of the SPECs in order and of every mask file they read, so that
/// editing a mask in place never reuses features made with the old one.
pub fn filters_id(filters: &[FilterSpec]) -> Option<String> {
    if filters.is_empty() {
        return None;
    }
    let mut hasher = Sha256::new();
    for spec in filters {
        hasher.update(spec.to_string().as_bytes());
        hasher.update(b"\n");
        if let FilterSpec::Mask { path } | FilterSpec::HotPixels { path } = spec {
            // A file that cannot be read fails when the filter is built, before any feature.
            hasher.update(std::fs::read(path).unwrap_or_default());
        }
    }
    let hex: String = hasher
        .finalize()
        .iter()
        .take(6)
        .map(|b| format!("{b:02x}"))
        .collect();
    Some(format!("f{hex}"))
}
