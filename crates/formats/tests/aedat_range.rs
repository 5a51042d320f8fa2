//! Reading a time range `[from, to)` of an AEDAT 4.0 file through its data table: the result is
//! exactly "read everything, then filter", only the packets in the range are read, and a missing
//! or damaged table falls back to a scan that gives the same result and says so once.

use std::io::{self, Cursor, Read, Seek};
use std::sync::OnceLock;

use evtac_events::{Event, ImuSample, Resolution, Trigger};
use evtac_formats::aedat::schema::{self, DataTableEntry};
use evtac_formats::aedat::{AedatError, AedatReader, AedatWriter, Compression, WriterConfig};
use evtac_formats::{RangeIndex, ScanReason};
use proptest::prelude::*;
use support::{Dribble, xorshift};

mod support;

const ALL: [Compression; 3] = [Compression::None, Compression::Lz4, Compression::Zstd];

/// What a read produced: (stream id, offset) per chunk, and the elements.
#[derive(Debug, Default, Clone, PartialEq)]
struct Decoded {
    chunks: Vec<(i32, u64)>,
    events: Vec<Event>,
    imu: Vec<ImuSample>,
    triggers: Vec<Trigger>,
}

fn decode<R: Read>(reader: &mut AedatReader<R>) -> Result<Decoded, AedatError> {
    let mut d = Decoded::default();
    while let Some(c) = reader.next_chunk()? {
        assert!(
            !(c.events.is_empty() && c.imu.is_empty() && c.triggers.is_empty()),
            "empty chunk at byte {}",
            c.offset
        );
        d.chunks.push((c.stream_id, c.offset));
        d.events.extend_from_slice(c.events);
        d.imu.extend_from_slice(c.imu);
        d.triggers.extend_from_slice(c.triggers);
    }
    Ok(d)
}

/// The reference: decode the whole file, then keep `from <= t < to` (and the chunks that keep
/// anything).
fn read_then_filter(bytes: &[u8], from: i64, to: i64) -> Decoded {
    let mut reader = AedatReader::from_slice(bytes).unwrap();
    let mut d = Decoded::default();
    let inside = |t: i64| from <= t && t < to;
    while let Some(c) = reader.next_chunk().unwrap() {
        let events: Vec<Event> = c.events.iter().copied().filter(|e| inside(e.t)).collect();
        let imu: Vec<ImuSample> = c.imu.iter().copied().filter(|s| inside(s.t)).collect();
        let triggers: Vec<Trigger> = c.triggers.iter().copied().filter(|t| inside(t.t)).collect();
        if !(events.is_empty() && imu.is_empty() && triggers.is_empty()) {
            d.chunks.push((c.stream_id, c.offset));
        }
        d.events.extend(events);
        d.imu.extend(imu);
        d.triggers.extend(triggers);
    }
    d
}

fn read_range<R: Read + Seek>(reader: R, from: i64, to: i64) -> (Decoded, RangeIndex, R) {
    let mut reader = AedatReader::new(reader).unwrap();
    let index = reader.select_range(from, to).unwrap();
    let d = decode(&mut reader).unwrap();
    (d, index, reader.into_inner())
}

const T0: i64 = 1_700_000_000_000_000;

/// Seeded data over about 2 s: `n` events (bursts with equal timestamps), IMU at 1 kHz, and
/// sparse triggers.
fn synthetic(n: usize, seed: u64) -> (Vec<Event>, Vec<ImuSample>, Vec<Trigger>) {
    let mut next = xorshift(seed);
    let step = (4_000_000 / n.max(1)) as u64 + 1;
    let mut t = T0;
    let events: Vec<Event> = (0..n)
        .map(|_| {
            t += (next() % step) as i64;
            Event {
                t,
                x: (next() % 64) as u16,
                y: (next() % 48) as u16,
                polarity: next().is_multiple_of(2),
            }
        })
        .collect();
    let end = t;
    let imu = (T0..=end)
        .step_by(1000)
        .map(|t| ImuSample {
            t,
            accelerometer: [(t % 7) as f32, 0.5, -1.0],
            ..Default::default()
        })
        .collect();
    let mut t = T0;
    let mut triggers = Vec::new();
    while t <= end {
        triggers.push(Trigger {
            t,
            kind: (next() % 10) as i8,
        });
        t += [0, 3_000, 40_000][(next() % 3) as usize];
    }
    (events, imu, triggers)
}

/// A file of `n` events, IMU and triggers, with a data table unless `table` is false.
fn file(c: Compression, n: usize, table: bool) -> Vec<u8> {
    let (events, imu, triggers) = synthetic(n, 77);
    let config = WriterConfig {
        resolution: Resolution::new(64, 48),
        source_name: "cam".into(),
        compression: c,
    };
    fn fill<W: io::Write>(mut w: AedatWriter<W>, e: &[Event], i: &[ImuSample], t: &[Trigger]) -> W {
        // Interleaved by time, 10 ms at a time, as a recording arrives.
        let mut at = (0, 0, 0);
        let mut until = T0;
        while at.0 < e.len() || at.1 < i.len() || at.2 < t.len() {
            until += 10_000;
            let n = (
                e[at.0..].partition_point(|x| x.t < until),
                i[at.1..].partition_point(|x| x.t < until),
                t[at.2..].partition_point(|x| x.t < until),
            );
            w.write_events(&e[at.0..at.0 + n.0]).unwrap();
            w.write_imu(&i[at.1..at.1 + n.1]).unwrap();
            w.write_triggers(&t[at.2..at.2 + n.2]).unwrap();
            at = (at.0 + n.0, at.1 + n.1, at.2 + n.2);
        }
        w.finish().unwrap()
    }
    if table {
        let w = AedatWriter::new_seekable(Cursor::new(Vec::new()), config).unwrap();
        fill(w, &events, &imu, &triggers).into_inner()
    } else {
        fill(
            AedatWriter::new(Vec::new(), config).unwrap(),
            &events,
            &imu,
            &triggers,
        )
    }
}

/// One multi-packet file per compression, made once.
fn files() -> &'static [Vec<u8>; 3] {
    static FILES: OnceLock<[Vec<u8>; 3]> = OnceLock::new();
    FILES.get_or_init(|| ALL.map(|c| file(c, 60_000, true)))
}

fn table_position(bytes: &[u8]) -> usize {
    let reader = AedatReader::from_slice(bytes).unwrap();
    reader.header().data_table_position.unwrap() as usize
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn range_read_equals_read_everything_then_filter(
        compression in 0usize..3,
        a in -100_000i64..2_200_000,
        len in 1i64..400_000,
    ) {
        let bytes = &files()[compression];
        let (from, to) = (T0 + a, T0 + a + len);
        let (got, index, _) = read_range(Cursor::new(bytes), from, to);
        prop_assert!(matches!(index, RangeIndex::DataTable { .. }), "{index:?}");
        let expected = read_then_filter(bytes, from, to);
        prop_assert_eq!(&got.chunks, &expected.chunks);
        prop_assert!(got == expected);
    }
}

#[test]
fn ranges_at_the_edges_are_exact() {
    for (bytes, c) in files().iter().zip(ALL) {
        let all = read_then_filter(bytes, i64::MIN, i64::MAX);
        let first = all.events[0].t;
        let last = all.events.last().unwrap().t;
        for (from, to) in [
            (i64::MIN, i64::MAX),
            (i64::MIN, first),
            (i64::MIN, first + 1),
            (first, first + 1),
            (last, last + 1),
            (last + 1, i64::MAX),
            (T0 - 10, T0),
        ] {
            let (got, index, _) = read_range(Cursor::new(bytes), from, to);
            assert!(
                matches!(index, RangeIndex::DataTable { .. }),
                "{c}: {index:?}"
            );
            assert!(
                got == read_then_filter(bytes, from, to),
                "{c}: [{from}, {to})"
            );
        }
    }
}

#[test]
fn empty_range_is_an_error() {
    let mut reader = AedatReader::new(Cursor::new(&files()[0])).unwrap();
    let err = reader.select_range(T0 + 5, T0 + 5).unwrap_err();
    assert!(
        matches!(err, AedatError::EmptyRange { from, to } if from == to),
        "{err}"
    );
    assert!(err.to_string().contains("empty"), "{err}");
}

#[test]
fn range_read_starts_over_after_a_full_read() {
    let bytes = &files()[1];
    let mut reader = AedatReader::new(Cursor::new(bytes)).unwrap();
    decode(&mut reader).unwrap();
    for (from, to) in [(T0 + 300_000, T0 + 310_000), (T0, T0 + 50_000)] {
        reader.select_range(from, to).unwrap();
        assert!(decode(&mut reader).unwrap() == read_then_filter(bytes, from, to));
    }
}

#[test]
fn read_size_does_not_change_a_range_read() {
    for bytes in files() {
        let (from, to) = (T0 + 500_000, T0 + 620_000);
        let (whole, _, _) = read_range(Cursor::new(bytes), from, to);
        assert!(!whole.events.is_empty());
        for step in [1, 7, 65536] {
            let (got, _, _) = read_range(Dribble::new(bytes, step), from, to);
            assert!(got == whole, "read size {step} changed the output");
        }
    }
}

#[test]
fn a_small_range_reads_only_its_packets() {
    // About 32 MB uncompressed, 800 packets.
    let bytes = file(Compression::None, 2_000_000, true);
    let (from, to) = (T0 + 1_000_000, T0 + 1_005_000);
    let (got, index, dribble) = read_range(Dribble::new(&bytes, usize::MAX), from, to);
    let RangeIndex::DataTable { packets, total } = index else {
        panic!("{index:?}");
    };
    assert!(packets <= 6 && total > 500, "{packets} of {total}");
    assert!(got == read_then_filter(&bytes, from, to));
    assert!(got.events.len() > 1000);
    // The header, the data table (about 60 bytes a packet) and a few packets of 64 KiB.
    let table = bytes.len() - table_position(&bytes);
    assert!(
        dribble.read < (table + 20_000 + packets * 70_000) as u64,
        "read {} of {} bytes (table {table})",
        dribble.read,
        bytes.len()
    );
    assert!(dribble.read * 100 < bytes.len() as u64);
}

#[test]
fn missing_table_falls_back_to_a_scan_with_the_same_result() {
    for c in ALL {
        let bytes = file(c, 20_000, false);
        assert_eq!(
            AedatReader::from_slice(&bytes)
                .unwrap()
                .header()
                .data_table_position,
            None
        );
        let (from, to) = (T0 + 200_000, T0 + 900_000);
        let (got, index, _) = read_range(Cursor::new(&bytes), from, to);
        assert_eq!(index, RangeIndex::Scan(ScanReason::NoDataTable), "{c}");
        assert_eq!(index.fallback(), Some(&ScanReason::NoDataTable));
        assert!(got == read_then_filter(&bytes, from, to), "{c}");
    }
}

/// Ways to damage a file's data table, each of which the range reader must notice.
fn damaged(bytes: &[u8], how: &str) -> Vec<u8> {
    let table = table_position(bytes);
    let mut bad = bytes.to_vec();
    match how {
        // The table's file identifier (after its size prefix and root offset; compressed tables
        // get their frame mangled instead).
        "identifier" => bad[table + 4..table + 12].copy_from_slice(b"garbage!"),
        // The file is cut inside its table.
        "cut" => bad.truncate(table + (bad.len() - table) / 2),
        // The file is cut just before its table: every packet is there, the table is not.
        "gone" => bad.truncate(table),
        // Uncompressed: the last entry's ByteOffset moved by 8 bytes (the entries no longer
        // tile). Offsets that large occur nowhere else in the table.
        "offset" => {
            let reader = AedatReader::from_slice(bytes).unwrap();
            let body = *decode_offsets(reader).last().unwrap() as i64 + 8;
            let at = table
                + bad[table..]
                    .windows(8)
                    .position(|w| w == body.to_le_bytes())
                    .unwrap();
            bad[at..at + 8].copy_from_slice(&(body + 8).to_le_bytes());
        }
        _ => unreachable!(),
    }
    bad
}

fn decode_offsets(mut reader: AedatReader<&[u8]>) -> Vec<u64> {
    let mut out = Vec::new();
    while let Some(c) = reader.next_chunk().unwrap() {
        out.push(c.offset);
    }
    out
}

#[test]
fn damaged_table_falls_back_to_a_scan_with_the_same_result() {
    for (bytes, c) in files().iter().zip(ALL) {
        let hows: &[&str] = if c == Compression::None {
            &["identifier", "cut", "gone", "offset"]
        } else {
            &["identifier", "cut", "gone"]
        };
        for how in hows {
            let bad = damaged(bytes, how);
            let (from, to) = (T0 + 700_000, T0 + 1_100_000);
            let mut reader = AedatReader::new(Cursor::new(&bad)).unwrap();
            let index = reader.select_range(from, to).unwrap();
            let Some(ScanReason::DamagedDataTable { reason, .. }) = index.fallback() else {
                panic!("{c} {how}: {index:?}");
            };
            assert!(!reason.is_empty());
            let got = decode(&mut reader).unwrap();
            assert!(
                got == read_then_filter(bytes, from, to),
                "{c} {how}: {reason}"
            );
        }
    }
}

#[test]
fn dvxplorer_fixture_range_reads_through_its_data_table() {
    let Some(path) = evtac_testkit::real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let bytes = std::fs::read(path).unwrap();
    let all = read_then_filter(&bytes, i64::MIN, i64::MAX);
    let first = all.events[0].t;
    for (from, to) in [
        (first + 100_000, first + 150_000),
        (first, first + 1),
        (i64::MIN, i64::MAX),
    ] {
        let (got, index, _) = read_range(Cursor::new(&bytes), from, to);
        assert!(matches!(index, RangeIndex::DataTable { .. }), "{index:?}");
        assert!(got == read_then_filter(&bytes, from, to), "[{from}, {to})");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Damage anywhere never panics a range read. Damage confined to the data table makes the
    /// read fall back to a scan, fail, or read through the table; what it gives is then always
    /// taken from the file's packets in the range, in file order (a table damaged in a way no
    /// check sees can make it miss a packet, never invent or reorder data).
    #[test]
    fn damaged_files_never_panic_a_range_read(
        compression in 0usize..3,
        flips in proptest::collection::vec((0.0f64..1.0, 1u8..=255), 1..6),
        in_table in any::<bool>(),
        a in 0i64..2_000_000,
    ) {
        let bytes = &files()[compression];
        let table = table_position(bytes);
        let lo = if in_table { table } else { 0 };
        let mut bad = bytes.clone();
        for (at, x) in flips {
            let i = lo + (at * (bytes.len() - lo) as f64) as usize;
            bad[i.min(bytes.len() - 1)] ^= x;
        }
        let (from, to) = (T0 + a, T0 + a + 50_000);
        let result = AedatReader::new(Cursor::new(&bad))
            .and_then(|mut r| r.select_range(from, to).map(|_| r))
            .and_then(|mut r| decode(&mut r));
        if let (true, Ok(got)) = (in_table, result) {
            let expected = read_then_filter(bytes, from, to);
            prop_assert!(is_subsequence(&got.events, &expected.events));
            prop_assert!(is_subsequence(&got.imu, &expected.imu));
            prop_assert!(is_subsequence(&got.triggers, &expected.triggers));
        }
    }
}

/// Whether `part` is `whole` with some elements left out.
fn is_subsequence<T: PartialEq>(part: &[T], whole: &[T]) -> bool {
    let mut rest = whole.iter();
    part.iter().all(|p| rest.any(|w| w == p))
}

/// The uncompressed test file with its data table rebuilt after `edit` changed its entries.
fn with_edited_table(edit: impl FnOnce(&mut Vec<DataTableEntry>)) -> Vec<u8> {
    let bytes = &files()[0];
    let table = table_position(bytes);
    let root = schema::size_prefixed_root_as_file_data_table(&bytes[table..]).unwrap();
    let mut entries: Vec<DataTableEntry> =
        root.table().unwrap().iter().map(|d| d.entry()).collect();
    edit(&mut entries);
    let mut fbb = flatbuffers::FlatBufferBuilder::new();
    schema::build_file_data_table(&mut fbb, &entries);
    let mut out = bytes[..table].to_vec();
    out.extend_from_slice(fbb.finished_data());
    out
}

/// Found by `damaged_files_never_panic_a_range_read`: a huge element count overflowed the
/// element index kept for error messages.
#[test]
fn huge_element_count_in_the_table_falls_back_instead_of_overflowing() {
    let bad = with_edited_table(|e| e[3].num_elements = i64::MAX);
    let (from, to) = (T0 + 100_000, T0 + 300_000);
    let (got, index, _) = read_range(Cursor::new(&bad), from, to);
    let Some(ScanReason::DamagedDataTable { reason, .. }) = index.fallback() else {
        panic!("{index:?}");
    };
    assert!(reason.contains("entry 3 counts"), "{reason}");
    assert!(got == read_then_filter(&files()[0], from, to));
}

#[test]
fn a_table_entry_that_lies_about_a_selected_packet_is_an_error() {
    let bytes = &files()[0];
    let first = AedatReader::from_slice(bytes)
        .unwrap()
        .next_chunk()
        .unwrap()
        .map(|c| (c.offset, c.events.len()))
        .unwrap();
    let bad = with_edited_table(|e| e[0].num_elements += 1);
    let mut reader = AedatReader::new(Cursor::new(&bad)).unwrap();
    let index = reader.select_range(T0, T0 + 1000).unwrap();
    assert!(matches!(index, RangeIndex::DataTable { .. }), "{index:?}");
    let err = decode(&mut reader).unwrap_err();
    assert!(
        matches!(
            err,
            AedatError::DataTableMismatch { offset, field: "NumElements", table, found }
                if offset == first.0 && found == first.1 as i64 && table == found + 1
        ),
        "{err}"
    );
}
