//! Fuzzes the NPY event reader (header dictionary parser and records). Any outcome but a panic
//! is fine.

#![no_main]

use evtac_formats::npy::NpyReader;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(mut reader) = NpyReader::from_slice(data) {
        while let Ok(Some(_)) = reader.next_chunk() {}
    }
});
