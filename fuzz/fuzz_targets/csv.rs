//! Fuzzes the CSV event reader, with and without a declared resolution. Any outcome but a panic
//! is fine.

#![no_main]

use evtac_events::Resolution;
use evtac_formats::csv::CsvReader;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for resolution in [None, Some(Resolution::new(640, 480))] {
        let Ok(mut reader) = CsvReader::from_slice(data) else {
            return;
        };
        if let Some(r) = resolution {
            reader.set_resolution(r);
        }
        while let Ok(Some(_)) = reader.next_chunk() {}
    }
});
