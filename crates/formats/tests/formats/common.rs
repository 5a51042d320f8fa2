//! Helpers shared by the reader tests.

#![allow(dead_code)]

use std::io::Read;

use evtac_events::Event;

/// A reader that hands out at most `step` bytes per `read`, to exercise the carry-over of data
/// that straddles read boundaries.
pub struct Trickle<'a> {
    pub bytes: &'a [u8],
    pub step: usize,
}

impl Read for Trickle<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.step.min(buf.len()).min(self.bytes.len());
        buf[..n].copy_from_slice(&self.bytes[..n]);
        self.bytes = &self.bytes[n..];
        Ok(n)
    }
}

/// The read sizes every streaming reader must be invariant to.
pub const READ_SIZES: [usize; 3] = [1, 7, 65536];

/// A deterministic, ordered event stream on a `width` x `height` sensor.
pub fn synthetic_events(n: usize, width: u16, height: u16) -> Vec<Event> {
    // A fixed linear congruential sequence: reproducible without a seed argument.
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut t = 1_000_000i64;
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            t += ((state >> 60) % 3) as i64;
            Event {
                t,
                x: ((state >> 16) % u64::from(width)) as u16,
                y: ((state >> 32) % u64::from(height)) as u16,
                polarity: state >> 63 == 1,
            }
        })
        .collect()
}

/// The events of a headerless `t,x,y,p` text file that a test's Python script wrote as the
/// expected answer.
pub fn read_expected_csv(path: &std::path::Path) -> Vec<Event> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| {
            let v: Vec<i64> = l.split(',').map(|f| f.parse().unwrap()).collect();
            Event {
                t: v[0],
                x: v[1] as u16,
                y: v[2] as u16,
                polarity: v[3] == 1,
            }
        })
        .collect()
}

/// Reads the `.expected.npy` of the EVT3 fixture with the crate's own NPY reader.
pub fn read_npy_events(path: &std::path::Path) -> Vec<Event> {
    let mut reader = evtac_formats::npy::NpyReader::from_path(path).expect("open npy");
    let mut out = Vec::new();
    while let Some(chunk) = reader.next_chunk().expect("read npy") {
        out.extend_from_slice(chunk);
    }
    out
}

/// FNV-1a (64-bit) over the lines `t,x,y,p\n` of `events` (`p` 1 for ON, 0 for OFF): the digest
/// that the Python writers in the tests compute over the events they encode.
pub fn events_digest(events: &[Event]) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for e in events {
        let line = format!("{},{},{},{}\n", e.t, e.x, e.y, u8::from(e.polarity));
        for b in line.bytes() {
            hash ^= u64::from(b);
            hash = hash.wrapping_mul(0x0100_0000_01b3);
        }
    }
    hash
}

/// The same digest in Python, for the test scripts: `digest(events)` over `(t, x, y, p)` tuples.
pub const PY_DIGEST: &str = r#"
def digest(events):
    h = 0xcbf29ce484222325
    for t, x, y, p in events:
        for b in f"{t},{x},{y},{p}\n".encode():
            h ^= b
            h = (h * 0x100000001b3) % (1 << 64)
    return h
"#;

/// The figures a test's independent writer states about the events it wrote, and that the
/// reader must reproduce: `count first_t last_t on digest` on one line.
#[derive(Debug, PartialEq, Eq)]
pub struct Figures {
    pub count: usize,
    pub first_t: i64,
    pub last_t: i64,
    pub on: usize,
    pub digest: u64,
}

impl Figures {
    /// The figures of decoded events.
    pub fn of(events: &[Event]) -> Self {
        Self {
            count: events.len(),
            first_t: events.first().map_or(-1, |e| e.t),
            last_t: events.last().map_or(-1, |e| e.t),
            on: events.iter().filter(|e| e.polarity).count(),
            digest: events_digest(events),
        }
    }

    /// Parses the line `count first_t last_t on digest` a script printed.
    pub fn parse(line: &str) -> Self {
        let v: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(v.len(), 5, "figures line `{line}`");
        Self {
            count: v[0].parse().unwrap(),
            first_t: v[1].parse().unwrap(),
            last_t: v[2].parse().unwrap(),
            on: v[3].parse().unwrap(),
            digest: v[4].parse().unwrap(),
        }
    }
}

/// Replaces the header dictionary of an NPY 1.0 file by `dict` (padded to the same length).
pub fn with_dict(bytes: &[u8], dict: &str) -> Vec<u8> {
    let len = usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
    assert!(dict.len() < len, "dictionary too long");
    let mut out = bytes.to_vec();
    let mut text = dict.as_bytes().to_vec();
    text.resize(len - 1, b' ');
    text.push(b'\n');
    out[10..10 + len].copy_from_slice(&text);
    out
}
