//! EVT 2.0 / 3.0: the figures of `EXPECTED.md`, chunk invariance, bad input.

use evtac_events::{Event, Resolution, Trigger};
use evtac_formats::evt::{EvtError, EvtReader, EvtVersion, decode_all};
use evtac_testkit::real_fixture;
use proptest::prelude::*;

use crate::common::{READ_SIZES, Trickle, read_npy_events};

const EVT2: &str = "prophesee_gen3_640x480.evt2.raw";
const EVT3: &str = "prophesee_gen4_1280x720.evt3.raw";
const EVT3_EXPECTED: &str = "prophesee_gen4_1280x720.evt3.expected.npy";

fn fixture_bytes(name: &str) -> Option<Vec<u8>> {
    Some(std::fs::read(real_fixture(name)?).expect("read fixture"))
}

fn read_with_step(bytes: &[u8], step: usize) -> (Vec<Event>, Vec<Trigger>) {
    let mut reader = EvtReader::new(Trickle { bytes, step }).expect("header");
    let (mut events, mut triggers) = (Vec::new(), Vec::new());
    while let Some(chunk) = reader.next_chunk().expect("decode") {
        events.extend_from_slice(chunk.events);
        triggers.extend_from_slice(chunk.triggers);
    }
    (events, triggers)
}

/// The `.expected.npy` beside the EVT3 fixture holds the correctly decoded events (see
/// `EXPECTED.md`; two independent decoders agree with it): every event, in order, must match
/// exactly.
#[test]
fn evt3_fixture_matches_the_expected_events() {
    let (Some(raw), Some(expected)) = (real_fixture(EVT3), real_fixture(EVT3_EXPECTED)) else {
        return;
    };
    let expected = read_npy_events(&expected);
    let mut reader = EvtReader::from_path(&raw).unwrap();
    assert_eq!(reader.header().version, EvtVersion::Evt3);
    assert_eq!(reader.resolution(), Some(Resolution::new(1280, 720)));
    let mut events = Vec::new();
    while let Some(chunk) = reader.next_chunk().unwrap() {
        events.extend_from_slice(chunk.events);
    }
    assert_eq!(events.len(), 219_596);
    assert_eq!(expected.len(), 219_596);
    if let Some(i) = events.iter().zip(&expected).position(|(a, b)| a != b) {
        panic!(
            "first difference at event {i}: {:?} != {:?}",
            events[i], expected[i]
        );
    }
    assert_eq!(events.first().map(|e| e.t), Some(11_718_656));
    assert_eq!(events.last().map(|e| e.t), Some(11_727_457));
}

/// The raw words of an EVT 3.0 file after its header: (type nibble, 12-bit payload).
fn evt3_words(bytes: &[u8]) -> Vec<(u16, u16)> {
    let header = EvtReader::from_slice(bytes).unwrap().header().len as usize;
    bytes[header..]
        .chunks_exact(2)
        .map(|w| u16::from_le_bytes([w[0], w[1]]))
        .map(|w| (w >> 12, w & 0xfff))
        .collect()
}

/// A TIME_LOW smaller than the previous one is not a wrap: only a smaller TIME_HIGH starts a new
/// period (Prophesee's EVT 3.0 rules). The fixture has such places (the camera sends a TIME_LOW a
/// few us ahead next to a TIME_HIGH); none of them may add 4096 us, so no step between
/// consecutive events is larger than the recording's 1 us.
#[test]
fn evt3_a_decreasing_time_low_never_adds_4096_us() {
    const TIME_LOW: u16 = 0x6;
    const TIME_HIGH: u16 = 0x8;
    let Some(bytes) = fixture_bytes(EVT3) else {
        return;
    };
    // The fixture must contain the case under test: TIME_LOW words that go back while the
    // TIME_HIGH stays the same.
    let (mut high, mut low, mut decreasing) = (None, None, 0);
    for (kind, payload) in evt3_words(&bytes) {
        match kind {
            TIME_HIGH => {
                if high != Some(payload) {
                    low = None;
                }
                high = Some(payload);
            }
            TIME_LOW => {
                if low.is_some_and(|previous| payload < previous) {
                    decreasing += 1;
                }
                low = Some(payload);
            }
            _ => {}
        }
    }
    assert!(decreasing > 0, "the fixture no longer exercises the case");
    let (_, events, _) = decode_all(&bytes).unwrap();
    for (i, pair) in events.windows(2).enumerate() {
        let step = pair[1].t - pair[0].t;
        assert!(
            (0..=1).contains(&step),
            "event {}: step of {step} us",
            i + 1
        );
    }
    // Prophesee's clock: bits 12..23 of the last timestamp are the last TIME_HIGH (0xb2f).
    assert_eq!(events.last().map(|e| e.t >> 12), Some(0xb2f));

    // The same case, isolated: TIME_HIGH 1, TIME_LOW 0x32b then 0x320, then one event.
    let mut small = b"% format EVT3;height=16;width=32\n% end\n".to_vec();
    let words: [u16; 5] = [0x8001, 0x632b, 0x6320, 0x0003, 0x2805];
    small.extend(words.iter().flat_map(|w| w.to_le_bytes()));
    let (_, events, _) = decode_all(&small).unwrap();
    assert_eq!(events.iter().map(|e| e.t).collect::<Vec<_>>(), vec![0x1320]);
}

#[test]
fn evt2_fixture_matches_expected_figures() {
    let Some(raw) = real_fixture(EVT2) else {
        return;
    };
    let (header, events, _) = decode_all(&std::fs::read(raw).unwrap()).unwrap();
    assert_eq!(header.version, EvtVersion::Evt2);
    assert_eq!(header.resolution, Some(Resolution::new(640, 480)));
    assert_eq!(
        header.source().as_deref(),
        Some("hal_plugin_gen3_fx3 00000157")
    );
    assert_eq!(events.len(), 521_252);
    assert_eq!(events.first().map(|e| e.t), Some(913_716_224));
    assert_eq!(events.last().map(|e| e.t), Some(913_812_095));
    assert!(events.iter().all(|e| e.x < 640 && e.y < 480));
}

#[test]
fn chunk_invariance_on_both_fixtures() {
    for name in [EVT2, EVT3] {
        let Some(bytes) = fixture_bytes(name) else {
            return;
        };
        let reference = read_with_step(&bytes, usize::MAX);
        assert!(!reference.0.is_empty());
        for step in READ_SIZES {
            assert!(
                read_with_step(&bytes, step) == reference,
                "{name}, read size {step}"
            );
        }
    }
}

#[test]
fn truncation_inside_a_word_is_an_error_with_its_offset() {
    let Some(bytes) = fixture_bytes(EVT2) else {
        return;
    };
    let cut = bytes.len() - 2;
    match decode_all(&bytes[..cut]) {
        Err(EvtError::Truncated {
            offset,
            got: 2,
            word: 4,
        }) => {
            assert_eq!(offset, cut as u64 - 2)
        }
        other => panic!("expected a truncation error, got {other:?}"),
    }
}

#[test]
fn empty_and_headerless_inputs_are_errors() {
    assert!(matches!(decode_all(b""), Err(EvtError::Empty)));
    assert!(matches!(decode_all(b"\x93NUMPY"), Err(EvtError::NoHeader)));
    let err = decode_all(b"% Date today\n% end\n").unwrap_err();
    assert!(err.to_string().contains("EVT version is unknown"), "{err}");
}

fn small_evt3() -> Vec<u8> {
    let mut bytes = b"% format EVT3;height=16;width=32\n% end\n".to_vec();
    let words: [u16; 9] = [
        0x8001, 0x6002, 0x0003, 0x2805, 0x3004, 0x4FFF, 0x4001, 0x5003, 0xA001,
    ];
    bytes.extend(words.iter().flat_map(|w| w.to_le_bytes()));
    bytes
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Any truncation and any flipped byte of a real file gives events or an error, never a panic;
    /// truncations inside a word are always errors.
    #[test]
    fn corrupted_fixtures_never_panic(cut in 0usize..4096, flip in 0usize..4096, bit in 0u8..8) {
        for name in [EVT2, EVT3] {
            let Some(bytes) = fixture_bytes(name) else { return Ok(()) };
            let bytes = &bytes[..bytes.len().min(8192)];
            let truncated = &bytes[..cut.min(bytes.len())];
            let result = decode_all(truncated);
            let word = if name == EVT2 { 4 } else { 2 };
            if truncated.len() > 166 && (truncated.len() - 166) % word != 0 {
                prop_assert!(result.is_err());
            }
            let mut flipped = bytes.to_vec();
            let i = flip % flipped.len();
            flipped[i] ^= 1 << bit;
            let _ = decode_all(&flipped);
        }
    }

    /// Arbitrary bytes after a valid header: an error or events, never a panic.
    #[test]
    fn random_data_never_panics(data in proptest::collection::vec(any::<u8>(), 0..512)) {
        let mut bytes = small_evt3();
        bytes.extend_from_slice(&data);
        let _ = decode_all(&bytes);
        let mut evt2 = b"% evt 2.0\n% geometry 64x64\n".to_vec();
        evt2.extend_from_slice(&data);
        let _ = decode_all(&evt2);
    }
}

#[test]
fn small_evt3_decodes_vectors_and_triggers() {
    let (_, events, triggers) = decode_all(&small_evt3()).unwrap();
    let xs: Vec<u16> = events.iter().map(|e| e.x).collect();
    // One ADDR_X, twelve from the full VECT_12, one from the next, two from VECT_8.
    assert_eq!(
        xs,
        vec![5, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 28, 29]
    );
    assert!(events.iter().all(|e| e.t == 4098 && e.y == 3));
    assert_eq!(triggers, vec![Trigger { t: 4098, kind: 1 }]);
}
