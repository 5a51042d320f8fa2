//! Fuzzes the EVT 2.0 decoder: the input as a whole file, and as the data after a valid header
//! (so the fuzzer reaches the word decoder without having to discover the header first).
//! Any outcome but a panic is fine.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = evtac_formats::evt::decode_all(data);
    let mut file = b"% evt 2.0\n% geometry 1280x720\n% end\n".to_vec();
    file.extend_from_slice(data);
    let _ = evtac_formats::evt::decode_all(&file);
});
