//! Fuzzes the NeuroTac pickle reader: the pickle machine (every opcode, lengths, the memo) and
//! the reading of its value as the lab's per-pixel structure, raw and after an object-NPY
//! header. Any outcome but a panic, a hang or a huge allocation is fine.

#![no_main]

use evtac_formats::neurotac::fuzz_decode;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    fuzz_decode(data);
});
