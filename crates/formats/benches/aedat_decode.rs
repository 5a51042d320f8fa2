//! AEDAT 4.0 decoding throughput (events/s), LZ4 and zstd, against the raw decompressors.
//!
//! Setup writes three files of 3 million synthetic events (640x480, ~1 Mev/s, seeded) with our
//! writer into `$EVTAC_BENCH_DIR` (default: `<tmp>/evtac-aedat-bench`), where
//! `benches/aedat_reference.py` times dv-processing and the `aedat` Python package on the same
//! files. Groups:
//! - `aedat_decode/{none,lz4,zstd}`: `AedatReader` over the file held in memory, all events
//!   (`none` shows the cost of framing, verification and conversion alone).
//! - `decompress_only/{lz4,zstd}`: the bare lz4_flex block decoder / zstd context alone on the same
//!   packet payloads (the floor).
//! - `aedat_range/{table,decode_all_then_filter}`: the events of a 10 ms window in the middle of
//!   the LZ4 file (about 20 000 of the 3 million), read through the data table
//!   (`AedatReader::select_range`) against decoding the whole file and keeping the window.

use std::hint::black_box;
use std::io::Cursor;
use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use evtac_events::{Event, Resolution};
use evtac_formats::aedat::{AedatReader, AedatWriter, Compression, WriterConfig};

const EVENTS: usize = 3_000_000;

/// Seeded synthetic events (xorshift64): 0..=1 us apart, uniform over the sensor.
fn events(res: Resolution) -> Vec<Event> {
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let mut t = 1_700_000_000_000_000i64;
    (0..EVENTS)
        .map(|_| {
            let r = next();
            t += (r & 1) as i64;
            Event {
                t,
                x: ((r >> 8) % u64::from(res.width)) as u16,
                y: ((r >> 24) % u64::from(res.height)) as u16,
                polarity: r >> 63 == 1,
            }
        })
        .collect()
}

fn bench_dir() -> PathBuf {
    std::env::var_os("EVTAC_BENCH_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("evtac-aedat-bench"))
}

/// The compressed bodies of every packet in an AEDAT 4.0 file (up to its data table).
fn payloads(bytes: &[u8]) -> Vec<&[u8]> {
    let reader = AedatReader::from_slice(bytes).expect("our own file");
    let end = reader.header().data_table_position.expect("data table") as usize;
    let header_len = u32::from_le_bytes(bytes[14..18].try_into().expect("4 bytes")) as usize;
    let mut pos = 18 + header_len;
    let mut out = Vec::new();
    while pos < end {
        let size = i32::from_le_bytes(bytes[pos + 4..pos + 8].try_into().expect("4 bytes"));
        let size = usize::try_from(size).expect("non-negative size");
        out.push(&bytes[pos + 8..pos + 8 + size]);
        pos += 8 + size;
    }
    out
}

/// The compressed blocks of an LZ4 frame as our writer makes it (no checksums, no content size;
/// uncompressed blocks do not occur in these files).
fn lz4_blocks(frame: &[u8]) -> Vec<&[u8]> {
    let mut pos = 7;
    let mut blocks = Vec::new();
    loop {
        let head = u32::from_le_bytes(frame[pos..pos + 4].try_into().expect("4 bytes"));
        pos += 4;
        if head == 0 {
            return blocks;
        }
        assert_eq!(head & 0x8000_0000, 0, "uncompressed block");
        let size = head as usize;
        blocks.push(&frame[pos..pos + size]);
        pos += size;
    }
}

fn decode(c: &mut Criterion) {
    let res = Resolution::new(640, 480);
    let events = events(res);
    let dir = bench_dir();
    std::fs::create_dir_all(&dir).expect("bench dir");
    let mut files = Vec::new();
    for (name, compression) in [
        ("none", Compression::None),
        ("lz4", Compression::Lz4),
        ("zstd", Compression::Zstd),
    ] {
        let path = dir.join(format!("bench_{name}.aedat4"));
        let config = WriterConfig {
            resolution: res,
            source_name: "DVXplorer_BENCH".into(),
            compression,
        };
        let mut w = AedatWriter::create(&path, config).expect("create");
        w.write_events(&events).expect("write");
        w.finish().expect("finish");
        eprintln!("wrote {}", path.display());
        files.push((name, std::fs::read(&path).expect("read back")));
    }

    let mut g = c.benchmark_group("aedat_decode");
    g.throughput(Throughput::Elements(EVENTS as u64));
    for (name, bytes) in &files {
        g.bench_function(*name, |b| {
            b.iter(|| {
                let mut r = AedatReader::from_slice(black_box(bytes)).expect("header");
                let mut n = 0usize;
                while let Some(chunk) = r.next_chunk().expect("decode") {
                    n += chunk.events.len();
                }
                assert_eq!(n, EVENTS);
                n
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("decompress_only");
    g.throughput(Throughput::Elements(EVENTS as u64));
    // Uncompressed: nothing to decompress, so no floor to compare with.
    for (name, bytes) in files.iter().filter(|(name, _)| *name != "none") {
        let packets = payloads(bytes);
        let blocks: Vec<Vec<&[u8]>> = if *name == "lz4" {
            packets.iter().map(|p| lz4_blocks(p)).collect()
        } else {
            Vec::new()
        };
        let mut out = Vec::with_capacity(1 << 20);
        let mut zstd_ctx = zstd::bulk::Decompressor::new().expect("zstd context");
        g.bench_function(*name, |b| {
            b.iter(|| {
                let mut total = 0usize;
                if *name == "lz4" {
                    // The bare block decoder over each frame's blocks: no frame parsing.
                    out.resize(1 << 20, 0);
                    for packet in &blocks {
                        let mut len = 0;
                        for block in packet {
                            let (before, rest) = out.split_at_mut(len);
                            let dict = &before[len.saturating_sub(1 << 16)..];
                            len += lz4_flex::block::decompress_into_with_dict(block, rest, dict)
                                .expect("lz4");
                        }
                        total += len;
                    }
                } else {
                    for p in &packets {
                        out.clear();
                        out.reserve(1 << 20);
                        zstd_ctx.decompress_to_buffer(p, &mut out).expect("zstd");
                        total += out.len();
                    }
                }
                black_box(total)
            })
        });
    }
    g.finish();

    let Some((_, lz4)) = files.iter().find(|(name, _)| *name == "lz4") else {
        return;
    };
    let from = events[EVENTS / 2].t;
    let to = from + 10_000;
    let expected = events.iter().filter(|e| from <= e.t && e.t < to).count();
    let mut g = c.benchmark_group("aedat_range");
    g.throughput(Throughput::Elements(expected as u64));
    g.bench_function("table", |b| {
        b.iter(|| {
            let mut r = AedatReader::new(Cursor::new(black_box(lz4))).expect("header");
            r.select_range(from, to).expect("range");
            let mut n = 0usize;
            while let Some(chunk) = r.next_chunk().expect("decode") {
                n += chunk.events.len();
            }
            assert_eq!(n, expected);
            n
        })
    });
    g.bench_function("decode_all_then_filter", |b| {
        b.iter(|| {
            let mut r = AedatReader::from_slice(black_box(lz4)).expect("header");
            let mut n = 0usize;
            while let Some(chunk) = r.next_chunk().expect("decode") {
                n += chunk
                    .events
                    .iter()
                    .filter(|e| from <= e.t && e.t < to)
                    .count();
            }
            assert_eq!(n, expected);
            n
        })
    });
    g.finish();
}

criterion_group!(benches, decode);
criterion_main!(benches);
