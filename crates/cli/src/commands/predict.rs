//! `evtac predict`: (pitch, roll) for every row of a features NPY with a trained model bundle.

use std::path::PathBuf;

use anyhow::{Context, bail};
use evtac_learn::ModelBundle;
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
    /// Output NPY: N x 2 float32, pitch and roll in degrees.
    #[arg(long)]
    pub output: PathBuf,
}

/// Runs `evtac predict`.
pub fn run(args: Args) -> anyhow::Result<()> {
    evtac_learn::flush_denormals();
    evtac_events::output::refuse_input(&args.output, &[&args.features])?;
    let bundle = ModelBundle::load(&args.model)
        .with_context(|| format!("loading the model bundle {}", args.model.display()))?;
    let predictor = bundle.predictor()?;
    let features = read_features(&args.features, predictor.inputs())?;
    let predictions = predictor.predict(&features)?;
    let out = Array2::from_shape_vec(
        (predictions.len(), 2),
        predictions.iter().flatten().copied().collect(),
    )?;
    crate::outputs::write_npy(&args.output, &out)
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
