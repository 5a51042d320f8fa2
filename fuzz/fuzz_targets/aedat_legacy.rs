//! Fuzzes the AEDAT 2.0 / 3.1 decoders: the input as a whole file, and as the data after a valid
//! header of each version (so the fuzzer reaches the record and packet decoders without having
//! to discover the headers first). Any outcome but a panic is fine.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = evtac_formats::aedat_legacy::decode_all(data);
    for header in [
        &b"#!AER-DAT2.0\r\n# AEChip: DAVIS346B\r\n"[..],
        &b"#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS240C\r\n#!END-HEADER\r\n"[..],
    ] {
        let mut file = header.to_vec();
        file.extend_from_slice(data);
        let _ = evtac_formats::aedat_legacy::decode_all(&file);
    }
});
