//! Datasets: `simulate` (a protocol into a dataset folder, as `evtac simulate`), `labels` (every
//! trial's labels written to `labels/`, as `evtac labels`) and `label_trial` (one trial's labels
//! in memory), and `dataset_features` (a dataset's features and labels through its feature
//! cache, as training reads them: what `evtac.torch.FeatureDataset` serves). Label settings come as a JSON object of `evtac_labels::LabelConfig` fields;
//! unset fields keep their defaults, as with `evtac labels --config`.

use std::path::PathBuf;

use evtac_events::manifest::Manifest;
use evtac_experiments::cache::FeatureCache;
use evtac_experiments::dataset::Dataset;
use evtac_experiments::sampling::{Phase, Sampling};
use evtac_import::inputs::Inputs;
use evtac_labels::dataset::{DatasetLabels, label_and_write};
use evtac_labels::{LabelConfig, read_calibration};
use evtac_repr::CROP;
use evtac_sim::{DatasetConfig, Protocol, Scale, SimParams, simulate_dataset};
use ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::error;
use crate::representation::Representation;

/// Simulates `protocol` at `scale` with `seed` into the folder `out`; returns the number of
/// trials written.
#[pyfunction]
#[pyo3(signature = (protocol, out, scale = "small", seed = 0, limit = None, params_json = None))]
pub fn simulate(
    py: Python<'_>,
    protocol: &str,
    out: PathBuf,
    scale: &str,
    seed: u64,
    limit: Option<usize>,
    params_json: Option<&str>,
) -> PyResult<usize> {
    let protocol: Protocol = protocol.parse().map_err(error::value)?;
    let scale: Scale = scale.parse().map_err(error::value)?;
    let params = match params_json {
        Some(text) => serde_json::from_str::<SimParams>(text)
            .map_err(|e| error::value(format!("simulator parameters: {e}")))?,
        None => SimParams::default(),
    };
    let config = DatasetConfig {
        params,
        limit,
        ..DatasetConfig::new(protocol, scale, seed)
    };
    let manifest = py
        .detach(|| simulate_dataset(&config, &out, |_| {}))
        .map_err(error::file)?;
    Ok(manifest.trials.len())
}

fn label_config(config_json: &str) -> PyResult<LabelConfig> {
    serde_json::from_str(config_json).map_err(|e| error::value(format!("label settings: {e}")))
}

/// Labels every trial of the dataset in `dataset_dir` (writing `labels/<trial>.csv`) and
/// returns the summary `evtac labels --json` prints, as JSON text.
#[pyfunction]
#[pyo3(signature = (dataset_dir, config_json = "{}"))]
pub fn labels(py: Python<'_>, dataset_dir: PathBuf, config_json: &str) -> PyResult<String> {
    let config = label_config(config_json)?;
    py.detach(|| {
        let dir = &dataset_dir;
        let manifest = Manifest::read(dir).map_err(error::file)?;
        let calibration = read_calibration(dir).map_err(error::file)?;
        if manifest.trials.is_empty() {
            return Err(error::file(format!(
                "{} lists no trials",
                Manifest::path(dir).display()
            )));
        }
        // As the CLI: trials in parallel, reports in manifest order.
        let reports = manifest
            .trials
            .par_iter()
            .map(|meta| label_and_write(dir, meta, &calibration, &config))
            .collect::<Result<Vec<_>, _>>()
            .map_err(error::file)?;
        serde_json::to_string(&DatasetLabels::from_reports(reports)).map_err(error::value)
    })
}

/// The labels of one trial: `t_us`, `theta_deg`, `pitch_deg`, `roll_deg` arrays.
type LabelArrays<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// Labels the trial named `trial` of the dataset in `dataset_dir`, in memory.
#[pyfunction]
#[pyo3(signature = (dataset_dir, trial, config_json = "{}"))]
pub fn label_trial<'py>(
    py: Python<'py>,
    dataset_dir: PathBuf,
    trial: &str,
    config_json: &str,
) -> PyResult<LabelArrays<'py>> {
    let config = label_config(config_json)?;
    let labels = py.detach(|| {
        let dir = &dataset_dir;
        let manifest = Manifest::read(dir).map_err(error::file)?;
        let Some(meta) = manifest.trials.iter().find(|m| m.trial == trial) else {
            return Err(error::value(format!(
                "{} has no trial `{trial}` ({} trials)",
                Manifest::path(dir).display(),
                manifest.trials.len()
            )));
        };
        let calibration = read_calibration(dir).map_err(error::file)?;
        evtac_labels::label_trial(dir, meta, &calibration, &config).map_err(error::file)
    })?;
    let s = labels.labels;
    Ok((
        s.t_us.into_pyarray(py),
        s.theta_deg.into_pyarray(py),
        s.pitch_deg.into_pyarray(py),
        s.roll_deg.into_pyarray(py),
    ))
}

/// Features, labels and per-sample meta of a dataset's trials, as training sees them.
type FeatureArrays<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<bool>>,
    Vec<String>,
);

/// The features (N x 900) and labels (N x 2: pitch, roll) of `trials` (default: all, in
/// manifest order) of the dataset in `dataset_dir` for `representation`'s config, through the
/// dataset's feature cache as `evtac train` reads them (computed and cached when missing; the
/// mask comes from the dataset's `no_contact.aedat4` and the labels use its `calibration.json`,
/// both required). Also returns, per sample, the index of
/// its trial in the returned names, its time, and whether it is a stop-phase sample.
#[pyfunction]
#[pyo3(signature = (dataset_dir, representation, trials = None, motion_points = 50, stop_points = 10))]
pub fn dataset_features<'py>(
    py: Python<'py>,
    dataset_dir: PathBuf,
    representation: &Representation,
    trials: Option<Vec<String>>,
    motion_points: usize,
    stop_points: usize,
) -> PyResult<FeatureArrays<'py>> {
    if !representation.on_crop() {
        return Err(error::value(format!(
            "dataset features come from the {CROP} crop; this representation's crop differs"
        )));
    }
    if representation.mask_ref().is_some() {
        return Err(error::value(
            "a dataset's mask comes from its no_contact.aedat4: give a representation without one",
        ));
    }
    let config = representation.config();
    let sampling = Sampling {
        motion_points,
        stop_points,
    };
    let (loaded, names) = py.detach(|| -> PyResult<_> {
        let ds = Dataset::open(&dataset_dir, Inputs::FROM_FILES).map_err(error::file)?;
        let names =
            trials.unwrap_or_else(|| ds.manifest.trials.iter().map(|t| t.trial.clone()).collect());
        let metas = ds.trials(&names).map_err(error::value)?;
        let cache = FeatureCache::new(&ds).map_err(error::file)?;
        let loaded = cache
            .load(&metas, &config, sampling, &[Phase::Motion, Phase::Stop])
            .map_err(error::file)?;
        Ok((loaded, names))
    })?;
    let n = loaded.samples.len();
    let features =
        Array2::from_shape_vec((n, loaded.set.width), loaded.set.features).map_err(error::value)?;
    let labels = Array2::from_shape_vec((n, 2), loaded.set.labels).map_err(error::value)?;
    let trial: Vec<i64> = loaded.samples.iter().map(|s| s.trial as i64).collect();
    let t_us: Vec<i64> = loaded.samples.iter().map(|s| s.t_us).collect();
    let stop: Vec<bool> = loaded
        .samples
        .iter()
        .map(|s| s.phase == Phase::Stop)
        .collect();
    Ok((
        features.into_pyarray(py),
        labels.into_pyarray(py),
        trial.into_pyarray(py),
        t_us.into_pyarray(py),
        stop.into_pyarray(py),
        names,
    ))
}
