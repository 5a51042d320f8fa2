//! Integration tests of the event file readers and writers: one test binary, one module per
//! format (the AEDAT4 codec's own
//! tests live in `tests/aedat.rs`).

mod alloc;
mod common;
mod csv;
mod evt;
mod npy;
mod recording;
