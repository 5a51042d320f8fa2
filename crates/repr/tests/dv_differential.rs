//! Differential tests against dv-processing 2.0.4's `dv::Accumulator` (the paper's static
//! representation): random streams in several configurations, fed in random batches, must give
//! bit-identical float32 potential surfaces before and after every `generateFrame()`, and the
//! 8-bit frames must be identical. Skipped locally without the reference Python (see
//! `evtac_testkit::python`); required under CI.

use crate::common::{encode, random_batches, random_stream};
use evtac_events::{Event, Resolution};
use evtac_repr::{
    Comparison, Decay, FeatureExtractor, Polarity, ReprConfig, StaticAccumulator, StaticConfig,
    ThresholdSpace, static_frame,
};

/// Feeds each case's events to `dv.Accumulator` batch by batch; after each batch writes the
/// potential surface (float32), `generateFrame().image` (uint8) and the surface again.
const SCRIPT: &str = r#"
import json, sys
import numpy as np
import dv_processing as dv

for case in json.loads(sys.argv[1]):
    n, w, h = case["n"], case["w"], case["h"]
    raw = open(case["events"], "rb").read()
    t = np.frombuffer(raw, "<i8", n, 0)
    x = np.frombuffer(raw, "<u2", n, 8 * n)
    y = np.frombuffer(raw, "<u2", n, 10 * n)
    p = np.frombuffer(raw, "u1", n, 12 * n)
    decay = {
        "exponential": dv.Accumulator.Decay.EXPONENTIAL,
        "linear": dv.Accumulator.Decay.LINEAR,
        "none": dv.Accumulator.Decay.NONE,
    }[case["decay"]]
    acc = dv.Accumulator((w, h), decay, case["decay_param"], case["sync"], case["eta"],
                         case["max"], case["neutral"], case["min"], case["ignore"])
    with open(case["out"], "wb") as out:
        start = 0
        for end in case["cuts"]:
            store = dv.EventStore()
            for i in range(start, end):
                store.push_back(int(t[i]), int(x[i]), int(y[i]), bool(p[i]))
            acc.accept(store)
            out.write(np.ascontiguousarray(acc.getPotentialSurface(), dtype=np.float32).tobytes())
            frame = acc.generateFrame().image
            assert frame.dtype == np.uint8 and frame.size == w * h, (frame.dtype, frame.shape)
            out.write(np.ascontiguousarray(frame).tobytes())
            out.write(np.ascontiguousarray(acc.getPotentialSurface(), dtype=np.float32).tobytes())
            start = end
"#;

struct Case {
    name: &'static str,
    config: StaticConfig,
    events: Vec<Event>,
    cuts: Vec<usize>,
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

const RES: Resolution = Resolution::new(16, 8);

fn cases() -> Vec<Case> {
    let d = StaticConfig::default();
    let mut cases = Vec::new();
    let mut add = |name, seed: u64, config: StaticConfig, n, t0, max_gap, batches| {
        let events = random_stream(seed, RES, n, t0, max_gap);
        let cuts = random_batches(seed, events.len(), batches);
        cases.push(Case {
            name,
            config,
            events,
            cuts,
        });
    };
    add("paper defaults", 1, d, 4000, 0, 3000, 25);
    add(
        "ignored polarity, odd tau, camera-clock timestamps",
        2,
        StaticConfig {
            polarity: Polarity::Ignore,
            tau_ms: 37.3,
            ..d
        },
        4000,
        1_605_537_493_718_345,
        400,
        40,
    );
    add(
        "negative min, neutral != 0, small eta",
        3,
        StaticConfig {
            tau_ms: 5.5,
            eta: 0.07,
            min_potential: -1.5,
            max_potential: 0.8,
            neutral_potential: 0.25,
            ..d
        },
        4000,
        17,
        2000,
        1,
    );
    add(
        "synchronous decay",
        4,
        StaticConfig {
            synchronous_decay: true,
            tau_ms: 20.0,
            neutral_potential: -0.1,
            min_potential: -1.0,
            ..d
        },
        3000,
        5,
        500,
        60,
    );
    add(
        "linear decay",
        5,
        StaticConfig {
            decay: Decay::Linear,
            tau_ms: 10.0,
            min_potential: -1.0,
            ..d
        },
        3000,
        0,
        300,
        10,
    );
    add(
        "no decay, large max",
        6,
        StaticConfig {
            decay: Decay::None,
            eta: 0.2,
            max_potential: 3.7,
            ..d
        },
        3000,
        0,
        100,
        7,
    );
    add(
        "single-event batches, equal timestamps",
        7,
        StaticConfig { tau_ms: 0.75, ..d },
        600,
        0,
        2,
        600,
    );
    cases
}

#[test]
fn potentials_and_frames_match_dv_processing_bit_for_bit() {
    if evtac_testkit::python().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cases = cases();
    let mut specs = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        let events_path = dir.path().join(format!("events{i}.bin"));
        std::fs::write(&events_path, encode(&case.events)).unwrap();
        let p = case.config.accumulator_params();
        specs.push(serde_json::json!({
            "n": case.events.len(),
            "w": RES.width,
            "h": RES.height,
            "events": events_path,
            "out": dir.path().join(format!("out{i}.bin")),
            "cuts": case.cuts,
            "decay": match p.decay {
                Decay::Exponential => "exponential",
                Decay::Linear => "linear",
                Decay::None => "none",
            },
            "decay_param": f64::from(p.decay_param),
            "sync": p.synchronous_decay,
            "eta": f64::from(p.eta),
            "min": f64::from(p.min_potential),
            "max": f64::from(p.max_potential),
            "neutral": f64::from(p.neutral_potential),
            "ignore": p.ignore_polarity,
        }));
    }
    let arg = serde_json::to_string(&specs).unwrap();
    evtac_testkit::run_python(SCRIPT, &[&arg]).expect("python is available");

    let n = RES.pixels();
    for (i, case) in cases.iter().enumerate() {
        let out = std::fs::read(dir.path().join(format!("out{i}.bin"))).unwrap();
        let per_batch = 4 * n + n + 4 * n;
        assert_eq!(out.len(), per_batch * case.cuts.len(), "{}", case.name);
        let mut acc = StaticAccumulator::new(RES, &case.config).unwrap();
        let mut start = 0;
        for (b, (&end, dv)) in case
            .cuts
            .iter()
            .zip(out.chunks_exact(per_batch))
            .enumerate()
        {
            acc.accumulate(&case.events[start..end]).unwrap();
            start = end;
            assert_eq!(
                bits(acc.potentials()),
                bits(&f32s(&dv[..4 * n])),
                "{}: potentials after batch {b}",
                case.name
            );
            let frame = acc.generate_frame();
            assert_eq!(
                frame,
                &dv[4 * n..5 * n],
                "{}: frame after batch {b}",
                case.name
            );
            assert_eq!(
                bits(acc.potentials()),
                bits(&f32s(&dv[5 * n..])),
                "{}: potentials after generateFrame {b}",
                case.name
            );
        }
        if !case.config.synchronous_decay {
            check_extractor_against_dv(case, &f32s(&out[out.len() - 4 * n..]));
        }
    }
}

/// The streaming extractor's potentials equal dv's, and its static frames equal the
/// straightforward binarization of dv's surface, in both threshold spaces and comparisons.
fn check_extractor_against_dv(case: &Case, dv_potentials: &[f32]) {
    let mut configs = Vec::new();
    for threshold_space in [ThresholdSpace::Potential, ThresholdSpace::U8] {
        for comparison in [Comparison::Gt, Comparison::Ge] {
            for threshold in [0.0, 1.0, 2.0, 3.5] {
                configs.push(StaticConfig {
                    threshold_space,
                    comparison,
                    threshold,
                    ..case.config
                });
            }
        }
    }
    let reprs: Vec<ReprConfig> = configs.iter().copied().map(ReprConfig::Static).collect();
    let mut fx = FeatureExtractor::new(&reprs, RES, None).unwrap();
    fx.push(&case.events).unwrap();
    fx.advance_to(case.events.last().map_or(0, |e| e.t))
        .unwrap();
    for (i, config) in configs.iter().enumerate() {
        assert_eq!(
            bits(fx.potentials(i).unwrap()),
            bits(dv_potentials),
            "{}",
            case.name
        );
        assert_eq!(
            fx.frame(i),
            &static_frame(config, dv_potentials, None)[..],
            "{}: {config:?}",
            case.name
        );
    }
}
