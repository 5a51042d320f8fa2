//! What a dataset knows of a replayed trial, for `evtac online --mcap`: when the input file is a
//! trial of a dataset (its folder's `trials.csv` lists it), the log carries the trial's labels
//! and, for simulated data, the truth beside each estimate, so that Foxglove plots the estimate
//! against what it estimates.
//!
//! The labels are the dataset's `labels/<trial>.csv` when `evtac labels` (or a reproduction)
//! wrote it, else computed as `evtac labels` would; a dataset that cannot be labelled (no
//! calibration) logs no labels and says why, rather than failing the run or logging a guess.

use std::path::Path;

use evtac_events::manifest::{Manifest, TrialMeta};
use evtac_labels::{CalibrationSource, LabelConfig, LabelSeries, dataset_calibration};
use evtac_online::mcap_log::Reference;

/// The manifest row of `input` in its folder's dataset, if it is a trial of one.
fn trial_of(input: &Path) -> Option<(std::path::PathBuf, TrialMeta)> {
    let dir = input.parent()?;
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let name = input.file_name()?;
    let manifest = Manifest::read(dir).ok()?;
    let meta = manifest
        .trials
        .into_iter()
        .find(|t| Path::new(&t.file).file_name() == Some(name))?;
    Some((dir.to_path_buf(), meta))
}

/// The references of `input`'s trial: `("label", ...)` and `("truth", ...)`, each when there is
/// one; what could not be had is said on standard error.
pub fn references(input: &Path) -> Vec<(&'static str, Reference)> {
    let Some((dir, meta)) = trial_of(input) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let as_reference = |series: LabelSeries| -> Reference { Box::new(move |t| series.at(t)) };
    match labels(&dir, &meta) {
        Ok(series) => out.push(("label", as_reference(series))),
        Err(why) => eprintln!(
            "note: trial {} of {}: no labels in the log ({why})",
            meta.trial,
            dir.display()
        ),
    }
    if let Some(file) = &meta.truth {
        match LabelSeries::read_csv(dir.join(file)) {
            Ok(series) => out.push(("truth", as_reference(series))),
            Err(e) => eprintln!("note: trial {}: no truth in the log ({e})", meta.trial),
        }
    }
    out
}

/// The trial's labels: `labels/<trial>.csv`, or computed with the dataset's calibration.
fn labels(dir: &Path, meta: &TrialMeta) -> Result<LabelSeries, String> {
    let written = evtac_labels::dataset::labels_path(dir, &meta.trial);
    if written.is_file() {
        return LabelSeries::read_csv(&written).map_err(|e| e.to_string());
    }
    let calibration =
        dataset_calibration(dir, CalibrationSource::File).map_err(|e| e.to_string())?;
    evtac_labels::label_trial(dir, meta, &calibration, &LabelConfig::default())
        .map(|l| l.labels)
        .map_err(|e| e.to_string())
}
