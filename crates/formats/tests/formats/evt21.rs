//! EVT 2.1: a file written by an independent writer (a Python script written from Prophesee's
//! EVT 2.1 format description, with `struct`), the figures it computed, chunk invariance, bad
//! input.

use evtac_events::{Resolution, Trigger};
use evtac_formats::Format;
use evtac_formats::evt::{EvtError, EvtReader, EvtVersion, decode_all};
use evtac_testkit::run_python;
use proptest::prelude::*;

use crate::common::{Figures, PY_DIGEST, READ_SIZES, Trickle};

/// Writes an EVT 2.1 file from the format description: 64-bit little-endian words, type in bits
/// 60..63; CD_OFF 0x0 / CD_ON 0x1 with ts (6 bits) at 54, x at 43 (a multiple of 32 here), y at
/// 32 and a 32-bit validity mask at 0; EVT_TIME_HIGH 0x8 with the upper 28 bits of time at 32;
/// EXT_TRIGGER 0xA with value bit 32, id at 40, ts at 54; an OTHERS word (0xE) now and then.
/// Prints the figures of the events it encoded (from its own list, not from the bytes), then
/// the triggers as `t:kind`.
const PY_WRITE_EVT21: &str = r#"
import random, struct, sys
rng = random.Random(21)
W, H = 240, 180
out = bytearray(b"% camera_integrator_name Prophesee\n% format EVT21;height=180;width=240\n% end\n")
events, triggers = [], []
t = 70_000
high = None
def word(w):
    out.extend(struct.pack("<Q", w))
for _ in range(3000):
    t += rng.choice([0, 0, 1, 3, 17, 64, 200])
    if t >> 6 != high:
        high = t >> 6
        word(0x8 << 60 | high << 32)
    kind = rng.randint(0, 1)
    y = rng.randrange(H)
    base = rng.randrange(0, W, 32)
    mask = rng.getrandbits(32) & rng.getrandbits(32)
    mask &= (1 << min(32, W - base)) - 1
    if mask == 0:
        mask = 1
    word(kind << 60 | (t & 63) << 54 | base << 43 | y << 32 | mask)
    for i in range(32):
        if mask >> i & 1:
            events.append((t, base + i, y, kind))
    r = rng.random()
    if r < 0.02:
        value = rng.randint(0, 1)
        word(0xA << 60 | (t & 63) << 54 | 1 << 40 | value << 32)
        triggers.append((t, 1 if value else 2))
    elif r < 0.04:
        word(0xE << 60 | rng.getrandbits(40))
open(sys.argv[1], "wb").write(out)
on = sum(p for _, _, _, p in events)
print(len(events), events[0][0], events[-1][0], on, digest(events))
print(" ".join(f"{t}:{k}" for t, k in triggers))
"#;

/// Writes the test file with Python and returns its bytes and the figures Python states (`None`
/// when the reference Python is missing outside CI).
fn python_file(dir: &std::path::Path) -> Option<(std::path::PathBuf, Figures, Vec<Trigger>)> {
    let path = dir.join("written_by_python.raw");
    let script = format!("{PY_DIGEST}\n{PY_WRITE_EVT21}");
    let out = run_python(&script, &[path.to_str().unwrap()])?;
    let mut lines = out.lines();
    let figures = Figures::parse(lines.next().unwrap());
    let triggers = lines
        .next()
        .unwrap_or("")
        .split_whitespace()
        .map(|pair| {
            let (t, k) = pair.split_once(':').unwrap();
            Trigger {
                t: t.parse().unwrap(),
                kind: k.parse().unwrap(),
            }
        })
        .collect();
    Some((path, figures, triggers))
}

#[test]
fn python_written_file_matches_the_writers_figures() {
    let dir = tempfile::tempdir().unwrap();
    let Some((path, figures, triggers)) = python_file(dir.path()) else {
        return;
    };
    assert!(figures.count > 10_000 && !triggers.is_empty());
    let rec = evtac_formats::read_recording(&path).unwrap();
    assert_eq!(rec.format, Format::Evt21);
    assert_eq!(rec.resolution, Some(Resolution::new(240, 180)));
    assert_eq!(rec.source.as_deref(), Some("Prophesee"));
    assert_eq!(Figures::of(&rec.events), figures);
    assert_eq!(rec.triggers, triggers);

    let bytes = std::fs::read(&path).unwrap();
    for step in READ_SIZES {
        let mut reader = EvtReader::new(Trickle {
            bytes: &bytes,
            step,
        })
        .unwrap();
        assert_eq!(reader.header().version, EvtVersion::Evt21);
        let mut events = Vec::new();
        while let Some(chunk) = reader.next_chunk().unwrap() {
            events.extend_from_slice(chunk.events);
        }
        assert_eq!(events, rec.events, "read size {step}");
    }

    // A file cut inside its last word names the word's offset.
    let cut = bytes.len() - 3;
    match decode_all(&bytes[..cut]) {
        Err(EvtError::Truncated {
            offset,
            got: 5,
            word: 8,
        }) => assert_eq!(offset, cut as u64 - 5),
        other => panic!("expected a truncation error, got {other:?}"),
    }
}

#[test]
fn legacy_endianness_and_columns_past_the_sensor_are_errors() {
    let err =
        decode_all(b"% format EVT21;endianness=legacy;height=8;width=64\n% end\n").unwrap_err();
    assert!(err.to_string().contains("endianness=legacy"), "{err}");
    // A vector at x base 32 on a 40-column sensor with bit 8 set: column 40 is outside.
    let mut bytes = b"% format EVT21;height=8;width=40\n% end\n".to_vec();
    for w in [
        0x8u64 << 60 | 1 << 32,
        1 << 60 | 32 << 43 | 2 << 32 | 1 << 8,
    ] {
        bytes.extend_from_slice(&w.to_le_bytes());
    }
    let err = decode_all(&bytes).unwrap_err();
    assert!(err.to_string().contains("x=40"), "{err}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Arbitrary bytes after a valid EVT 2.1 header: an error or events, never a panic; a length
    /// that is not a whole number of words is always an error.
    #[test]
    fn random_data_never_panics(data in proptest::collection::vec(any::<u8>(), 0..1024)) {
        let mut bytes = b"% format EVT21;height=64;width=64\n% end\n".to_vec();
        bytes.extend_from_slice(&data);
        let result = decode_all(&bytes);
        if data.len() % 8 != 0 {
            prop_assert!(result.is_err());
        }
        let mut big = b"% evt 2.1\n% geometry 2048x2048\n".to_vec();
        big.extend_from_slice(&data);
        let _ = decode_all(&big);
    }
}
