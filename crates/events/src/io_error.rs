//! The I/O error of the crates above this one (`evtac-import`, `evtac-experiments`): the file it
//! happened to and the cause, kept whole.
//!
//! Their modules' errors carry file failures as [`IoError`] (their `Io` variant), so a message
//! always names the file and `source()` still reaches the underlying error (an
//! `std::io::Error`, or the NPY or JSON library's), instead of a string copy of it. (This
//! crate's own readers report through [`Error`](crate::Error), which names the format too.)

use std::path::{Path, PathBuf};

/// The cause of an [`IoError`]: any error, boxed.
pub type Cause = Box<dyn std::error::Error + Send + Sync>;

/// Reading or writing `path` failed.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct IoError {
    /// The file or folder.
    pub path: PathBuf,
    /// The underlying error.
    #[source]
    pub source: Cause,
}

impl IoError {
    /// A `map_err` adapter naming `path`: `std::fs::read(p).map_err(IoError::at(p))?`.
    pub fn at<E: Into<Cause>>(path: &Path) -> impl Fn(E) -> IoError + '_ {
        move |source| IoError {
            path: path.to_path_buf(),
            source: source.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_the_file_and_keeps_the_cause() {
        let err = std::fs::read("/nonexistent/x.npy")
            .map_err(IoError::at(Path::new("/nonexistent/x.npy")))
            .unwrap_err();
        assert!(err.to_string().starts_with("/nonexistent/x.npy: "), "{err}");
        let source = std::error::Error::source(&err).expect("a cause");
        assert!(source.downcast_ref::<std::io::Error>().is_some());
    }
}
