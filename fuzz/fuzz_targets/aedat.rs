//! cargo-fuzz target for the AEDAT 4.0 decoder: any bytes, decoded as a file and as a network
//! stream, must give an error or data, never a panic.
//!
//! Run: `cargo +nightly fuzz run aedat` from the workspace root (seed corpus: any `.aedat4`).

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    evtac_formats::aedat::fuzz_decode(data);
});
