//! Fuzzes the HDF5 event reader: the `hdf5-pure` crate's parsing of the file (superblock,
//! object headers, B-trees, chunk indexes, filters; instrumented with evtac's code), finding the
//! event datasets, their types and shapes, the attributes, `ms_to_idx` and the slices. Any
//! outcome but a panic, a crash, a hang or a huge allocation is fine.

#![no_main]

use evtac_formats::hdf5::fuzz_decode;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = fuzz_decode(data);
});
