//! The commands' NPY and text outputs, written whole or not at all through
//! [`evtac_events::output`] (a temporary file beside the output, renamed when complete), so a
//! command that fails half-way leaves no file that looks valid.

use std::path::Path;

use anyhow::Context;
use evtac_events::output::{self, OutputFile};
use ndarray_npy::WriteNpyExt;

/// Writes `array` as NPY to `path`.
pub fn write_npy(path: &Path, array: &impl WriteNpyExt) -> anyhow::Result<()> {
    let context = || format!("writing {}", path.display());
    let mut file = OutputFile::buffered(path).with_context(context)?;
    array.write_npy(&mut file).with_context(context)?;
    OutputFile::commit_buffered(file).with_context(context)
}

/// Writes `text` to `path`.
pub fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    output::write_atomic(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}
