//! Integration tests of `evtac-repr`: one test binary, one module per concern.

mod bad_input;
mod common;
mod dense_kinds;
mod dense_reference;
mod dv_differential;
mod expf;
mod reference;
mod tonic_differential;
