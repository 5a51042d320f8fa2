//! The recording read and the file written by the commands that rewrite a recording
//! (`convert`, `filter`): the same two positional arguments, flattened into both.

use std::path::PathBuf;

/// The input recording and the output file.
#[derive(Debug, Clone, clap::Args)]
pub struct RewriteArgs {
    // The help is built from the one phrase of readable formats (see `crate::formats`).
    #[arg(help = concat!("The recording to read (", crate::formats::readable_formats!(), ")"))]
    pub input: PathBuf,
    /// The file to write; its extension picks the format: .aedat4 (LZ4, with the IMU samples
    /// and triggers), .csv or .npy.
    pub output: PathBuf,
}

impl RewriteArgs {
    /// Says on stderr how many of the events read were written, and where.
    pub fn say_written(&self, written: u64, read: u64) {
        eprintln!(
            "wrote {written} of {read} events to {}",
            self.output.display()
        );
    }
}
