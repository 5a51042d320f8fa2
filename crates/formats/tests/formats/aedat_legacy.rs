//! AEDAT 2.0 and 3.1: files written by independent writers (Python scripts written from
//! iniVation's AEDAT 2.0 / 3.1 format descriptions and libcaer's event layouts, with `struct`),
//! the figures they computed from the events they encoded, chunk invariance, truncation, bad
//! input.

use evtac_events::{Event, ImuSample, Resolution, Trigger};
use evtac_formats::Format;
use evtac_formats::aedat_legacy::{LegacyError, LegacyReader, Version, decode_all};
use evtac_testkit::run_python;
use proptest::prelude::*;

use crate::common::{Figures, PY_DIGEST, READ_SIZES, Trickle};

/// Writes an AEDAT 2.0 file as jAER does for a DAVIS240: `#` header lines ending in CR LF, then
/// big-endian (address, timestamp) int32 pairs. Polarity events at image (x, y) (origin top
/// left) get the address `(179 - y) << 22 | (239 - x) << 12 | p << 11` (jAER's coordinates:
/// x mirrored, origin bottom left); APS samples (bit 31), IMU axes (bit 31 and bits 10, 11) and
/// external input events (bit 10) are mixed in. Timestamps are written modulo 2^32 and start
/// 40 ms before the wrap. Prints the figures of the polarity events, then the offset of the last
/// record.
const PY_WRITE_AEDAT2: &str = r##"
import random, struct, sys
rng = random.Random(2)
out = bytearray()
for line in ["#!AER-DAT2.0", "# This is a raw AE data file - do not edit",
             "# Data format is int32 address, int32 timestamp (8 bytes total), repeated for each event",
             "# Timestamps tick is 1 us", "# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C"]:
    out += (line + "\r\n").encode()
events = []
t = (1 << 32) - 40_000
def record(address, t):
    out.extend(struct.pack(">II", address, t % (1 << 32)))
record(1 << 31 | 5 << 12, t)  # an APS sample first, as DAVIS files often start
last = 0
for _ in range(12_000):
    t += rng.choice([0, 1, 2, 5, 13])
    r = rng.random()
    last = len(out)
    if r < 0.05:
        record(1 << 31 | rng.randrange(7) << 28 | rng.getrandbits(16) << 12 | 0xC00, t)
    elif r < 0.10:
        record(1 << 31 | rng.randrange(180) << 22 | rng.randrange(240) << 12 | rng.randrange(3) << 10, t)
    elif r < 0.11:
        record(1 << 10, t)
    else:
        x, y, p = rng.randrange(240), rng.randrange(180), rng.randint(0, 1)
        record((179 - y) << 22 | (239 - x) << 12 | p << 11, t)
        events.append((t, x, y, p))
open(sys.argv[1], "wb").write(out)
on = sum(e[3] for e in events)
print(len(events), events[0][0], events[-1][0], on, digest(events))
print(last)
"##;

/// Writes an AEDAT 3.1 file as cAER does: the `#` header up to `#!END-HEADER`, then
/// little-endian packets with a 28-byte header (type i16, source i16, eventSize, eventTSOffset,
/// eventTSOverflow, eventCapacity, eventNumber, eventValid as i32). Polarity packets (type 1,
/// 8-byte events: data with valid bit 0, polarity bit 1, y at 2, x at 17; then the timestamp),
/// IMU6 packets (type 3, 36 bytes: info, timestamp, accel xyz, gyro xyz, temperature), special
/// packets (type 0: rising edge 2, falling edge 3), a frame packet (type 2) and packets of a
/// second source to skip; some events invalid, some packets with spare capacity. Timestamps
/// cross 2^31 (a new overflow). Prints the figures of the valid polarity events, the IMU samples
/// as `t:ax:gz:temp` (the floats' bit patterns), the triggers as `t:code`, and the offset of the last packet.
const PY_WRITE_AEDAT31: &str = r##"
import random, struct, sys
rng = random.Random(31)
out = bytearray(b"#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS240C\r\n"
                b"#Start-Time: 2018-03-01 10:00:00 (TZ+0000)\r\n#!END-HEADER\r\n")
def packet(kind, source, size, overflow, events, spare=0):
    global last
    last = len(out)
    valid = sum(1 for e in events if struct.unpack_from("<I", e)[0] & 1)
    out.extend(struct.pack("<hhiiiiii", kind, source, size, 4, overflow,
                           len(events) + spare, len(events), valid))
    for e in events:
        out.extend(e)
    out.extend(bytes(size * spare))
events, imu, triggers = [], [], []
t = (1 << 31) - 30_000
for _ in range(150):
    batch = []
    overflow = t >> 31
    for _ in range(rng.randrange(1, 200)):
        step = rng.choice([0, 1, 3, 9])
        if (t + step) >> 31 != overflow:
            t += step
            break
        t += step
        x, y, p = rng.randrange(240), rng.randrange(180), rng.randint(0, 1)
        valid = 0 if rng.random() < 0.03 else 1
        batch.append(struct.pack("<Ii", x << 17 | y << 2 | p << 1 | valid, t & 0x7FFFFFFF))
        if valid:
            events.append((t, x, y, p))
    packet(1, 1, 8, overflow, batch, spare=rng.choice([0, 0, 3]))
    r = rng.random()
    if r < 0.3:
        a = [rng.uniform(-2, 2) for _ in range(3)]
        g = [rng.uniform(-250, 250) for _ in range(3)]
        temp = rng.uniform(20, 40)
        e = struct.pack("<Ii7f", 1, t & 0x7FFFFFFF, *a, *g, temp)
        packet(3, 1, 36, t >> 31, [e])
        v = struct.unpack("<7I", e[8:])
        imu.append((t, v[0], v[5], v[6]))
    elif r < 0.4:
        code = rng.choice([2, 3])
        packet(0, 1, 8, t >> 31, [struct.pack("<Ii", code << 1 | 1, t & 0x7FFFFFFF)])
        triggers.append((t, code - 1))
    elif r < 0.45:
        packet(2, 1, 1000, t >> 31, [bytes([1]) + bytes(999)])
    elif r < 0.5:
        packet(1, 2, 8, t >> 31, [struct.pack("<Ii", 1, t & 0x7FFFFFFF)])
open(sys.argv[1], "wb").write(out)
on = sum(e[3] for e in events)
print(len(events), events[0][0], events[-1][0], on, digest(events))
print(" ".join(f"{t}:{ax}:{gz}:{tp}" for t, ax, gz, tp in imu))
print(" ".join(f"{t}:{k}" for t, k in triggers))
print(last)
"##;

/// Runs a writer script; its stdout lines. `None` when the reference Python is missing.
fn write_with_python(script: &str, path: &std::path::Path) -> Option<Vec<String>> {
    let script = format!("{PY_DIGEST}\n{script}");
    let out = run_python(&script, &[path.to_str().unwrap()])?;
    Some(out.lines().map(str::to_string).collect())
}

/// Everything a reader yields when `bytes` arrive `step` bytes at a time.
fn read_with_step(bytes: &[u8], step: usize) -> (Vec<Event>, Vec<ImuSample>, Vec<Trigger>) {
    let mut reader = LegacyReader::new(Trickle { bytes, step }).unwrap();
    let (mut events, mut imu, mut triggers) = (Vec::new(), Vec::new(), Vec::new());
    while let Some(chunk) = reader.next_chunk().unwrap() {
        events.extend_from_slice(chunk.events);
        imu.extend_from_slice(chunk.imu);
        triggers.extend_from_slice(chunk.triggers);
    }
    (events, imu, triggers)
}

/// Reading with read sizes 1, 7 and 65536 gives what reading the whole file does.
fn assert_chunk_invariant(bytes: &[u8]) {
    let reference = read_with_step(bytes, usize::MAX);
    for step in READ_SIZES {
        assert!(read_with_step(bytes, step) == reference, "read size {step}");
    }
}

#[test]
fn aedat2_written_by_python_matches_its_figures() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("davis240.aedat");
    let Some(lines) = write_with_python(PY_WRITE_AEDAT2, &path) else {
        return;
    };
    let figures = Figures::parse(&lines[0]);
    // The writer's clock crosses 2^32 us: the wrap must be undone.
    assert!(figures.first_t < 1 << 32 && figures.last_t > 1 << 32);
    let rec = evtac_formats::read_recording(&path).unwrap();
    assert_eq!(rec.format, Format::Aedat2);
    assert_eq!(rec.resolution, Some(Resolution::new(240, 180)));
    assert_eq!(
        rec.source.as_deref(),
        Some("eu.seebetter.ini.chips.davis.DAVIS240C")
    );
    assert_eq!(Figures::of(&rec.events), figures);
    assert!(rec.imu.is_empty() && rec.triggers.is_empty());

    let bytes = std::fs::read(&path).unwrap();
    assert_chunk_invariant(&bytes);
    let last: u64 = lines[1].parse().unwrap();
    let cut = bytes.len() - 3;
    match decode_all(&bytes[..cut]) {
        Err(LegacyError::Truncated {
            what: "record",
            offset,
            needed: 8,
            len,
        }) => assert_eq!((offset, len), (last, cut as u64)),
        other => panic!("expected a truncation error, got {other:?}"),
    }
}

#[test]
fn aedat31_written_by_python_matches_its_figures() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("davis240.aedat");
    let Some(lines) = write_with_python(PY_WRITE_AEDAT31, &path) else {
        return;
    };
    let figures = Figures::parse(&lines[0]);
    assert!(figures.first_t < 1 << 31 && figures.last_t > 1 << 31);
    let rec = evtac_formats::read_recording(&path).unwrap();
    assert_eq!(rec.format, Format::Aedat31);
    assert_eq!(rec.resolution, Some(Resolution::new(240, 180)));
    assert_eq!(rec.source.as_deref(), Some("DAVIS240C"));
    assert_eq!(Figures::of(&rec.events), figures);

    let imu: Vec<String> = rec
        .imu
        .iter()
        .map(|s| {
            format!(
                "{}:{}:{}:{}",
                s.t,
                s.accelerometer[0].to_bits(),
                s.gyroscope[2].to_bits(),
                s.temperature.to_bits()
            )
        })
        .collect();
    assert!(!imu.is_empty());
    assert_eq!(imu.join(" "), lines[1]);
    let triggers: Vec<String> = rec
        .triggers
        .iter()
        .map(|t| format!("{}:{}", t.t, t.kind))
        .collect();
    assert!(!triggers.is_empty());
    assert_eq!(triggers.join(" "), lines[2]);

    // A range read (scanned: the format has no index) equals the filtered whole.
    let (from, to) = (rec.events[1000].t, rec.imu[20].t);
    let (part, how) = evtac_formats::read_recording_range(&path, from, to).unwrap();
    assert!(how.fallback().is_none());
    let within = |t: i64| from <= t && t < to;
    let events: Vec<Event> = rec.events.iter().copied().filter(|e| within(e.t)).collect();
    let imu: Vec<ImuSample> = rec.imu.iter().copied().filter(|s| within(s.t)).collect();
    let kept: Vec<Trigger> = rec
        .triggers
        .iter()
        .copied()
        .filter(|t| within(t.t))
        .collect();
    assert!(!events.is_empty() && !imu.is_empty());
    assert_eq!((part.events, part.imu, part.triggers), (events, imu, kept));

    let bytes = std::fs::read(&path).unwrap();
    assert_chunk_invariant(&bytes);
    let last: u64 = lines[3].parse().unwrap();
    let cut = bytes.len() - 3;
    match decode_all(&bytes[..cut]) {
        Err(LegacyError::Truncated {
            what: "packet",
            offset,
            len,
            ..
        }) => assert_eq!((offset, len), (last, cut as u64)),
        other => panic!("expected a truncation error, got {other:?}"),
    }
    // Cut inside the last packet's header.
    match decode_all(&bytes[..last as usize + 10]) {
        Err(LegacyError::Truncated {
            what: "packet header",
            offset,
            needed: 28,
            ..
        }) => assert_eq!(offset, last),
        other => panic!("expected a truncation error, got {other:?}"),
    }
}

/// Writes an AEDAT 2.0 and an AEDAT 3.1 file of plain polarity events (no other records, every
/// event valid, one camera, no timestamp wrap: what iniVation's own legacy reader handles) and
/// reads them back with that reader, `dv.LegacyAedatFile` (the `dv` package). It reports jAER's
/// raw AEDAT 2.0 addresses, which evtac mirrors (`x = 239 - x`, `y = 179 - y`); the script applies
/// that and prints the figures of what `dv` read from each file.
const PY_DV_READS: &str = r##"
import random, struct, sys, os
from dv import LegacyAedatFile
d = sys.argv[1]
rng = random.Random(7)
ev, t = [], 5000
for _ in range(4000):
    t += rng.randrange(0, 6)
    ev.append((t, rng.randrange(240), rng.randrange(180), rng.randint(0, 1)))
a2 = bytearray(b"#!AER-DAT2.0\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n")
for t, x, y, p in ev:
    a2 += struct.pack(">II", (179 - y) << 22 | (239 - x) << 12 | p << 11, t)
open(os.path.join(d, "dv2.aedat"), "wb").write(a2)
a3 = bytearray(b"#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS240C\r\n#!END-HEADER\r\n")
for i in range(0, len(ev), 700):
    batch = ev[i:i + 700]
    a3 += struct.pack("<hhiiiiii", 1, 1, 8, 4, 0, len(batch), len(batch), len(batch))
    for t, x, y, p in batch:
        a3 += struct.pack("<Ii", x << 17 | y << 2 | p << 1 | 1, t)
open(os.path.join(d, "dv31.aedat"), "wb").write(a3)
for name, flip in [("dv2.aedat", True), ("dv31.aedat", False)]:
    with LegacyAedatFile(os.path.join(d, name)) as f:
        got = [(e.timestamp, 239 - e.x if flip else e.x, 179 - e.y if flip else e.y, int(e.polarity))
               for e in f]
    print(len(got), got[0][0], got[-1][0], sum(e[3] for e in got), digest(got))
"##;

#[test]
fn inivations_legacy_reader_agrees() {
    let dir = tempfile::tempdir().unwrap();
    let script = format!("{PY_DIGEST}\n{PY_DV_READS}");
    let Some(out) = run_python(&script, &[dir.path().to_str().unwrap()]) else {
        return;
    };
    let lines: Vec<&str> = out.lines().collect();
    for (name, line) in ["dv2.aedat", "dv31.aedat"].iter().zip(lines) {
        let rec = evtac_formats::read_recording(dir.path().join(name)).unwrap();
        let figures = Figures::parse(line);
        assert_eq!(figures.count, 4000, "{name}");
        assert_eq!(Figures::of(&rec.events), figures, "{name}");
    }
}

#[test]
fn other_versions_and_broken_headers_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.aedat");
    std::fs::write(&path, b"#!AER-DAT1.0\r\n\x00\x01").unwrap();
    let err = evtac_formats::read_recording(&path)
        .unwrap_err()
        .to_string();
    assert!(err.contains("old.aedat") && err.contains("`1.0`"), "{err}");
    assert!(matches!(decode_all(b""), Err(LegacyError::Empty)));
    let err = decode_all(b"#!AER-DAT3.1\r\n#Format: RAW\r\n").unwrap_err();
    assert!(
        matches!(err, LegacyError::TruncatedHeader { offset: 28 }),
        "{err:?}"
    );
    let reader = LegacyReader::from_slice(b"#!AER-DAT2.0\n").unwrap();
    assert_eq!(reader.header().version, Version::Aedat2);
}

/// cAER writes a packet container's polarity packet before its IMU and special packets, so the
/// IMU samples and triggers of a range may come after events past the range's end (here after
/// more than one read's worth of them): a range read still finds them.
#[test]
fn aedat31_range_reads_find_imu_and_triggers_that_trail_the_events() {
    let mut bytes = headers()[1].to_vec();
    let mut packet = |kind: i16, size: i32, events: Vec<(u32, i32)>| {
        let n = events.len() as i32;
        bytes.extend(kind.to_le_bytes());
        bytes.extend(1i16.to_le_bytes());
        for v in [size, 4, 0, n, n, n] {
            bytes.extend(v.to_le_bytes());
        }
        for (data, t) in events {
            bytes.extend(data.to_le_bytes());
            bytes.extend(t.to_le_bytes());
            bytes.extend(vec![0u8; size as usize - 8]);
        }
    };
    // 20,000 events (160 KB) at t = 100 .. 20,099, then IMU samples and rising edges that span
    // the same time.
    packet(1, 8, (0..20_000).map(|i| (3 << 17 | 1, 100 + i)).collect());
    packet(3, 36, (0..20).map(|i| (1, 100 + 1_000 * i)).collect());
    packet(
        0,
        8,
        (0..20).map(|i| (2 << 1 | 1, 150 + 1_000 * i)).collect(),
    );
    packet(1, 8, vec![(5 << 17 | 1, 30_000)]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("containers.aedat");
    std::fs::write(&path, &bytes).unwrap();
    let whole = evtac_formats::read_recording(&path).unwrap();
    let (from, to) = (2_000, 5_000);
    let (part, _) = evtac_formats::read_recording_range(&path, from, to).unwrap();
    let within = |t: i64| from <= t && t < to;
    assert_eq!(part.events.len(), 3_000);
    assert_eq!(
        part.imu,
        whole
            .imu
            .iter()
            .copied()
            .filter(|s| within(s.t))
            .collect::<Vec<_>>()
    );
    assert_eq!(
        part.triggers,
        whole
            .triggers
            .iter()
            .copied()
            .filter(|t| within(t.t))
            .collect::<Vec<_>>()
    );
    assert_eq!((part.imu.len(), part.triggers.len()), (3, 3));
}

/// A valid header of each version, for the never-panic properties.
fn headers() -> [&'static [u8]; 2] {
    [
        b"#!AER-DAT2.0\r\n# AEChip: DAVIS240C\r\n",
        b"#!AER-DAT3.1\r\n#Source 1: DAVIS240C\r\n#!END-HEADER\r\n",
    ]
}

/// A small AEDAT 3.1 file built here (polarity, IMU6 and special packets) and the offsets where
/// its packets end.
fn small_aedat31() -> (Vec<u8>, Vec<usize>) {
    let mut bytes = headers()[1].to_vec();
    let mut ends = vec![bytes.len()];
    let mut t = 10i32;
    for (kind, size) in [(1i16, 8i32), (3, 36), (1, 8), (0, 8), (1, 8)] {
        let n = 3;
        bytes.extend(kind.to_le_bytes());
        bytes.extend(1i16.to_le_bytes());
        for v in [size, 4, 0, n, n, n] {
            bytes.extend(v.to_le_bytes());
        }
        for i in 0..n {
            t += 5;
            let data: u32 = if kind == 0 {
                2 << 1 | 1
            } else {
                (i as u32) << 17 | 1
            };
            bytes.extend(data.to_le_bytes());
            bytes.extend(t.to_le_bytes());
            bytes.extend(vec![0u8; size as usize - 8]);
        }
        ends.push(bytes.len());
    }
    (bytes, ends)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// A file cut anywhere but at a record (AEDAT 2.0) or packet (AEDAT 3.1) boundary is a
    /// truncation error naming where the cut record or packet starts; a cut at a boundary reads
    /// the whole packets before it.
    #[test]
    fn cuts_inside_records_and_packets_are_errors(cut in 0usize..400) {
        let (bytes, ends) = small_aedat31();
        let cut = ends[0] + cut % (bytes.len() - ends[0] + 1);
        match decode_all(&bytes[..cut]) {
            Ok(_) => prop_assert!(ends.contains(&cut), "cut at {cut} read without error"),
            Err(LegacyError::Truncated { offset, len, .. }) => {
                prop_assert!(!ends.contains(&cut));
                prop_assert_eq!(len, cut as u64);
                let start = ends.iter().copied().filter(|&e| e < cut).max().unwrap();
                prop_assert_eq!(offset, start as u64);
            }
            Err(other) => prop_assert!(false, "cut at {cut}: {other}"),
        }
        let mut v2 = headers()[0].to_vec();
        let header = v2.len();
        for i in 0..40u32 {
            v2.extend((i << 12).to_be_bytes());
            v2.extend((100 + i).to_be_bytes());
        }
        let cut = header + cut % (v2.len() - header + 1);
        let result = decode_all(&v2[..cut]);
        prop_assert_eq!(result.is_ok(), (cut - header).is_multiple_of(8));
    }

    /// Arbitrary bytes after a valid header: an error or events, never a panic.
    #[test]
    fn random_data_never_panics(data in proptest::collection::vec(any::<u8>(), 0..1024)) {
        for header in headers() {
            let mut bytes = header.to_vec();
            bytes.extend_from_slice(&data);
            let _ = decode_all(&bytes);
        }
    }

    /// AEDAT 3.1 packets with arbitrary header fields (including huge capacities, which must
    /// not be allocated) and arbitrary contents: an error or events, never a panic.
    #[test]
    fn arbitrary_packets_never_panic(
        packets in proptest::collection::vec(
            (0i16..5, 0i16..3, -2i32..40, 0i32..6,
             prop_oneof![-1i32..3, (i32::MAX - 1)..=i32::MAX], any::<i32>(), -1i32..8,
             proptest::collection::vec(any::<u8>(), 0..80)),
            0..6,
        ),
    ) {
        let mut bytes = headers()[1].to_vec();
        for (kind, source, size, ts_offset, overflow, capacity, number, data) in packets {
            bytes.extend(kind.to_le_bytes());
            bytes.extend(source.to_le_bytes());
            for v in [size, ts_offset, overflow, capacity, number, number] {
                bytes.extend(v.to_le_bytes());
            }
            bytes.extend(data);
        }
        let _ = decode_all(&bytes);
    }
}
