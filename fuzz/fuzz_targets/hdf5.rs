//! Fuzzes the HDF5 event reader: finding the event datasets, their types and shapes, the
//! attributes, `ms_to_idx` and the slices, over whatever the HDF5 library (Debian's libhdf5, not
//! instrumented: coverage is of evtac's side) makes of the input. Any outcome but a panic, a
//! crash, a hang or a huge allocation is fine.

#![no_main]

use evtac_events::hdf5::fuzz_decode;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = fuzz_decode(data);
});
