//! `evtac predict`: (pitch, roll) for every row of a features NPY with a trained model bundle.
//!
//! Features made otherwise than the model's (another representation or setting, another crop,
//! another mask) have the right number of columns and give confident wrong angles, so the
//! features' provenance (`FEATURES.npy.json`, written by `evtac represent`) must match the
//! model's; features without one are refused unless `--unchecked-features` says to go on.

use std::path::PathBuf;

use anyhow::{Context, bail};
use evtac_learn::Model;
use evtac_repr::FeatureProvenance;
use ndarray::{Array2, ArrayD};
use ndarray_npy::ReadNpyError;

/// Arguments of `evtac predict`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Model bundle folder written by `evtac train` (model.safetensors, config.json, ...).
    #[arg(long)]
    pub model: PathBuf,
    /// Features as an N x 900 float32 NPY (one pooled 30 x 30 representation per row; N x 1800
    /// for stacked and late models: the static frame's cells, then the dynamic frame's).
    #[arg(long)]
    pub features: PathBuf,
    /// Predict from features that carry no record of what made them (no FEATURES.npy.json
    /// beside them, as `evtac represent` writes): you vouch that they are the model's own.
    #[arg(long)]
    pub unchecked_features: bool,
    /// Output NPY: N x 2 float32, pitch and roll in degrees.
    #[arg(long)]
    pub output: PathBuf,
}

/// Runs `evtac predict`.
pub fn run(args: Args) -> anyhow::Result<()> {
    evtac_learn::flush_denormals();
    evtac_events::output::refuse_input(&args.output, &[&args.features])?;
    let model = Model::load(&args.model)
        .with_context(|| format!("loading the model bundle {}", args.model.display()))?;
    check_provenance(&args, &model.feature_provenance())?;
    let predictor = &model.predictor;
    let features = read_features(&args.features, predictor.inputs())?;
    let predictions = predictor.predict(&features)?;
    let out = Array2::from_shape_vec(
        (predictions.len(), 2),
        predictions.iter().flatten().copied().collect(),
    )?;
    crate::outputs::write_npy(&args.output, &out)
}

/// Refuses features whose provenance differs from the model's, or that have none (unless
/// `--unchecked-features`).
fn check_provenance(args: &Args, expected: &FeatureProvenance) -> anyhow::Result<()> {
    let sidecar = FeatureProvenance::sidecar(&args.features);
    let text = match std::fs::read_to_string(&sidecar) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound && args.unchecked_features => {
            return Ok(());
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => bail!(
            "{} has no {} saying what made the features, so they cannot be checked against the \
             model {} ({expected}); make them with `evtac represent --model {}`, or pass \
             --unchecked-features if you know they match",
            args.features.display(),
            sidecar.display(),
            args.model.display(),
            args.model.display()
        ),
        Err(e) => return Err(e).with_context(|| format!("reading {}", sidecar.display())),
    };
    let got: FeatureProvenance = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a features provenance", sidecar.display()))?;
    if let Some(why) = got.mismatch(expected) {
        bail!(
            "{} does not match the model {}: {why}; make them with `evtac represent --model {}`",
            args.features.display(),
            args.model.display(),
            args.model.display()
        );
    }
    Ok(())
}

/// Reads an N x `inputs` float32 NPY into a flat row-major buffer, with errors naming the file
/// and what its header says.
fn read_features(path: &std::path::Path, inputs: usize) -> anyhow::Result<Vec<f32>> {
    let array: ArrayD<f32> = match ndarray_npy::read_npy(path) {
        Ok(a) => a,
        Err(ReadNpyError::WrongDescriptor(descr)) => bail!(
            "{}: features must be float32 ('<f4'), the file holds {descr}",
            path.display()
        ),
        Err(e) => return Err(e).with_context(|| format!("reading {}", path.display())),
    };
    let shape = array.shape().to_vec();
    if shape.len() != 2 || shape[1] != inputs {
        bail!(
            "{}: features must have shape (N, {inputs}), the file has {shape:?} (the model reads {inputs} features per sample)",
            path.display()
        );
    }
    // `iter()` walks in logical (row-major) order even for Fortran-ordered files.
    Ok(array.iter().copied().collect())
}
