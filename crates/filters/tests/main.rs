//! Integration tests of `evtac-filters`: one test binary, one module per concern.

mod chunks;
mod common;
mod dv_processing;
mod masks;
mod references;
