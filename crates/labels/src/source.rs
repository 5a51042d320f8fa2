//! Where a dataset's labels come from: the IMU (the paper's way, and the default) or the robot's
//! commanded motion ([`crate::commanded`]), for recordings that hold no IMU (the NeuroTac lab's
//! pickles, HDF5, NPY, NPZ and CSV files).
//!
//! The choice belongs to the dataset, not to a command: `evtac import --labels commanded`
//! writes it to `label_source.json` beside `trials.csv`, and every command that labels the
//! dataset ([`crate::label_trial`]: `labels`, `check`, `train`, `reproduce`, the Python
//! package) reads it there, so no two commands label one dataset two ways. A dataset without
//! the file is labelled from the IMU, as every dataset was before the choice existed.

use std::path::{Path, PathBuf};

use evtac_events::layout::LABEL_SOURCE_FILE;
use serde::{Deserialize, Serialize};

use crate::error::Error;

/// Where the labels of a dataset come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LabelSource {
    /// The gyroscope, integrated and scaled onto the commanded total ([`crate::label_imu`]).
    #[default]
    Imu,
    /// The commanded motion itself, from the log's times ([`crate::commanded`]): no IMU needed,
    /// but nothing measured either (the stop check is not made).
    Commanded,
}

/// The file's content: one key, so that it can grow without breaking old datasets.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SourceFile {
    labels: LabelSource,
}

impl LabelSource {
    /// The label source of the dataset in `dataset_dir`: its `label_source.json`, or
    /// [`LabelSource::Imu`] when there is none.
    pub fn of(dataset_dir: impl AsRef<Path>) -> Result<Self, Error> {
        let path = Self::path(dataset_dir);
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Self::Imu),
            Err(e) => return Err(bad(path, e.to_string())),
        };
        serde_json::from_str::<SourceFile>(&text)
            .map(|f| f.labels)
            .map_err(|e| {
                bad(
                    path,
                    format!(
                        "{e} (expected {{\"labels\": \"imu\"}} or {{\"labels\": \"commanded\"}})"
                    ),
                )
            })
    }

    /// Writes this source into the dataset folder `dataset_dir`.
    pub fn write(self, dataset_dir: impl AsRef<Path>) -> Result<(), Error> {
        let path = Self::path(dataset_dir);
        let text = serde_json::to_string_pretty(&SourceFile { labels: self })
            .expect("a one-key object serialises");
        std::fs::write(&path, text + "\n").map_err(|e| bad(path, e.to_string()))
    }

    /// `label_source.json` in `dataset_dir`.
    pub fn path(dataset_dir: impl AsRef<Path>) -> PathBuf {
        dataset_dir.as_ref().join(LABEL_SOURCE_FILE)
    }
}

fn bad(path: PathBuf, message: String) -> Error {
    Error::LabelSource { path, message }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dataset_without_the_file_is_labelled_from_the_imu() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(LabelSource::of(dir.path()).unwrap(), LabelSource::Imu);
        LabelSource::Commanded.write(dir.path()).unwrap();
        assert_eq!(LabelSource::of(dir.path()).unwrap(), LabelSource::Commanded);
        let text = std::fs::read_to_string(LabelSource::path(dir.path())).unwrap();
        assert!(text.contains("\"labels\": \"commanded\""), "{text}");
    }

    #[test]
    fn an_unknown_source_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(LabelSource::path(dir.path()), r#"{"labels": "robot"}"#).unwrap();
        let err = LabelSource::of(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("label_source.json") && err.contains("commanded"),
            "{err}"
        );
    }
}
