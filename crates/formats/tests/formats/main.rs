//! Integration tests of the event file readers and writers: one test binary, one module per
//! format, and the bad-input matrix over every reader (`bad_input.rs`; the AEDAT4 codec's own
//! tests live in `tests/aedat.rs`).

mod aedat_legacy;
mod alloc;
mod bad_input;
mod bad_input_archives;
mod bad_input_legacy;
mod common;
mod csv;
mod evt;
mod evt21;
mod hdf5;
mod hdf5_damaged;
mod neurotac;
mod npy;
mod other_tools;
mod recording;
mod ros;
