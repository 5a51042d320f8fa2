//! Decoding throughput (events/s) of the readers for older setups' files: AEDAT 2.0 (jAER),
//! AEDAT 3.1 (cAER, with IMU6 and trigger packets) and Prophesee EVT 2.1, on seeded synthetic
//! recordings of a DAVIS240 / Gen4-like stream (no real fixtures of these formats exist in
//! `../shared`). The files are also written to `target/bench-files/` so that the Python reference
//! (`legacy_decode_reference.py`: iniVation's `dv.LegacyAedatFile` for AEDAT 2.0 / 3.1) times
//! exactly the same bytes; run both in one session and compare:
//!
//! ```sh
//! nice cargo bench -p evtac-events --bench legacy_decode -- --warm-up-time 1 --measurement-time 3
//! .venv/bin/python crates/formats/benches/legacy_decode_reference.py target/bench-files
//! ```

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use evtac_formats::aedat_legacy::LegacyReader;
use evtac_formats::evt::EvtReader;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Events per file: about 7 s of a 300k events/s contact stream.
const EVENTS: usize = 2_000_000;

/// Event times: steps of 0 to 6 us (300k events/s on average), from a start of 1 s.
fn times(rng: &mut ChaCha8Rng) -> Vec<u32> {
    let mut t = 1_000_000u32;
    (0..EVENTS)
        .map(|_| {
            t += rng.random_range(0..7u32);
            t
        })
        .collect()
}

/// jAER AEDAT 2.0 from a DAVIS240: big-endian (address, timestamp) records, mirrored addresses.
fn aedat2(rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut out = b"#!AER-DAT2.0\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n".to_vec();
    for t in times(rng) {
        let (x, y, p) = (
            rng.random_range(0..240u32),
            rng.random_range(0..180u32),
            rng.random_range(0..2u32),
        );
        out.extend((y << 22 | x << 12 | p << 11).to_be_bytes());
        out.extend(t.to_be_bytes());
    }
    out
}

/// cAER AEDAT 3.1: polarity packets of 4096 events, each followed by an IMU6 packet (1 kHz) and,
/// every tenth, a special packet with one rising edge, as cAER writes packet containers.
fn aedat31(rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut out =
        b"#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS240C\r\n#!END-HEADER\r\n".to_vec();
    let header = |out: &mut Vec<u8>, kind: i16, size: i32, n: usize| {
        out.extend(kind.to_le_bytes());
        out.extend(1i16.to_le_bytes());
        for v in [size, 4, 0, n as i32, n as i32, n as i32] {
            out.extend(v.to_le_bytes());
        }
    };
    let times = times(rng);
    for (i, chunk) in times.chunks(4096).enumerate() {
        header(&mut out, 1, 8, chunk.len());
        for &t in chunk {
            let (x, y, p) = (
                rng.random_range(0..240u32),
                rng.random_range(0..180u32),
                rng.random_range(0..2u32),
            );
            out.extend((x << 17 | y << 2 | p << 1 | 1).to_le_bytes());
            out.extend(t.to_le_bytes());
        }
        let (first, last) = (chunk[0], chunk[chunk.len() - 1]);
        let imu: Vec<u32> = (first..=last).step_by(1000).collect();
        header(&mut out, 3, 36, imu.len());
        for t in imu {
            out.extend(1u32.to_le_bytes());
            out.extend(t.to_le_bytes());
            for v in [0.01f32, -0.02, 1.0, 0.5, -0.3, 0.1, 31.5] {
                out.extend(v.to_le_bytes());
            }
        }
        if i % 10 == 0 {
            header(&mut out, 0, 8, 1);
            out.extend((2u32 << 1 | 1).to_le_bytes());
            out.extend(first.to_le_bytes());
        }
    }
    out
}

/// Prophesee EVT 2.1 (Gen4, 1280x720): a TIME_HIGH word when the upper bits change, then
/// vectorised CD words with one to three events among their 32 columns.
fn evt21(rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut out = b"% format EVT21;height=720;width=1280\n% end\n".to_vec();
    let mut high = None;
    let times = times(rng);
    let mut i = 0;
    while i < times.len() {
        let t = u64::from(times[i]);
        if high != Some(t >> 6) {
            high = Some(t >> 6);
            out.extend((0x8u64 << 60 | (t >> 6) << 32).to_le_bytes());
        }
        let mut mask = 0u64;
        for _ in 0..rng.random_range(1..4) {
            mask |= 1 << rng.random_range(0..32);
        }
        i += mask.count_ones() as usize;
        let (base, y, p) = (
            rng.random_range(0..40u64) * 32,
            rng.random_range(0..720u64),
            rng.random_range(0..2u64),
        );
        out.extend((p << 60 | (t & 63) << 54 | base << 43 | y << 32 | mask).to_le_bytes());
    }
    out
}

/// Where the files go for the Python reference.
fn bench_files() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"),
        PathBuf::from,
    );
    target.join("bench-files")
}

/// Decodes everything, returning the event count and a checksum so nothing is optimised away.
fn drain_legacy(bytes: &[u8]) -> (u64, i64) {
    let mut reader = LegacyReader::from_slice(bytes).expect("header");
    let (mut n, mut sum) = (0u64, 0i64);
    while let Some(chunk) = reader.next_chunk().expect("decodes") {
        n += chunk.events.len() as u64;
        sum = sum.wrapping_add(chunk.events.last().map_or(0, |e| e.t) + chunk.imu.len() as i64);
    }
    (n, sum)
}

fn drain_evt(bytes: &[u8]) -> (u64, i64) {
    let mut reader = EvtReader::from_slice(bytes).expect("header");
    let (mut n, mut sum) = (0u64, 0i64);
    while let Some(chunk) = reader.next_chunk().expect("decodes") {
        n += chunk.events.len() as u64;
        sum = sum.wrapping_add(chunk.events.last().map_or(0, |e| e.t));
    }
    (n, sum)
}

/// A bench file: its name, file name, writer and drain.
type BenchFile = (
    &'static str,
    &'static str,
    fn(&mut ChaCha8Rng) -> Vec<u8>,
    fn(&[u8]) -> (u64, i64),
);

fn legacy_decode(c: &mut Criterion) {
    let dir = bench_files();
    std::fs::create_dir_all(&dir).expect("bench file folder");
    let mut group = c.benchmark_group("legacy_decode");
    let files: [BenchFile; 3] = [
        ("aedat2", "davis240.aedat2.aedat", aedat2, drain_legacy),
        ("aedat31", "davis240.aedat31.aedat", aedat31, drain_legacy),
        ("evt21", "gen4.evt21.raw", evt21, drain_evt),
    ];
    for (name, file, write, drain) in files {
        let bytes = write(&mut ChaCha8Rng::seed_from_u64(7));
        std::fs::write(dir.join(file), &bytes).expect("write bench file");
        let (events, _) = drain(&bytes);
        group.throughput(Throughput::Elements(events));
        group.bench_function(format!("{name}/memory"), |b| {
            b.iter(|| drain(black_box(&bytes)))
        });
    }
    group.finish();
}

criterion_group!(benches, legacy_decode);
criterion_main!(benches);
