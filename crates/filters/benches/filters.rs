//! Event filters' throughput from memory (events/s), one SPEC at a time, against dv-processing
//! 2.0.4's filters (`benches/filters_reference.py`) on the same events.
//!
//! Issue 53 asks each filter to run at least twice as fast as dv-processing's. So that the two
//! sides see the same stream, setup writes it to `$EVTAC_FILTER_BENCH_DIR` (default:
//! `<tmp>/evtac-filter-bench`):
//! - `events.aedat4`: the real DVXplorer fixture (`dvxplorer_320x240_imu.aedat4`, 112 k events
//!   over 0.59 s) repeated 18 times, each copy shifted to start 1 us after the previous one
//!   ends, so time stays ordered: about 2 million events, LZ4-compressed. The reference reads it
//!   with dv-processing's reader; `evtac filter` reads it for the whole-process comparison. When
//!   the fixture is absent a seeded synthetic stream of the same density stands in (printed).
//! - `mask.npy`: the `mask=` filter's uint8 240x320 mask, a fixed pattern with 75% of the
//!   pixels non-zero, so the mask keeps about that share of a uniform stream.
//!
//! Each benchmark `filters/<name>` builds a fresh filter from its SPEC (outside the timing, via
//! `iter_batched`: a filter's state would otherwise carry over from one iteration to the next
//! and see time go backwards) and times `Filter::retain` over the stream in chunks of 65536
//! events, as `evtac filter` and dv-processing's `accept` + `generateEvents` both take it. The
//! output buffer is cleared per chunk, as a writer would drain it.

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use evtac_events::{Event, Resolution};
use evtac_filters::{Filter, FilterSpec};
use evtac_formats::aedat::{AedatWriter, Compression, WriterConfig};

/// Events per `retain` call: dv-processing's Python loop is timed on slices of the same size.
const CHUNK: usize = 65_536;
/// Copies of the fixture: 18 x 111 954 = 2 015 172 events.
const COPIES: usize = 18;
const FIXTURE: &str = "dvxplorer_320x240_imu.aedat4";

fn bench_dir() -> PathBuf {
    std::env::var_os("EVTAC_FILTER_BENCH_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("evtac-filter-bench"))
}

/// The fixture repeated `COPIES` times; each copy is shifted by the fixture's span plus 1 us, so
/// a copy's first event comes strictly after the previous copy's last.
fn repeated_fixture(path: &Path) -> (Vec<Event>, Resolution) {
    let rec = evtac_formats::read_recording(path).expect("read the fixture");
    let sensor = rec.resolution.expect("the fixture states its sensor");
    let one = rec.events;
    let span = one.last().expect("events").t - one[0].t + 1;
    let events = (0..COPIES as i64)
        .flat_map(|k| {
            one.iter().map(move |e| Event {
                t: e.t + k * span,
                ..*e
            })
        })
        .collect();
    (events, sensor)
}

/// Seeded synthetic events (xorshift64) at the fixture's density: about 190 k events/s over
/// 320x240, so about 5 us apart, uniform over the sensor.
fn synthetic() -> (Vec<Event>, Resolution) {
    let sensor = Resolution::new(320, 240);
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let mut t = 1_605_537_493_718_345i64;
    let events = (0..COPIES * 111_954)
        .map(|_| {
            let r = next();
            t += (r & 7) as i64 + 1;
            Event {
                t,
                x: ((r >> 8) % u64::from(sensor.width)) as u16,
                y: ((r >> 24) % u64::from(sensor.height)) as u16,
                polarity: r >> 63 == 1,
            }
        })
        .collect();
    (events, sensor)
}

/// 0 where `(7x + 13y) mod 4 == 0`, 255 elsewhere: three pixels in four kept, spread over the
/// whole sensor so no region of the stream is favoured.
fn write_mask(path: &Path, sensor: Resolution) {
    let (h, w) = (usize::from(sensor.height), usize::from(sensor.width));
    let mask =
        ndarray::Array2::from_shape_fn(
            (h, w),
            |(y, x)| if (7 * x + 13 * y) % 4 == 0 { 0u8 } else { 255 },
        );
    ndarray_npy::write_npy(path, &mask).expect("write the mask");
}

fn filters(c: &mut Criterion) {
    let (events, sensor) = match evtac_testkit::real_fixture(FIXTURE) {
        Some(path) => {
            let (events, sensor) = repeated_fixture(&path);
            eprintln!("events: {FIXTURE} x {COPIES} = {} events", events.len());
            (events, sensor)
        }
        None => {
            let (events, sensor) = synthetic();
            eprintln!(
                "events: SYNTHETIC (fixture absent), {} events",
                events.len()
            );
            (events, sensor)
        }
    };
    let dir = bench_dir();
    std::fs::create_dir_all(&dir).expect("bench dir");
    let stream = dir.join("events.aedat4");
    let config = WriterConfig {
        resolution: sensor,
        source_name: "DVXplorer_BENCH".into(),
        compression: Compression::Lz4,
    };
    let mut w = AedatWriter::create(&stream, config).expect("create");
    w.write_events(&events).expect("write");
    w.finish().expect("finish");
    let mask = dir.join("mask.npy");
    write_mask(&mask, sensor);
    eprintln!("wrote {} and {}", stream.display(), mask.display());

    let specs = [
        (
            "background-activity",
            "background-activity=10ms".to_string(),
        ),
        ("fast-decay", "fast-decay".to_string()),
        ("k-noise", "k-noise=1ms".to_string()),
        ("polarity", "polarity=on".to_string()),
        ("region", "region=40,0,240,240".to_string()),
        ("mask", format!("mask={}", mask.display())),
        ("refractory", "refractory=1ms".to_string()),
        ("circle", "circle=160,120,110".to_string()),
    ];
    let mut g = c.benchmark_group("filters");
    g.throughput(Throughput::Elements(events.len() as u64));
    for (name, spec) in &specs {
        let spec: FilterSpec = spec.parse().expect("SPEC");
        // One untimed pass: a SPEC that does not fit fails before any timing, and the kept
        // count printed can be checked against the reference's (the filters match exactly).
        let mut once = spec.build(sensor).expect("build");
        let mut out = Vec::new();
        once.retain(&events, &mut out);
        eprintln!("{name}: kept {} of {}", out.len(), events.len());
        g.bench_function(*name, |b| {
            b.iter_batched(
                || {
                    let filter = spec.build(sensor).expect("build");
                    (filter, Vec::with_capacity(CHUNK))
                },
                |(mut filter, mut out): (Box<dyn Filter>, Vec<Event>)| {
                    let mut kept = 0usize;
                    for chunk in black_box(&events).chunks(CHUNK) {
                        out.clear();
                        filter.retain(chunk, &mut out);
                        kept += out.len();
                    }
                    black_box(kept)
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    // Short runs: 8 filters at 10-120 ms an iteration; with writing the stream the whole bench
    // takes about a minute on a loaded 2-core machine.
    config = Criterion::default()
        .warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(3))
        .sample_size(30);
    targets = filters
}
criterion_main!(benches);
