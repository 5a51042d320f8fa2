//! Labelling the trials of a dataset folder: read `trials.csv`, `calibration.json` and each
//! trial's recording, write `labels/<trial>.csv`, and check the labels against the commanded
//! stop angles and, where the simulator left one, the exact ground truth.

use evtac_events::layout::{CALIBRATION_FILE, LABELS_DIR};
use std::path::{Path, PathBuf};

use evtac_events::ImuSample;
use evtac_events::manifest::{Manifest, TrialMeta};
use serde::{Deserialize, Serialize};

use crate::bias::Bias;
use crate::commanded::label_commanded;
use crate::error::{Error, TrialError};
use crate::geometry::Calibration;
use crate::series::LabelSeries;
use crate::source::LabelSource;
use crate::trial::{LabelConfig, TrialLabels, TrialMotion, label_imu};
use crate::validation::{StopCheck, Summary, TruthError};

/// Where the labels of `trial` go: `<dataset_dir>/labels/<trial>.csv`.
pub fn labels_path(dataset_dir: impl AsRef<Path>, trial: &str) -> PathBuf {
    dataset_dir
        .as_ref()
        .join(LABELS_DIR)
        .join(format!("{trial}.csv"))
}

pub use crate::error::IDENTITY_CALIBRATION_FLAG;

/// Where a dataset's IMU-to-sensor rotation comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CalibrationSource {
    /// The dataset's `calibration.json`, which must exist.
    File,
    /// [`Calibration::default`] (the identity rotation), asked for explicitly: a real sensor
    /// whose IMU is not aligned with the dome would otherwise get wrong labels without a word.
    Identity,
}

/// The calibration of the dataset in `dataset_dir` from `source`: [`read_calibration`] or the
/// identity. A dataset labelled from the commanded motion needs none (the calibration rotates
/// the IMU's rates into the sensor's frame, and its labels use no IMU): the identity, whatever
/// `source` says.
pub fn dataset_calibration(
    dataset_dir: impl AsRef<Path>,
    source: CalibrationSource,
) -> Result<Calibration, Error> {
    if LabelSource::of(&dataset_dir)? == LabelSource::Commanded {
        return Ok(Calibration::default());
    }
    match source {
        CalibrationSource::File => read_calibration(dataset_dir),
        CalibrationSource::Identity => Ok(Calibration::default()),
    }
}

/// Reads `<dataset_dir>/calibration.json`; a missing file is [`Error::MissingCalibration`].
pub fn read_calibration(dataset_dir: impl AsRef<Path>) -> Result<Calibration, Error> {
    read_calibration_file(&dataset_dir.as_ref().join(CALIBRATION_FILE))
}

/// Reads and checks the calibration file at `path` (a `calibration.json` anywhere, e.g. the
/// one `evtac import --calibration` is given).
pub fn read_calibration_file(path: &Path) -> Result<Calibration, Error> {
    let path = path.to_path_buf();
    let bad = |message: String| Error::Calibration {
        path: path.clone(),
        message,
    };
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(Error::MissingCalibration { path });
        }
        Err(e) => return Err(bad(e.to_string())),
    };
    let calibration: Calibration = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let m = calibration.imu_to_sensor;
    // A rotation's rows are orthonormal; anything else would silently scale the gyroscope.
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| m[i][k] * m[j][k]).sum();
            let want = if i == j { 1.0 } else { 0.0 };
            // Written so that NaN fails too.
            let ok = (dot - want).abs() < 1e-6;
            if !ok {
                return Err(bad(format!(
                    "imu_to_sensor is not a rotation: rows {i} and {j} have dot product {dot}, \
                     expected {want}"
                )));
            }
        }
    }
    Ok(calibration)
}

/// Labels the trial `meta` as its dataset's [`LabelSource`] says: reads its recording's IMU and
/// labels it (see [`label_imu`]), or takes the commanded motion ([`label_commanded`]; no
/// recording read, no bias, scale 1, no stop check).
pub fn label_trial(
    dataset_dir: impl AsRef<Path>,
    meta: &TrialMeta,
    calibration: &Calibration,
    config: &LabelConfig,
) -> Result<TrialLabels, Error> {
    let wrap = |kind: TrialError| Error::trial(&meta.trial, kind);
    let motion = TrialMotion::from_meta(meta).map_err(wrap)?;
    if LabelSource::of(&dataset_dir)? == LabelSource::Commanded {
        return Ok(TrialLabels {
            labels: label_commanded(&motion),
            bias: Bias::default(),
            scale_factor: 1.0,
            final_error_deg: 0.0,
            stop: None,
        });
    }
    let path = dataset_dir.as_ref().join(&meta.file);
    let imu = read_imu(&path).map_err(|e| {
        wrap(TrialError::Read {
            path: path.clone(),
            message: e.to_string(),
        })
    })?;
    label_imu(&imu, &motion, calibration, config).map_err(wrap)
}

/// Reads only the IMU stream of the recording at `path`: the events, which can run to hundreds
/// of megabytes, are decoded chunk by chunk and dropped.
pub fn read_imu(path: &Path) -> Result<Vec<ImuSample>, evtac_formats::Error> {
    let mut reader = evtac_formats::open(path)?;
    let mut imu = Vec::new();
    while let Some(chunk) = reader.next_chunk()? {
        imu.extend_from_slice(chunk.imu);
    }
    Ok(imu)
}

/// What labelling one trial found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialReport {
    /// The trial's name.
    pub trial: String,
    /// The labels file written, relative to the dataset folder.
    pub labels_file: PathBuf,
    /// Label samples (IMU samples).
    pub samples: usize,
    /// The axial gyroscope bias removed, deg/s.
    pub bias_deg_s: f64,
    /// The gyroscope's noise over the stationary segment (standard deviation), deg/s.
    pub gyro_noise_deg_s: f64,
    /// The scale factor applied.
    pub scale_factor: f64,
    /// Labelled final tilt minus the commanded one, degrees.
    pub final_error_deg: f64,
    /// The stop check (trials with a stop).
    pub stop: Option<StopCheck>,
    /// Errors against the ground truth (trials with a `truth` file).
    pub truth: Option<TruthError>,
}

/// Labels the trial `meta`, writes `labels/<trial>.csv` and compares the labels with the trial's
/// ground truth when the manifest names one.
pub fn label_and_write(
    dataset_dir: impl AsRef<Path>,
    meta: &TrialMeta,
    calibration: &Calibration,
    config: &LabelConfig,
) -> Result<TrialReport, Error> {
    let dir = dataset_dir.as_ref();
    let labels = label_trial(dir, meta, calibration, config)?;
    let wrap = |kind: TrialError| Error::trial(&meta.trial, kind);
    let labels_file = Path::new(LABELS_DIR).join(format!("{}.csv", meta.trial));
    labels
        .labels
        .write_csv(dir.join(&labels_file))
        .map_err(|e| wrap(e.into()))?;
    let truth = match &meta.truth {
        Some(file) => {
            let truth = LabelSeries::read_csv(dir.join(file)).map_err(|e| wrap(e.into()))?;
            TruthError::compare(&labels.labels, &truth)
        }
        None => None,
    };
    Ok(TrialReport {
        trial: meta.trial.clone(),
        labels_file,
        samples: labels.labels.len(),
        bias_deg_s: labels.bias.rate_deg_s,
        gyro_noise_deg_s: labels.bias.noise_deg_s,
        scale_factor: labels.scale_factor,
        final_error_deg: labels.final_error_deg,
        stop: labels.stop,
        truth,
    })
}

/// What labelling a dataset found: every trial's report and the summaries over them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetLabels {
    /// One report per trial, in manifest order.
    pub trials: Vec<TrialReport>,
    /// Stop errors (measured minus commanded, degrees) over the trials with a stop; the paper
    /// reports -0.01 +- 0.04 deg.
    pub stop_error_deg: Option<Summary>,
    /// Per-trial RMS error against ground truth over both contact angles, degrees.
    pub truth_rms_deg: Option<Summary>,
    /// Scale factors over all trials.
    pub scale_factor: Option<Summary>,
}

impl DatasetLabels {
    /// Summarises trial reports.
    pub fn from_reports(trials: Vec<TrialReport>) -> Self {
        let stops: Vec<f64> = trials
            .iter()
            .filter_map(|r| r.stop.map(|s| s.error_deg))
            .collect();
        let rms: Vec<f64> = trials
            .iter()
            .filter_map(|r| r.truth.map(|t| t.rms_deg))
            .collect();
        let scales: Vec<f64> = trials.iter().map(|r| r.scale_factor).collect();
        Self {
            stop_error_deg: Summary::of(&stops),
            truth_rms_deg: Summary::of(&rms),
            scale_factor: Summary::of(&scales),
            trials,
        }
    }
}

/// Labels every trial of the dataset in `dataset_dir` (in manifest order), writing
/// `labels/<trial>.csv` for each; `on_trial` sees each report as it is made. Stops at the first
/// trial that fails, naming it.
pub fn label_dataset(
    dataset_dir: impl AsRef<Path>,
    config: &LabelConfig,
    mut on_trial: impl FnMut(&TrialReport),
) -> Result<DatasetLabels, Error> {
    let dir = dataset_dir.as_ref();
    let manifest = Manifest::read(dir)?;
    let calibration = read_calibration(dir)?;
    let mut reports = Vec::with_capacity(manifest.trials.len());
    for meta in &manifest.trials {
        let report = label_and_write(dir, meta, &calibration, config)?;
        on_trial(&report);
        reports.push(report);
    }
    Ok(DatasetLabels::from_reports(reports))
}
