//! How Rust errors become Python exceptions: the message is the Rust error's `Display` (which
//! names the file, field or index at fault), the type says whose fault it is. Anything about a
//! file (missing, unreadable, corrupt, unwritable) is an `OSError`; a bad argument (a setting,
//! an array, an unordered event) is a `ValueError`.

use pyo3::PyErr;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};

/// An `OSError` carrying `err`'s message.
pub fn file(err: impl std::fmt::Display) -> PyErr {
    PyOSError::new_err(err.to_string())
}

/// An `OSError` carrying `err`'s message, as the subclass `FileNotFoundError` when `io` says
/// the file is missing (what Python's own `open` raises).
pub fn io(err: impl std::fmt::Display, io: &std::io::Error) -> PyErr {
    match io.kind() {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(err.to_string()),
        _ => file(err),
    }
}

/// A `ValueError` carrying `err`'s message.
pub fn value(err: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(err.to_string())
}
