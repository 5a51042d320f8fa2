//! Decoding throughput (events/s) of the EVT 3.0 and EVT 2.0 readers on the real fixtures, from
//! memory and from the file. The Python reference (`evt_decode_reference.py`, the `expelliarmus`
//! decoder) times the same files; run both in one session and compare:
//!
//! ```sh
//! nice cargo bench -p evtac-events --bench evt_decode -- --warm-up-time 1 --measurement-time 3
//! .venv/bin/python crates/formats/benches/evt_decode_reference.py
//! ```

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use evtac_formats::evt::EvtReader;
use evtac_testkit::real_fixture;

const FILES: [(&str, &str); 2] = [
    ("evt3", "prophesee_gen4_1280x720.evt3.raw"),
    ("evt2", "prophesee_gen3_640x480.evt2.raw"),
];

/// Decodes everything from `reader`, returning the event count (and a checksum so nothing is
/// optimised away).
fn drain<R: std::io::Read>(mut reader: EvtReader<R>) -> (u64, i64) {
    let (mut n, mut sum) = (0u64, 0i64);
    while let Some(chunk) = reader.next_chunk().expect("fixture decodes") {
        n += chunk.events.len() as u64;
        sum = sum.wrapping_add(chunk.events.last().map_or(0, |e| e.t));
    }
    (n, sum)
}

fn evt_decode(c: &mut Criterion) {
    let mut group = c.benchmark_group("evt_decode");
    for (name, file) in FILES {
        let Some(path) = real_fixture(file) else {
            continue;
        };
        let bytes = std::fs::read(&path).expect("read fixture");
        let (events, _) = drain(EvtReader::from_slice(&bytes).expect("header"));
        group.throughput(Throughput::Elements(events));
        group.bench_function(format!("{name}/memory"), |b| {
            b.iter(|| drain(EvtReader::from_slice(black_box(&bytes)).expect("header")))
        });
        group.bench_function(format!("{name}/file"), |b| {
            b.iter(|| drain(EvtReader::from_path(black_box(&path)).expect("open")))
        });
    }
    group.finish();
}

criterion_group!(benches, evt_decode);
criterion_main!(benches);
