//! CSV: round trips, chunk invariance, bad input.

use evtac_events::Event;
use evtac_formats::csv::{CsvReader, CsvWriter};
use proptest::prelude::*;

use crate::common::{READ_SIZES, Trickle, synthetic_events};

fn write(events: &[Event]) -> Vec<u8> {
    let mut w = CsvWriter::new(Vec::new()).unwrap();
    w.write_events(events).unwrap();
    w.finish().unwrap()
}

fn read_all<R: std::io::BufRead>(source: R) -> Result<Vec<Event>, evtac_formats::csv::CsvError> {
    CsvReader::new(source)?.read_to_end()
}

#[test]
fn round_trip_and_chunk_invariance() {
    let events = synthetic_events(40_000, 1280, 720);
    let bytes = write(&events);
    for step in READ_SIZES {
        let source = std::io::BufReader::with_capacity(
            step,
            Trickle {
                bytes: &bytes,
                step,
            },
        );
        assert_eq!(read_all(source).unwrap(), events, "read size {step}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    /// Any truncation or flipped byte: events or an error, never a panic.
    #[test]
    fn corrupted_csv_never_panics(cut in 0usize..2000, flip in 0usize..2000, byte in any::<u8>()) {
        let bytes = write(&synthetic_events(100, 640, 480));
        let _ = read_all(&bytes[..cut.min(bytes.len())]);
        let mut flipped = bytes.clone();
        let i = flip % flipped.len();
        flipped[i] = byte;
        let _ = read_all(flipped.as_slice());
    }

    /// Round trip of arbitrary ordered events.
    #[test]
    fn arbitrary_round_trip(mut events in proptest::collection::vec(
        (any::<i64>(), any::<u16>(), any::<u16>(), any::<bool>())
            .prop_map(|(t, x, y, polarity)| Event { t, x, y, polarity }), 0..200)) {
        events.sort_by_key(|e| e.t);
        prop_assert_eq!(read_all(write(&events).as_slice()).unwrap(), events);
    }
}
