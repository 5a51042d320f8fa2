//! The bad-input matrix: every reader x {empty file, cut at every byte (so at every packet
//! boundary and inside every packet), one flipped byte in every header field, wrong magic or
//! version, timestamps going back, coordinates outside the sensor, a declared size of 4 GiB}.
//!
//! Each case is written to a file and read through the whole-file API ([`evtac_formats::open`]),
//! as the CLI reads it. It must give either the events it still holds (only a file cut where a
//! packet ends, in a format that declares no length) or an error whose message names the file
//! and locates the problem (a byte offset, line, field or key). Nothing may panic, and no single
//! allocation may exceed [`ALLOCATION_LIMIT`], whatever sizes the file claims.
//!
//! All failures are collected and reported together, one line per case. The AEDAT 2.0 and 3.1
//! rows are in `bad_input_legacy.rs`.

use std::ops::Range;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use evtac_events::{Event, Resolution};
use evtac_formats::aedat::{AedatReader, AedatWriter, Compression, WriterConfig};
use evtac_formats::csv::CsvWriter;
use evtac_formats::npy::NpyWriter;

use crate::alloc::largest_allocation_during;
use crate::common::with_dict;

/// The sensor every sample declares.
pub(crate) const SENSOR: Resolution = Resolution::new(64, 32);
/// The largest single allocation a read may make. The readers' fixed buffers (event chunks,
/// read buffers) take a few hundred KiB; the files are a few KiB; the claims go up to 4 GiB.
const ALLOCATION_LIMIT: usize = 16 << 20;
/// Words at least one of which an error message must contain: what locates the problem (an
/// empty file has no place to name: saying so is enough; a container's member or topic is a
/// place). An event's index (`event 3 at ...`) locates it too, see [`names_an_event`].
const LOCATORS: [&str; 12] = [
    "byte",
    "member",
    "topic",
    "line",
    "field",
    "character",
    "key",
    "magic",
    "version",
    "IOHeader",
    "infoNode",
    "empty",
];

/// A header field: a name for the report, its bytes, and whether inverting any of its bytes
/// must make the file unreadable (a magic, a version or a size must; a free-text value may be
/// anything).
pub(crate) struct Field {
    pub(crate) name: String,
    pub(crate) range: Range<usize>,
    pub(crate) must_fail: bool,
}

/// A small valid file of one format, and what the matrix needs to know about its layout.
pub(crate) struct Sample {
    pub(crate) label: &'static str,
    /// File name; the extension is how CSV files are recognised.
    pub(crate) file: &'static str,
    pub(crate) bytes: Vec<u8>,
    /// Sensor size to declare (CSV and NPY files do not store one).
    pub(crate) declare: Option<Resolution>,
    /// The cuts that leave a valid shorter file, with the number of events it still holds. Every
    /// other cut (from 0 to the length) must be an error.
    pub(crate) valid_cuts: Vec<(usize, usize)>,
    pub(crate) header: Vec<Field>,
}

/// The events every sample holds: 40 ms, so the AEDAT4 writer makes several packets.
pub(crate) fn events() -> Vec<Event> {
    (0..10u16)
        .map(|i| Event {
            t: 1_000_000 + 4_000 * i64::from(i) + i64::from(i % 3),
            x: i * 7 % 64,
            y: i * 5 % 32,
            polarity: i % 2 == 0,
        })
        .collect()
}

/// Whether `message` names an event by its index (`event 3`): the place of a value the
/// checks refuse in a format of columns, where no single byte offset holds an event.
fn names_an_event(message: &str) -> bool {
    message
        .match_indices("event ")
        .any(|(i, m)| message[i + m.len()..].starts_with(|c: char| c.is_ascii_digit()))
}

/// What reading a case gave.
enum Outcome {
    Events(Vec<Event>),
    Error(String),
    Panic(String),
}

/// Reads `bytes` as the file `file` in `dir`, as the CLI does: returns the outcome and the
/// largest single allocation made.
fn read(dir: &Path, file: &str, bytes: &[u8], declare: Option<Resolution>) -> (Outcome, usize) {
    let path = dir.join(file);
    std::fs::write(&path, bytes).expect("write case");
    let run = || -> Result<Vec<Event>, evtac_formats::Error> {
        let mut reader = evtac_formats::open(&path)?;
        if let Some(r) = declare {
            reader.set_resolution(r)?;
        }
        let mut events = Vec::new();
        while let Some(chunk) = reader.next_chunk()? {
            events.extend_from_slice(chunk.events);
        }
        Ok(events)
    };
    let (result, largest) = largest_allocation_during(|| catch_unwind(AssertUnwindSafe(run)));
    let outcome = match result {
        Ok(Ok(events)) => Outcome::Events(events),
        Ok(Err(e)) => Outcome::Error(e.to_string()),
        Err(panic) => Outcome::Panic(
            panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default(),
        ),
    };
    (outcome, largest)
}

/// Runs the cases of one sample and collects what went wrong.
pub(crate) struct Matrix<'a> {
    dir: &'a Path,
    failures: Vec<String>,
    cases: usize,
}

/// What a case must give.
pub(crate) enum Expect<'a> {
    /// An error naming the file and the place.
    Error,
    /// Exactly these events.
    Events(&'a [Event]),
    /// Either of the above (a flipped byte in free text may change nothing, or break the file).
    EventsOrError,
}

impl Matrix<'_> {
    pub(crate) fn case(&mut self, sample: &Sample, case: &str, bytes: &[u8], expect: Expect<'_>) {
        self.cases += 1;
        let name = format!("{} / {case}", sample.label);
        let (outcome, largest) = read(self.dir, sample.file, bytes, sample.declare);
        if largest > ALLOCATION_LIMIT {
            self.failures.push(format!(
                "{name}: allocated {largest} bytes at once from a {}-byte file",
                bytes.len()
            ));
        }
        let path = self.dir.join(sample.file).display().to_string();
        match (outcome, expect) {
            (Outcome::Panic(message), _) => {
                self.failures.push(format!("{name}: panicked: {message}"));
            }
            (Outcome::Error(message), Expect::Error | Expect::EventsOrError) => {
                if !message.contains(&path) {
                    self.failures.push(format!(
                        "{name}: the error does not name the file: {message}"
                    ));
                }
                if !LOCATORS.iter().any(|w| message.contains(w)) && !names_an_event(&message) {
                    self.failures.push(format!(
                        "{name}: the error names no offset, line or field: {message}"
                    ));
                }
            }
            (Outcome::Error(message), Expect::Events(_)) => {
                self.failures
                    .push(format!("{name}: unexpected error: {message}"));
            }
            (Outcome::Events(got), Expect::Error) => self.failures.push(format!(
                "{name}: read {} events, expected an error",
                got.len()
            )),
            (Outcome::Events(got), Expect::Events(want)) => {
                if got != want {
                    self.failures.push(format!(
                        "{name}: read {} events, expected {}",
                        got.len(),
                        want.len()
                    ));
                }
            }
            (Outcome::Events(_), Expect::EventsOrError) => {}
        }
    }

    /// The cases every sample gets: empty, every cut, every header byte inverted and with its
    /// lowest bit flipped.
    pub(crate) fn generic(&mut self, sample: &Sample, events: &[Event]) {
        self.case(sample, "intact", &sample.bytes, Expect::Events(events));
        self.case(sample, "empty", &[], Expect::Error);
        for cut in 0..sample.bytes.len() {
            let expect = match sample.valid_cuts.iter().find(|(at, _)| *at == cut) {
                Some(&(_, n)) => Expect::Events(&events[..n]),
                None => Expect::Error,
            };
            self.case(
                sample,
                &format!("cut at byte {cut}"),
                &sample.bytes[..cut],
                expect,
            );
        }
        for field in &sample.header {
            for i in field.range.clone() {
                for (mask, must_fail) in [(0xFF, field.must_fail), (0x01, false)] {
                    let mut bytes = sample.bytes.clone();
                    bytes[i] ^= mask;
                    let expect = if must_fail {
                        Expect::Error
                    } else {
                        Expect::EventsOrError
                    };
                    let case = format!("{} byte {i} ^ {mask:#04x}", field.name);
                    self.case(sample, &case, &bytes, expect);
                }
            }
        }
    }

    fn finish(self) {
        // Shown with `--nocapture`: the case counts `docs/reliability.md` reports.
        eprintln!("{} cases", self.cases);
        assert!(
            self.failures.is_empty(),
            "{} of {} cases failed:\n{}",
            self.failures.len(),
            self.cases,
            self.failures.join("\n")
        );
    }
}

pub(crate) fn with_matrix(f: impl FnOnce(&mut Matrix<'_>)) {
    let dir = tempfile::tempdir().unwrap();
    let mut matrix = Matrix {
        dir: dir.path(),
        failures: Vec::new(),
        cases: 0,
    };
    f(&mut matrix);
    matrix.finish();
}

/// The offset of the only occurrence of `needle` in `haystack`.
pub(crate) fn find_once(haystack: &[u8], needle: &[u8]) -> usize {
    let hits: Vec<usize> = haystack
        .windows(needle.len())
        .enumerate()
        .filter(|(_, w)| *w == needle)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(hits.len(), 1, "expected one occurrence of {needle:?}");
    hits[0]
}

// ---------------------------------------------------------------------------------------------
// EVT 2.0 and 3.0
// ---------------------------------------------------------------------------------------------

/// Text header lines (`%` for EVT, `#` for AEDAT 2.0 / 3.1), each with whether every change of
/// one must make the file unreadable: their bytes, one field per line, and a valid cut (with no
/// events) after each line, since a file cut there is a header without data.
pub(crate) fn evt_header_fields(
    lines: &[(&str, bool)],
) -> (Vec<u8>, Vec<Field>, Vec<(usize, usize)>) {
    let mut bytes = Vec::new();
    let mut valid_cuts = Vec::new();
    let mut header = Vec::new();
    for &(line, must_fail) in lines {
        let start = bytes.len();
        bytes.extend_from_slice(line.as_bytes());
        header.push(Field {
            name: format!("header line `{}`", line.trim_end()),
            range: start..bytes.len(),
            must_fail,
        });
        valid_cuts.push((bytes.len(), 0));
    }
    (bytes, header, valid_cuts)
}

/// An EVT file: header lines, then the words of each event (several words per event for EVT3).
/// Returns the sample; cuts are valid at every line end of the header and every word end.
pub(crate) fn evt_sample(
    label: &'static str,
    version: &str,
    geometry: &str,
    word_size: usize,
    encode: impl Fn(&Event) -> Vec<u64>,
    events: &[Event],
) -> Sample {
    let (version, geometry) = (
        format!("% evt {version}\n"),
        format!("% geometry {geometry}\n"),
    );
    let (mut bytes, header, mut valid_cuts) =
        evt_header_fields(&[(&version, true), (&geometry, false), ("% end\n", false)]);
    for (n, e) in events.iter().enumerate() {
        for word in encode(e) {
            bytes.extend_from_slice(&word.to_le_bytes()[..word_size]);
            valid_cuts.push((bytes.len(), n));
        }
        // The last word of an event emits it.
        valid_cuts.last_mut().unwrap().1 = n + 1;
    }
    Sample {
        label,
        file: "case.raw",
        bytes,
        declare: None,
        valid_cuts,
        header,
    }
}

fn evt2_words(e: &Event) -> Vec<u64> {
    let t = e.t as u64;
    vec![
        0x8000_0000 | t >> 6,
        u64::from(e.polarity) << 28 | (t & 0x3F) << 22 | u64::from(e.x) << 11 | u64::from(e.y),
    ]
}

fn evt3_words(e: &Event) -> Vec<u64> {
    let t = e.t as u64;
    vec![
        0x8000 | (t >> 12 & 0xFFF),
        0x6000 | (t & 0xFFF),
        u64::from(e.y),
        0x2000 | u64::from(e.polarity) << 11 | u64::from(e.x),
    ]
}

fn evt_cases(version: &str, word_size: usize, encode: fn(&Event) -> Vec<u64>) {
    let label = match word_size {
        2 => "EVT3",
        4 => "EVT2",
        _ => "EVT2.1",
    };
    let good = events();
    with_matrix(|m| {
        let sample = evt_sample(label, version, "64x32", word_size, encode, &good);
        m.generic(&sample, &good);

        // EVT 2.1 is read too (a different word size), so the wrong EVT2 version is 2.5.
        let wrong_version = if word_size == 2 { "4.0" } else { "2.5" };
        let bad = evt_sample(label, wrong_version, "64x32", word_size, encode, &good);
        m.case(&sample, "wrong version", &bad.bytes, Expect::Error);

        let mut back = good.clone();
        back[6].t = back[5].t - 5_000;
        let bad = evt_sample(label, version, "64x32", word_size, encode, &back);
        m.case(&sample, "timestamps going back", &bad.bytes, Expect::Error);

        let mut outside = good.clone();
        outside[4].x = 64;
        let bad = evt_sample(label, version, "64x32", word_size, encode, &outside);
        m.case(&sample, "x outside the sensor", &bad.bytes, Expect::Error);
        outside[4].x = 3;
        outside[7].y = 32;
        let bad = evt_sample(label, version, "64x32", word_size, encode, &outside);
        m.case(&sample, "y outside the sensor", &bad.bytes, Expect::Error);

        // EVT declares no sizes but the sensor's.
        let huge = "4294967296x4294967296";
        let bad = evt_sample(label, version, huge, word_size, encode, &good);
        m.case(&sample, "a 4 GiB x 4 GiB sensor", &bad.bytes, Expect::Error);
    });
}

#[test]
fn evt2_bad_input_matrix() {
    evt_cases("2.0", 4, evt2_words);
}

#[test]
fn evt3_bad_input_matrix() {
    evt_cases("3.0", 2, evt3_words);
}

/// EVT 2.1: a TIME_HIGH word, then a vectorised CD word whose mask marks the one event's column
/// within its 32-column group.
fn evt21_words(e: &Event) -> Vec<u64> {
    let t = e.t as u64;
    let x = u64::from(e.x);
    vec![
        0x8 << 60 | (t >> 6) << 32,
        u64::from(e.polarity) << 60
            | (t & 0x3F) << 54
            | (x & !31) << 43
            | u64::from(e.y) << 32
            | 1 << (x & 31),
    ]
}

#[test]
fn evt21_bad_input_matrix() {
    evt_cases("2.1", 8, evt21_words);
}

// ---------------------------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------------------------

fn csv_bytes(events: &[Event]) -> Vec<u8> {
    let mut writer = CsvWriter::new(Vec::new()).unwrap();
    writer.write_events(events).unwrap();
    writer.finish().unwrap()
}

#[test]
fn csv_bad_input_matrix() {
    let good = events();
    let bytes = csv_bytes(&good);
    // A line is complete with or without its line break.
    let line_ends: Vec<usize> = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .map(|(i, _)| i + 1)
        .collect();
    let mut valid_cuts = Vec::new();
    for (n, end) in line_ends.iter().enumerate() {
        valid_cuts.push((end - 1, n));
        valid_cuts.push((*end, n));
    }
    let sample = Sample {
        label: "CSV",
        file: "case.csv",
        header: vec![Field {
            name: "header line".into(),
            range: 0..line_ends[0],
            must_fail: true,
        }],
        bytes,
        declare: Some(SENSOR),
        valid_cuts,
    };
    with_matrix(|m| {
        m.generic(&sample, &good);
        let mut bad = sample.bytes.clone();
        bad[..7].copy_from_slice(b"t,x,y,q");
        m.case(&sample, "wrong header", &bad, Expect::Error);

        let mut back = good.clone();
        back[6].t = back[5].t - 1;
        m.case(
            &sample,
            "timestamps going back",
            &csv_bytes(&back),
            Expect::Error,
        );

        let mut outside = good.clone();
        outside[4].x = 64;
        m.case(
            &sample,
            "x outside the sensor",
            &csv_bytes(&outside),
            Expect::Error,
        );
        let mut bad = sample.bytes.clone();
        bad.extend_from_slice(b"2000000,4294967296,0,1\n");
        m.case(&sample, "x of 4 Gi", &bad, Expect::Error);
    });
}

// ---------------------------------------------------------------------------------------------
// NPY
// ---------------------------------------------------------------------------------------------

fn npy_bytes(events: &[Event]) -> Vec<u8> {
    let mut writer = NpyWriter::new(std::io::Cursor::new(Vec::new())).unwrap();
    writer.write_events(events).unwrap();
    writer.finish().unwrap().into_inner()
}

#[test]
fn npy_bad_input_matrix() {
    let good = events();
    let bytes = npy_bytes(&good);
    let data = 10 + usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
    let field = |name: &str, range: Range<usize>| Field {
        name: name.into(),
        range,
        must_fail: true,
    };
    let sample = Sample {
        label: "NPY",
        file: "case.npy",
        header: vec![
            field("magic", 0..6),
            field("version", 6..8),
            field("header length", 8..10),
            field("header dictionary", 10..data),
        ],
        // The header declares the record count: every cut is an error.
        valid_cuts: vec![],
        bytes,
        declare: Some(SENSOR),
    };
    let descr = "'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')]";
    with_matrix(|m| {
        m.generic(&sample, &good);
        let mut bad = sample.bytes.clone();
        bad[5] = b'Z';
        m.case(&sample, "wrong magic", &bad, Expect::Error);
        let mut bad = sample.bytes.clone();
        bad[6] = 4;
        m.case(&sample, "version 4.0", &bad, Expect::Error);

        let mut back = good.clone();
        back[6].t = back[5].t - 1;
        m.case(
            &sample,
            "timestamps going back",
            &npy_bytes(&back),
            Expect::Error,
        );
        let mut outside = good.clone();
        outside[4].y = 32;
        m.case(
            &sample,
            "y outside the sensor",
            &npy_bytes(&outside),
            Expect::Error,
        );

        // 4 GiB claims: records, header length, and a padding field.
        let dict = format!("{{{descr}, 'fortran_order': False, 'shape': (4294967296,), }}");
        let bad = with_dict(&sample.bytes, &dict);
        m.case(&sample, "4 Gi records declared", &bad, Expect::Error);
        let mut bad = b"\x93NUMPY\x02\x00\xff\xff\xff\xff{".to_vec();
        bad.extend_from_slice(&sample.bytes[10..]);
        m.case(&sample, "a 4 GiB header length", &bad, Expect::Error);
        let padded = "'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1'), \
                      ('', '|V4294967296')]";
        let dict = format!("{{{padded}, 'fortran_order': False, 'shape': (10,), }}");
        let bad = with_dict(&sample.bytes, &dict);
        m.case(&sample, "a 4 GiB padding field", &bad, Expect::Error);
        let padded = "'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1'), \
                      ('', '|V18446744073709551615'), ('', '|V18446744073709551615')]";
        let dict = format!("{{{padded}, 'fortran_order': False, 'shape': (10,), }}");
        let bad = with_dict(&sample.bytes, &dict);
        m.case(
            &sample,
            "padding fields summing past usize",
            &bad,
            Expect::Error,
        );
    });
}

// ---------------------------------------------------------------------------------------------
// AEDAT 4.0
// ---------------------------------------------------------------------------------------------

/// Events and IMU samples written with `compression`, with a data table (`seekable`) or
/// without one (as a stream is written).
fn aedat_bytes(events: &[Event], compression: Compression, seekable: bool) -> Vec<u8> {
    let config = WriterConfig {
        resolution: SENSOR,
        source_name: "DVXplorer_TEST".into(),
        compression,
    };
    let imu: Vec<evtac_events::ImuSample> = events
        .iter()
        .map(|e| evtac_events::ImuSample {
            // Not the events' times, so that an event's timestamp occurs once in the file.
            t: e.t + 1,
            ..Default::default()
        })
        .collect();
    let write = |mut w: AedatWriter<_>| {
        for (e, s) in events.chunks(3).zip(imu.chunks(3)) {
            w.write_events(e).unwrap();
            w.write_imu(s).unwrap();
        }
        w
    };
    let sink = std::io::Cursor::new(Vec::new());
    let writer = if seekable {
        AedatWriter::new_seekable(sink, config)
    } else {
        AedatWriter::new(sink, config)
    };
    write(writer.unwrap()).finish().unwrap().into_inner()
}

/// The packets of an AEDAT 4.0 file: offset of each 8-byte packet header, and the end of the
/// IOHeader (where the first packet starts).
fn aedat_packets(bytes: &[u8]) -> (usize, Vec<Range<usize>>) {
    let le32 = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let reader = AedatReader::from_slice(bytes).unwrap();
    let end = reader
        .header()
        .data_table_position
        .map_or(bytes.len(), |p| p as usize);
    let first = 14 + 4 + le32(14);
    let mut packets = Vec::new();
    let mut at = first;
    while at < end {
        let next = at + 8 + le32(at + 4);
        packets.push(at..next);
        at = next;
    }
    (first, packets)
}

/// Events in the packet starting at each offset.
fn aedat_events_per_packet(bytes: &[u8]) -> Vec<(u64, usize)> {
    let mut reader = AedatReader::from_slice(bytes).unwrap();
    let mut out = Vec::new();
    while let Some(chunk) = reader.next_chunk().unwrap() {
        out.push((chunk.offset, chunk.events.len()));
    }
    out
}

/// An AEDAT4 sample; the IOHeader's bytes (mostly the XML stream description, the same in
/// every sample) are flipped only when `flip_io_header`, to keep the matrix quick.
fn aedat_sample(
    label: &'static str,
    compression: Compression,
    seekable: bool,
    flip_io_header: bool,
) -> Sample {
    let bytes = aedat_bytes(&events(), compression, seekable);
    let (first, packets) = aedat_packets(&bytes);
    let mut header = vec![
        Field {
            name: "magic".into(),
            range: 0..14,
            must_fail: true,
        },
        Field {
            name: "IOHeader size".into(),
            range: 14..18,
            must_fail: true,
        },
    ];
    if flip_io_header {
        header.push(Field {
            name: "IOHeader".into(),
            range: 18..first,
            must_fail: false,
        });
    }
    for (i, p) in packets.iter().enumerate() {
        header.push(Field {
            name: format!("packet {i} header (stream id, size)"),
            range: p.start..p.start + 8,
            must_fail: true,
        });
    }
    // A file with a data table is cut wherever it ends early; without one, a file cut where a
    // packet ends holds the packets before.
    let mut valid_cuts = Vec::new();
    if !seekable {
        let per_packet = aedat_events_per_packet(&bytes);
        valid_cuts.push((first, 0));
        for p in &packets {
            let n = per_packet
                .iter()
                .filter(|(at, _)| (*at as usize) < p.end)
                .map(|(_, n)| n)
                .sum();
            valid_cuts.push((p.end, n));
        }
    }
    Sample {
        label,
        file: "case.aedat4",
        bytes,
        declare: None,
        valid_cuts,
        header,
    }
}

/// A packet of stream 0 (events) holding `payload`.
fn packet(payload: &[u8]) -> Vec<u8> {
    let mut out = 0i32.to_le_bytes().to_vec();
    out.extend_from_slice(&(payload.len() as i32).to_le_bytes());
    out.extend_from_slice(payload);
    out
}

/// A zstd frame that declares `size` bytes of content and holds none (one empty raw block).
fn zstd_frame_declaring(size: u64) -> Vec<u8> {
    let mut out = vec![0x28, 0xB5, 0x2F, 0xFD];
    // Frame header descriptor: an 8-byte content size, a window descriptor (1 MiB window).
    out.extend_from_slice(&[0xC0, 0x50]);
    out.extend_from_slice(&size.to_le_bytes());
    // The last block, raw, 0 bytes.
    out.extend_from_slice(&[0x01, 0x00, 0x00]);
    out
}

#[test]
fn aedat_bad_input_matrix() {
    let good = events();
    with_matrix(|m| {
        for (label, compression, seekable, flip_io_header) in [
            (
                "AEDAT4 uncompressed, data table",
                Compression::None,
                true,
                true,
            ),
            ("AEDAT4 LZ4, no data table", Compression::Lz4, false, false),
            (
                "AEDAT4 zstd, no data table",
                Compression::Zstd,
                false,
                false,
            ),
        ] {
            let sample = aedat_sample(label, compression, seekable, flip_io_header);
            m.generic(&sample, &good);
        }

        let sample = aedat_sample("AEDAT4 uncompressed", Compression::None, false, false);
        let mut bad = sample.bytes.clone();
        bad[..14].copy_from_slice(b"#!AER-DAT3.1\r\n");
        m.case(&sample, "AEDAT 3.1 magic", &bad, Expect::Error);

        // The writer refuses bad events, so patch them into an uncompressed file: each event
        // is a 16-byte struct (t i64, x i16, y i16, polarity, padding).
        let at = find_once(&sample.bytes, &good[6].t.to_le_bytes());
        let mut bad = sample.bytes.clone();
        bad[at..at + 8].copy_from_slice(&(good[5].t - 1).to_le_bytes());
        m.case(&sample, "timestamps going back", &bad, Expect::Error);
        let mut bad = sample.bytes.clone();
        assert_eq!(bad[at + 8..at + 10], good[6].x.to_le_bytes());
        bad[at + 8..at + 10].copy_from_slice(&64u16.to_le_bytes());
        m.case(&sample, "x outside the sensor", &bad, Expect::Error);
        let mut bad = sample.bytes.clone();
        bad[at + 10..at + 12].copy_from_slice(&(-1i16).to_le_bytes());
        m.case(&sample, "negative y", &bad, Expect::Error);

        // 4 GiB claims: the IOHeader size, a packet size (an i32: 2 GiB is the most it can
        // say, and 0xFFFFFFFF reads as -1), a packet's flatbuffer size prefix, zstd frames.
        let (first, packets) = aedat_packets(&sample.bytes);
        let mut bad = sample.bytes.clone();
        bad[14..18].copy_from_slice(&u32::MAX.to_le_bytes());
        m.case(&sample, "a 4 GiB IOHeader size", &bad, Expect::Error);
        for size in [i32::MAX as u32, u32::MAX] {
            let mut bad = sample.bytes.clone();
            bad[first + 4..first + 8].copy_from_slice(&size.to_le_bytes());
            m.case(
                &sample,
                &format!("packet size {size:#x}"),
                &bad,
                Expect::Error,
            );
        }
        let mut bad = sample.bytes.clone();
        let body = packets[0].start + 8;
        bad[body..body + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        m.case(
            &sample,
            "a 4 GiB flatbuffer size prefix",
            &bad,
            Expect::Error,
        );

        let sample = aedat_sample("AEDAT4 zstd", Compression::Zstd, false, false);
        for size in [1 << 30, 1 << 32] {
            let mut bad = sample.bytes.clone();
            bad.extend_from_slice(&packet(&zstd_frame_declaring(size)));
            let case = format!("a zstd frame declaring {size} bytes");
            m.case(&sample, &case, &bad, Expect::Error);
        }
    });
}

/// A zstd packet whose frame declares 1 GiB (the most a packet may decompress to) in 20 bytes
/// made the AEDAT4 reader reserve the whole gibibyte before decoding (found by this matrix).
#[test]
fn zstd_frame_declaring_a_gibibyte_is_not_reserved() {
    let sample = aedat_sample("AEDAT4 zstd", Compression::Zstd, false, false);
    let mut bytes = sample.bytes.clone();
    bytes.extend_from_slice(&packet(&zstd_frame_declaring(1 << 30)));
    let (result, largest) = largest_allocation_during(|| {
        let mut reader = AedatReader::from_slice(&bytes)?;
        while reader.next_chunk()?.is_some() {}
        Ok::<_, evtac_formats::aedat::AedatError>(())
    });
    let err = result.unwrap_err();
    assert!(
        err.to_string().contains("frame says 1073741824 bytes"),
        "{err}"
    );
    assert!(largest < 1 << 20, "allocated {largest} bytes");
}
