//! Fuzzes the NPZ reader: the zip container (the `zip` crate's parsing and inflation) and the
//! NPY members inside it, as one record array or one array per field. Any outcome but a panic,
//! a hang or a huge allocation is fine.

#![no_main]

use evtac_formats::npy::npz::fuzz_decode;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = fuzz_decode(data);
});
