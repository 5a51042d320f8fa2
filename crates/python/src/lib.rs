//! The native half of the `evtac` Python package (`evtac._evtac`): the library crates behind a
//! small, positional API that the Python half (`python/evtac/__init__.py`) wraps with keyword
//! arguments, input normalisation and docstrings.
//!
//! Everything here calls the same functions as the `evtac` command, so results are bit for bit
//! the CLI's. Work on data runs with the interpreter released ([`Python::detach`]); arrays leave
//! as numpy arrays that own the Rust buffers (no copy), and come in as read-only views. Events,
//! IMU samples, triggers and estimates cross as packed records whose layouts are given in
//! [`records`] (the event record is the one of evtac's NPY files).
//!
//! Errors reach Python as exceptions with the Rust message ([`error`]): `OSError` for files,
//! `ValueError` for bad arguments.

use pyo3::prelude::*;

pub mod dataset;
pub mod error;
pub mod filter;
pub mod io;
pub mod model;
pub mod records;
pub mod representation;

/// The extension module `evtac._evtac`.
#[pymodule]
fn _evtac(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(io::read, m)?)?;
    m.add_function(wrap_pyfunction!(io::write, m)?)?;
    m.add_function(wrap_pyfunction!(filter::filter, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::labels, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::label_trial, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::dataset_features, m)?)?;
    m.add_class::<io::Recording>()?;
    m.add_class::<io::Reader>()?;
    m.add_class::<representation::Representation>()?;
    m.add_class::<model::Model>()?;
    m.add_class::<model::Estimator>()?;
    Ok(())
}
