//! Integration tests of the event file readers and writers: one test binary, one module per
//! format (the AEDAT4 codec's tests live in their own `aedat*.rs` files).

mod aedat_legacy;
mod common;
mod csv;
mod evt;
mod evt21;
mod npy;
mod recording;
