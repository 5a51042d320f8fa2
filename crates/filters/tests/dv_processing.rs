//! Differential tests against dv-processing 2.0.4: each filter it has (and chains of two, as
//! `dv.EventFilterChain`) on seeded random streams and on the real DVXplorer recording, fed in
//! random batches on both sides (different cuts each side), must keep the same events in the
//! same order and count the same removed. Skipped locally without the reference Python (see
//! `evtac_testkit::python`); required under CI.

use std::path::{Path, PathBuf};

use evtac_events::{Event, Resolution};
use evtac_filters::{Filter, FilterSpec};

use crate::common::{CAMERA_T0, SENSOR, assert_same_events, random_cuts, run_in_batches, stream};

/// Runs each case of the JSON file `argv[1]` through dv-processing: the events (columns `t`
/// int64, `x` and `y` uint16, `p` uint8, as `encode` writes them) in the batches ending at
/// `cuts`, one `accept` and `generateEvents` per batch; writes the kept events in the same
/// layout to `out` and prints the filter's incoming and outgoing counts.
const SCRIPT: &str = r#"
import datetime, json, sys
import numpy as np
import dv_processing as dv

def make(f, res):
    kind = f["kind"]
    if kind == "background-activity":
        return dv.noise.BackgroundActivityNoiseFilter(
            res, backgroundActivityDuration=datetime.timedelta(microseconds=f["us"]))
    if kind == "fast-decay":
        return dv.noise.FastDecayNoiseFilter(
            res, halfLife=datetime.timedelta(microseconds=f["us"]),
            subdivisionFactor=f["subdivision"], noiseThreshold=f["threshold"])
    if kind == "k-noise":
        return dv.noise.KNoiseFilter(res, timeDelta=datetime.timedelta(microseconds=f["us"]))
    if kind == "polarity":
        return dv.EventPolarityFilter(f["on"])
    if kind == "region":
        return dv.EventRegionFilter((f["x"], f["y"], f["w"], f["h"]))
    if kind == "mask":
        return dv.EventMaskFilter(np.load(f["path"]))
    if kind == "hot-pixels":
        # No dv-processing class: its mask filter with the mask inverted.
        return dv.EventMaskFilter((np.load(f["path"]) == 0).astype(np.uint8))
    raise ValueError(kind)

stores = {}
def load(path, n):
    if path not in stores:
        raw = open(path, "rb").read()
        t = np.frombuffer(raw, "<i8", n, 0)
        x = np.frombuffer(raw, "<u2", n, 8 * n)
        y = np.frombuffer(raw, "<u2", n, 10 * n)
        p = np.frombuffer(raw, "u1", n, 12 * n)
        store = dv.EventStore()
        for i in range(n):
            store.push_back(int(t[i]), int(x[i]), int(y[i]), bool(p[i]))
        stores[path] = store
    return stores[path]

for case in json.load(open(sys.argv[1])):
    store = load(case["events"], case["n"])
    res = (case["w"], case["h"])
    filters = [make(f, res) for f in case["filters"]]
    # The bindings' EventFilterChain takes no EventMaskFilter: a chain with one runs its
    # filters one after the other on each batch, which is what a chain does.
    masked = any(f["kind"] in ("mask", "hot-pixels") for f in case["filters"])
    if len(filters) == 1 or masked:
        stages = filters
    else:
        chain = dv.EventFilterChain()
        for f in filters:
            chain.addFilter(f)
        stages = [chain]
    parts = []
    start = 0
    for end in case["cuts"]:
        out = store.slice(start, end - start)
        for f in stages:
            f.accept(out)
            out = f.generateEvents()
        if out.size() > 0:
            parts.append(out.numpy())
        start = end
    kept = np.concatenate(parts) if parts else np.zeros(0, dtype=store.numpy().dtype)
    with open(case["out"], "wb") as f:
        f.write(kept["timestamp"].astype("<i8").tobytes())
        f.write(kept["x"].astype("<u2").tobytes())
        f.write(kept["y"].astype("<u2").tobytes())
        f.write(kept["polarity"].astype("u1").tobytes())
    print(stages[0].getNumberOfIncomingEvents(), stages[-1].getNumberOfOutgoingEvents())
"#;

/// One stream through one filter or chain.
struct Case {
    name: String,
    specs: Vec<FilterSpec>,
    sensor: Resolution,
    /// Index into the streams written for the script.
    stream: usize,
    ours: Vec<usize>,
    theirs: Vec<usize>,
    /// Whether the filter must both keep and remove some events here (a test that keeps
    /// everything, or nothing, would compare little).
    mixed: bool,
}

fn encode(events: &[Event]) -> Vec<u8> {
    let mut out = Vec::with_capacity(events.len() * 13);
    out.extend(events.iter().flat_map(|e| e.t.to_le_bytes()));
    out.extend(events.iter().flat_map(|e| e.x.to_le_bytes()));
    out.extend(events.iter().flat_map(|e| e.y.to_le_bytes()));
    out.extend(events.iter().map(|e| u8::from(e.polarity)));
    out
}

fn decode(bytes: &[u8]) -> Vec<Event> {
    let n = bytes.len() / 13;
    assert_eq!(bytes.len(), 13 * n, "the script writes 13 bytes an event");
    let u16_at = |offset: usize, i: usize| {
        u16::from_le_bytes([bytes[offset + 2 * i], bytes[offset + 2 * i + 1]])
    };
    (0..n)
        .map(|i| Event {
            t: i64::from_le_bytes(bytes[8 * i..8 * i + 8].try_into().unwrap()),
            x: u16_at(8 * n, i),
            y: u16_at(10 * n, i),
            polarity: bytes[12 * n + i] != 0,
        })
        .collect()
}

/// The filter's settings as the script's `make` reads them.
fn dv_json(spec: &FilterSpec) -> String {
    match *spec {
        FilterSpec::BackgroundActivity { duration } => {
            format!(
                r#"{{"kind": "background-activity", "us": {}}}"#,
                duration.get()
            )
        }
        FilterSpec::FastDecay {
            half_life,
            subdivision,
            threshold,
        } => format!(
            r#"{{"kind": "fast-decay", "us": {}, "subdivision": {subdivision}, "threshold": {threshold}}}"#,
            half_life.get()
        ),
        FilterSpec::KNoise { duration } => {
            format!(r#"{{"kind": "k-noise", "us": {}}}"#, duration.get())
        }
        FilterSpec::Polarity { on } => format!(r#"{{"kind": "polarity", "on": {on}}}"#),
        FilterSpec::Region {
            x,
            y,
            width,
            height,
        } => format!(r#"{{"kind": "region", "x": {x}, "y": {y}, "w": {width}, "h": {height}}}"#),
        FilterSpec::Mask { ref path } | FilterSpec::HotPixels { ref path } => format!(
            r#"{{"kind": "{}", "path": {:?}}}"#,
            spec.name(),
            path.to_str().unwrap()
        ),
        FilterSpec::Refractory { .. } | FilterSpec::Circle { .. } | FilterSpec::HotPixelsAuto => {
            panic!("{spec} has no dv-processing class")
        }
    }
}

/// Runs `cases` over `streams` here and through dv-processing, and compares.
fn compare(streams: &[Vec<Event>], cases: &[Case], dir: &Path) {
    let paths: Vec<PathBuf> = streams
        .iter()
        .enumerate()
        .map(|(i, events)| {
            let path = dir.join(format!("events{i}.bin"));
            std::fs::write(&path, encode(events)).unwrap();
            path
        })
        .collect();
    let outs: Vec<PathBuf> = (0..cases.len())
        .map(|i| dir.join(format!("kept{i}.bin")))
        .collect();
    let json: Vec<String> = cases
        .iter()
        .zip(&outs)
        .map(|(case, out)| {
            let filters: Vec<String> = case.specs.iter().map(dv_json).collect();
            // Debug-quoted paths are JSON strings: the temporary folder's name is plain ASCII.
            format!(
                r#"{{"events": {:?}, "n": {}, "w": {}, "h": {}, "filters": [{}], "cuts": {:?}, "out": {:?}}}"#,
                paths[case.stream].to_str().unwrap(),
                streams[case.stream].len(),
                case.sensor.width,
                case.sensor.height,
                filters.join(", "),
                case.theirs,
                out.to_str().unwrap(),
            )
        })
        .collect();
    let plan = dir.join("cases.json");
    std::fs::write(&plan, format!("[{}]", json.join(",\n"))).unwrap();
    let Some(stdout) = evtac_testkit::run_python(SCRIPT, &[plan.to_str().unwrap()]) else {
        return;
    };
    let counts: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        counts.len(),
        cases.len(),
        "one line of counts a case: {stdout}"
    );

    for ((case, out), counts) in cases.iter().zip(&outs).zip(counts) {
        let events = &streams[case.stream];
        let theirs = decode(&std::fs::read(out).unwrap());
        let mut filter: Box<dyn Filter> = if case.specs.len() == 1 {
            case.specs[0].build(case.sensor).unwrap()
        } else {
            Box::new(evtac_filters::Chain::build(&case.specs, case.sensor).unwrap())
        };
        let ours = run_in_batches(&mut filter, events, &case.ours);
        assert_same_events(&case.name, &ours, &theirs);
        let (incoming, outgoing) = counts.split_once(' ').unwrap();
        assert_eq!(
            incoming.parse::<usize>().unwrap(),
            events.len(),
            "{}",
            case.name
        );
        let removed = events.len() as u64 - outgoing.parse::<u64>().unwrap();
        assert_eq!(filter.removed(), removed, "{}: removed", case.name);
        if case.mixed {
            assert!(
                !ours.is_empty() && ours.len() < events.len(),
                "{}: kept {} of {}: the case compares little",
                case.name,
                ours.len(),
                events.len()
            );
        }
    }
}

/// A seeded random uint8 mask for `sensor` (about one pixel in four zero, the others 1 to 255)
/// saved as NPY under `dir`; its path.
fn write_mask(dir: &Path, name: &str, sensor: Resolution, seed: u64) -> String {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (w, h) = (usize::from(sensor.width), usize::from(sensor.height));
    let mask = ndarray::Array2::from_shape_fn((h, w), |_| {
        if rng.random_bool(0.25) {
            0u8
        } else {
            rng.random_range(1..=255)
        }
    });
    let path = dir.join(name);
    ndarray_npy::write_npy(&path, &mask).unwrap();
    path.to_str().unwrap().to_string()
}

fn specs(s: &str) -> Vec<FilterSpec> {
    s.split(' ').map(|s| s.parse().unwrap()).collect()
}

#[test]
fn random_streams_filter_as_in_dv_processing() {
    if evtac_testkit::python().is_none() {
        return;
    }
    // Stream 0 starts at t = 0, where the filters' zero-initialised state shows (an event at
    // t < DURATION is supported by pixels or slots that never fired); stream 1 and 2 are on a
    // camera's clock; stream 3 on a sensor whose sides the cell sizes below do not divide.
    let odd = Resolution::new(37, 23);
    let dir = tempfile::tempdir().unwrap();
    let mask = write_mask(dir.path(), "mask.npy", SENSOR, 5);
    let odd_mask = write_mask(dir.path(), "odd_mask.npy", odd, 6);
    let streams = vec![
        stream(1, SENSOR, 6_000, 0),
        stream(2, SENSOR, 6_000, CAMERA_T0),
        stream(3, SENSOR, 3_000, 17),
        stream(4, odd, 4_000, CAMERA_T0),
    ];
    let mut cases = Vec::new();
    let mut add = |spec: &str, stream: usize, batches: usize, mixed: bool| {
        let n = streams[stream].len();
        let seed = cases.len() as u64;
        cases.push(Case {
            name: format!("{spec} on stream {stream}"),
            specs: specs(spec),
            sensor: if stream == 3 { odd } else { SENSOR },
            stream,
            ours: random_cuts(seed, n, batches),
            theirs: random_cuts(seed + 1000, n, batches + 7),
            mixed,
        });
    };
    for stream in [0, 1, 3] {
        add("background-activity=2ms", stream, 20, true);
        add("fast-decay", stream, 30, true);
        add("k-noise=1ms", stream, 25, true);
    }
    add("background-activity=500us", 2, 1, true);
    add("background-activity=1us", 1, 40, true);
    add("background-activity=50ms", 0, 10, true);
    add("fast-decay=3ms,3,2.5", 1, 15, true);
    add("fast-decay=20ms,7,3", 3, 15, true);
    add("fast-decay=1ms,1,1.5", 0, 50, true);
    add("fast-decay=100ms,64,40", 2, 5, true);
    add("k-noise=100us", 1, 12, true);
    add("k-noise=1us", 2, 3, true);
    add("k-noise=50ms", 0, 30, true);
    add("polarity=on", 1, 9, true);
    add("polarity=off", 3, 4, true);
    add("region=10,5,30,20", 1, 11, true);
    add("region=63,47,1,1", 0, 6, true);
    add("region=0,0,37,23", 3, 2, false);
    add("polarity=on background-activity=2ms", 1, 20, true);
    add("k-noise=1ms region=0,0,20,48", 0, 17, true);
    add("fast-decay background-activity=2ms", 3, 8, true);
    add(&format!("mask={mask}"), 1, 13, true);
    add(&format!("mask={odd_mask}"), 3, 5, true);
    add(&format!("hot-pixels={mask}"), 0, 9, true);
    add(&format!("polarity=off mask={mask}"), 2, 21, true);
    compare(&streams, &cases, dir.path());
}

#[test]
fn the_dvxplorer_recording_filters_as_in_dv_processing() {
    if evtac_testkit::python().is_none() {
        return;
    }
    let Some(path) = evtac_testkit::real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let recording = evtac_formats::read_recording(&path).unwrap();
    let sensor = recording.resolution.expect("the recording's resolution");
    let events = recording.events;
    let dir = tempfile::tempdir().unwrap();
    let hot = write_mask(dir.path(), "hot.npy", sensor, 7);
    let mut cases = Vec::new();
    let mut add = |spec: &str, batches: usize| {
        let seed = cases.len() as u64 + 77;
        cases.push(Case {
            name: format!("{spec} on the DVXplorer recording"),
            specs: specs(spec),
            sensor,
            stream: 0,
            ours: random_cuts(seed, events.len(), batches),
            theirs: random_cuts(seed + 1000, events.len(), batches + 13),
            mixed: true,
        });
    };
    add("background-activity=2ms", 40);
    add("fast-decay", 25);
    add("k-noise=1ms", 60);
    add("polarity=off", 10);
    add("region=40,0,240,240", 10);
    add("fast-decay=5ms,2,3 k-noise=2ms", 30);
    add(&format!("background-activity=10ms hot-pixels={hot}"), 20);
    compare(&[events], &cases, dir.path());
}

#[test]
fn fast_decay_rounds_as_dv_processing_does() {
    if evtac_testkit::python().is_none() {
        return;
    }
    // Three events in one cell, the threshold between the third count as computed with two
    // roundings (multiply, then add) and with one (a fused multiply-add): only the rounding
    // dv-processing does keeps the same events. Both use the platform's exp2f.
    let decay = |dt: i64| (-(dt as f32) / 10_000.0).exp2();
    let mut streams = Vec::new();
    let mut cases = Vec::new();
    for dt2 in 1..400 {
        let dt1 = 1;
        let second = decay(dt1) + 1.0;
        let (two, fused) = (second * decay(dt2) + 1.0, second.mul_add(decay(dt2), 1.0));
        if two == fused {
            continue;
        }
        let threshold = two.min(fused);
        let t = [CAMERA_T0, CAMERA_T0 + dt1, CAMERA_T0 + dt1 + dt2];
        streams.push(t.map(|t| Event {
            t,
            x: 1,
            y: 1,
            polarity: true,
        }));
        cases.push(Case {
            name: format!("fast-decay threshold {threshold} after gaps {dt1} and {dt2} us"),
            specs: vec![format!("fast-decay=10ms,4,{threshold}").parse().unwrap()],
            sensor: SENSOR,
            stream: cases.len(),
            ours: vec![1, 3],
            theirs: vec![3],
            mixed: false,
        });
        if cases.len() == 16 {
            break;
        }
    }
    assert_eq!(cases.len(), 16, "thresholds where the roundings differ");
    let streams: Vec<Vec<Event>> = streams.iter().map(|s| s.to_vec()).collect();
    let dir = tempfile::tempdir().unwrap();
    compare(&streams, &cases, dir.path());
}

#[test]
fn simulated_trials_filter_as_in_dv_processing() {
    if evtac_testkit::python().is_none() {
        return;
    }
    // Two trials of the simulator (640x480, its background noise and hot pixels, a contact
    // moving across the dome): the events the experiments' datasets are made of.
    let params = evtac_sim::SimParams::default();
    let sim = evtac_sim::Simulator::new(params.clone(), 3);
    let specs_of = evtac_sim::plan(
        evtac_sim::Protocol::Exp1,
        evtac_sim::Scale::Tiny,
        3,
        &params.timeline,
    );
    let sensor = Resolution::new(params.camera.width, params.camera.height);
    let streams: Vec<Vec<Event>> = specs_of[..2]
        .iter()
        .map(|s| sim.simulate(s).events)
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let mut cases = Vec::new();
    let mut add = |spec: &str, stream: usize, batches: usize| {
        let seed = cases.len() as u64 + 300;
        let n = streams[stream].len();
        cases.push(Case {
            name: format!("{spec} on simulated trial {stream}"),
            specs: specs(spec),
            sensor,
            stream,
            ours: random_cuts(seed, n, batches),
            theirs: random_cuts(seed + 1000, n, batches + 11),
            mixed: true,
        });
    };
    add("background-activity=10ms", 0, 30);
    add("fast-decay", 1, 20);
    add("k-noise=1ms", 0, 25);
    add("background-activity=10ms region=200,120,240,240", 1, 15);
    add("polarity=on k-noise=2ms", 1, 10);
    compare(&streams, &cases, dir.path());
}
