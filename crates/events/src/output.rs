//! Output files that appear whole or not at all, and never over a command's input.
//!
//! Every evtac command writes through [`OutputFile`]: the bytes go to a temporary file beside
//! the final name (the same folder, so the final rename is atomic on one file system), which
//! replaces the final name only on [`OutputFile::commit`], once the writer has finished without
//! error. A failed, interrupted or killed write leaves no file that looks valid (an NPY of zero
//! events, an AEDAT4 header pointing at a data table that was never written) and leaves an
//! earlier file of that name as it was; the temporary file is deleted when the `OutputFile` is
//! dropped uncommitted.
//!
//! A path that already names something other than a regular file or folder (`/dev/null`,
//! `/dev/stdout`, a named pipe) is written straight through: there is nothing to keep whole, and
//! renaming a file over it would replace the device with a regular file (run as root, every
//! later reader of `/dev/null` would read what the last command wrote there).
//!
//! [`refuse_input`] is the other half: a command checks, before it opens anything for writing,
//! that none of its outputs is one of its inputs, by the same path or through a link (symbolic
//! or hard), because writing the output would destroy the recording it is reading.
//!
//! ```
//! use std::io::Write;
//! use evtac_events::output::OutputFile;
//!
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("rates.csv");
//! let mut out = OutputFile::create(&path)?;
//! writeln!(out, "t,rate")?;
//! assert!(!path.exists(), "nothing under the final name until committed");
//! out.commit()?;
//! assert_eq!(std::fs::read_to_string(&path)?, "t,rate\n");
//! # Ok::<(), std::io::Error>(())
//! ```

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// A file being written under a temporary name beside `path`, renamed to `path` by
/// [`commit`](Self::commit) and deleted if dropped before.
#[derive(Debug)]
pub struct OutputFile {
    target: Target,
    path: PathBuf,
}

/// Where the bytes go until [`OutputFile::commit`].
#[derive(Debug)]
enum Target {
    /// A temporary file beside the final name, renamed over it on commit.
    Temp(tempfile::NamedTempFile),
    /// The final name itself, which is a device or a pipe (see the module's docs).
    Special(File),
}

/// Whether `path` exists and is neither a regular file nor a folder (a device, a pipe, a
/// socket), following symbolic links as opening it would.
fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|meta| !meta.is_file() && !meta.is_dir())
}

impl OutputFile {
    /// Starts writing `path`: creates an empty temporary file in its folder, named
    /// `.NAME.XXXXXX.EXT` (hidden, and with the final extension, for tools that pick an encoder
    /// by it). The folder must exist.
    pub fn create(path: impl AsRef<Path>) -> io::Result<Self> {
        let path = path.as_ref().to_path_buf();
        if is_special(&path) {
            let file = File::options().write(true).open(&path)?;
            return Ok(Self {
                target: Target::Special(file),
                path,
            });
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        let suffix = match path.extension() {
            Some(ext) => format!(".{}", ext.to_string_lossy()),
            None => String::new(),
        };
        let prefix = format!(".{name}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(&suffix);
        // A temporary file is private (0600); the output is an ordinary file, so it gets the
        // permissions `File::create` gives (0666 less the umask).
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let temp = builder.tempfile_in(dir).map_err(|e| {
            io::Error::new(
                e.kind(),
                format!("creating a temporary file in {}: {e}", dir.display()),
            )
        })?;
        Ok(Self {
            target: Target::Temp(temp),
            path,
        })
    }

    /// Where the bytes are until [`commit`](Self::commit) (for writers that take a path): the
    /// final path itself when that is a device or a pipe.
    pub fn temp_path(&self) -> &Path {
        match &self.target {
            Target::Temp(temp) => temp.path(),
            Target::Special(_) => &self.path,
        }
    }

    /// Flushes the file and renames it to its final name, replacing any file there.
    pub fn commit(mut self) -> io::Result<()> {
        self.flush()?;
        match self.target {
            Target::Temp(temp) => temp.persist(&self.path).map(drop).map_err(|e| e.error),
            Target::Special(_) => Ok(()),
        }
    }

    /// The open file, whichever kind of target it is.
    fn file(&mut self) -> &mut File {
        match &mut self.target {
            Target::Temp(temp) => temp.as_file_mut(),
            Target::Special(file) => file,
        }
    }

    /// [`create`](Self::create) behind a 64 KiB buffer.
    pub fn buffered(path: impl AsRef<Path>) -> io::Result<BufWriter<Self>> {
        Ok(BufWriter::with_capacity(1 << 16, Self::create(path)?))
    }

    /// Flushes a [`buffered`](Self::buffered) file and [commits](Self::commit) it.
    pub fn commit_buffered(buffered: BufWriter<Self>) -> io::Result<()> {
        buffered.into_inner().map_err(|e| e.into_error())?.commit()
    }
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file().write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.file().write_all(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file().flush()
    }
}

impl Seek for OutputFile {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.file().seek(pos)
    }
}

/// Writes `bytes` to `path` whole or not at all ([`OutputFile`]).
pub fn write_atomic(path: impl AsRef<Path>, bytes: &[u8]) -> io::Result<()> {
    let mut out = OutputFile::create(path)?;
    out.write_all(bytes)?;
    out.commit()
}

/// An output that is one of the command's inputs.
#[derive(Debug, thiserror::Error)]
#[error(
    "{} is the input {}{}: refusing to write over it (choose another output path)",
    output.display(),
    input.display(),
    if output == input { "" } else { " (the same file through a link)" }
)]
pub struct OutputIsInput {
    /// The output path as given.
    pub output: PathBuf,
    /// The input path as given.
    pub input: PathBuf,
}

/// Refuses an `output` that is one of `inputs`: the same path, or the same file reached through
/// a symbolic or hard link (compared by device and inode, [`same_file`]). An output that does not
/// exist yet cannot be an input.
pub fn refuse_input<P: AsRef<Path>>(output: &Path, inputs: &[P]) -> Result<(), OutputIsInput> {
    for input in inputs {
        let input = input.as_ref();
        let same = output == input || same_file::is_same_file(output, input).unwrap_or(false);
        if same {
            return Err(OutputIsInput {
                output: output.to_path_buf(),
                input: input.to_path_buf(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_appears_until_committed_and_a_dropped_file_leaves_no_trace() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.npy");
        std::fs::write(&path, b"earlier").unwrap();
        {
            let mut out = OutputFile::create(&path).unwrap();
            out.write_all(b"half").unwrap();
            assert!(out.temp_path().starts_with(dir.path()));
            assert!(out.temp_path().to_string_lossy().ends_with(".npy"));
        }
        assert_eq!(std::fs::read(&path).unwrap(), b"earlier");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "the temporary file is deleted");
        let mut out = OutputFile::create(&path).unwrap();
        out.write_all(b"whole").unwrap();
        out.commit().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"whole");
    }

    #[cfg(unix)]
    #[test]
    fn a_device_is_written_through_and_never_replaced_by_a_file() {
        use std::os::unix::fs::FileTypeExt;
        write_atomic("/dev/null", b"discarded").unwrap();
        let mut out = OutputFile::buffered("/dev/null").unwrap();
        out.write_all(b"also discarded").unwrap();
        OutputFile::commit_buffered(out).unwrap();
        let kind = std::fs::metadata("/dev/null").unwrap().file_type();
        assert!(kind.is_char_device(), "/dev/null is still a device");
        assert!(std::fs::read("/dev/null").unwrap().is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn outputs_get_ordinary_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.csv");
        write_atomic(&path, b"x").unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
        assert_ne!(
            mode & 0o044,
            0,
            "readable by others as File::create makes it: {mode:o}"
        );
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_by_path_and_through_links() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("x.aedat4");
        std::fs::write(&input, b"recording").unwrap();
        let err = refuse_input(&input, &[&input]).unwrap_err();
        assert!(
            err.to_string().contains("refusing to write over it"),
            "{err}"
        );
        let fresh = dir.path().join("y.aedat4");
        refuse_input(&fresh, &[&input]).unwrap();
        let hard = dir.path().join("hard.aedat4");
        std::fs::hard_link(&input, &hard).unwrap();
        let err = refuse_input(&hard, &[&input]).unwrap_err();
        assert!(err.to_string().contains("through a link"), "{err}");
        #[cfg(unix)]
        {
            let soft = dir.path().join("soft.aedat4");
            std::os::unix::fs::symlink(&input, &soft).unwrap();
            refuse_input(&soft, &[&input]).unwrap_err();
            let relative = dir.path().join(".").join("x.aedat4");
            refuse_input(&relative, &[&input]).unwrap_err();
        }
        std::fs::write(&fresh, b"other").unwrap();
        refuse_input(&fresh, &[&input]).unwrap();
    }
}
