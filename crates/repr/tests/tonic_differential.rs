//! Time surfaces, histograms and voxel grids against tonic 1.7's functional transforms
//! (`to_timesurface_numpy`, `to_frame_numpy` with `time_window`, `to_voxel_grid_numpy`) on
//! seeded random streams, the real DVXplorer recording and a simulated trial, sampled at random
//! times. Frames are tonic's float64 values in float32: histograms, binarized surfaces and voxel
//! grids identical, continuous surfaces within one float32 ulp (numpy's `exp` and the C
//! library's may differ in the last float64 bit); pooled features within 1e-6 of the 8x8 means
//! of tonic's frames. Skipped locally without tonic (see `evtac_testkit::python_with`); required
//! under CI.

use evtac_events::{Event, Resolution, Roi};
use evtac_repr::{
    DenseConfig, DenseExtractor, HistogramConfig, TimeSurfaceConfig, VoxelGridConfig,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::common::{encode, pool_channels, random_stream};

/// For each case: tonic's frame at each sample time, as float32, one after another. How each
/// sample's slice is asked of tonic is the recipe in `crates/repr/README.md`.
const SCRIPT: &str = r#"
import json, sys
import numpy as np
import tonic.functional as F

for case in json.loads(sys.argv[1]):
    n, w, h = case["n"], case["w"], case["h"]
    raw = open(case["events"], "rb").read()
    ev = np.zeros(n, dtype=[("x", "<i2"), ("y", "<i2"), ("t", "<i8"), ("p", "<i1")])
    ev["t"] = np.frombuffer(raw, "<i8", n, 0)
    ev["x"] = np.frombuffer(raw, "<u2", n, 8 * n)
    ev["y"] = np.frombuffer(raw, "<u2", n, 10 * n)
    ev["p"] = np.frombuffer(raw, "u1", n, 12 * n)
    size = (w, h, 2)
    kind = case["kind"]
    with open(case["out"], "wb") as out:
        for t_k in case["samples"]:
            if kind == "histogram":
                win = case["window_us"]
                frame = F.to_frame_numpy(ev, size, time_window=win, start_time=t_k - win,
                                         end_time=t_k)[0]
            elif kind == "time-surface":
                sel = ev[ev["t"] < t_k]
                if len(sel) == 0:
                    frame = np.zeros((2, h, w))
                else:
                    frame = F.to_timesurface_numpy(sel, size, dt=int(t_k - sel["t"][0]),
                                                   tau=case["tau_us"])[0]
                if case["threshold"] is not None:
                    frame = (frame > case["threshold"]).astype(np.float64)
            else:
                win, bins = case["window_us"], case["bins"]
                sel = ev[(ev["t"] >= t_k - win) & (ev["t"] < t_k)]
                # The window's edges as tonic's first and last events: two opposite events at
                # t_k - W cancel, one at t_k weighs nothing (ts = bins).
                edge = np.zeros(3, dtype=ev.dtype)
                edge["t"] = [t_k - win, t_k - win, t_k]
                edge["p"] = [1, 0, 1]
                arr = np.concatenate([edge[:2], sel, edge[2:]])
                frame = F.to_voxel_grid_numpy(arr, size, n_time_bins=bins)[:, 0]
            out.write(np.ascontiguousarray(frame, dtype=np.float32).tobytes())
"#;

fn configs() -> Vec<DenseConfig> {
    vec![
        DenseConfig::Histogram(HistogramConfig { window_ms: 10.0 }),
        DenseConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 20.0,
            threshold: None,
        }),
        DenseConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 50.0,
            threshold: Some(0.25),
        }),
        DenseConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 30.0,
            bins: 5,
        }),
        DenseConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 7.0,
            bins: 3,
        }),
    ]
}

fn case_json(
    config: &DenseConfig,
    n: usize,
    res: Resolution,
    samples: &[i64],
) -> serde_json::Value {
    let mut case = serde_json::json!({
        "n": n, "w": res.width, "h": res.height, "samples": samples,
    });
    let us = |ms: f64| (ms * 1000.0).round() as i64;
    match *config {
        DenseConfig::Histogram(c) => {
            case["kind"] = "histogram".into();
            case["window_us"] = us(c.window_ms).into();
        }
        DenseConfig::TimeSurface(c) => {
            case["kind"] = "time-surface".into();
            case["tau_us"] = c.tau_us().into();
            case["threshold"] = c.threshold.into();
        }
        DenseConfig::VoxelGrid(c) => {
            case["kind"] = "voxel-grid".into();
            case["window_us"] = us(c.window_ms).into();
            case["bins"] = c.bins.into();
        }
    }
    case
}

/// Sample times: `count` random times over the stream's span, sorted, a few repeated and some
/// exactly at event times (an event at the sample time waits for the next).
fn samples(events: &[Event], count: usize, seed: u64) -> Vec<i64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (first, last) = (events[0].t, events[events.len() - 1].t);
    let mut out: Vec<i64> = (0..count)
        .map(|i| match i % 4 {
            0 => events[rng.random_range(0..events.len())].t,
            _ => rng.random_range(first..=last + 1),
        })
        .collect();
    out.sort_unstable();
    out
}

fn ulps(a: f32, b: f32) -> u32 {
    if a == b {
        return 0;
    }
    (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs() as u32
}

/// Compares every config with tonic on `events` (crop coordinates of a `res` frame).
fn compare(name: &str, events: &[Event], res: Resolution, samples: &[i64]) {
    let Some(python) = evtac_testkit::python_with("tonic") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let events_path = dir.path().join("events.bin");
    std::fs::write(&events_path, encode(events)).unwrap();
    let mut cases = Vec::new();
    for (i, config) in configs().iter().enumerate() {
        let mut case = case_json(config, events.len(), res, samples);
        case["events"] = events_path.display().to_string().into();
        case["out"] = dir
            .path()
            .join(format!("{i}.f32"))
            .display()
            .to_string()
            .into();
        cases.push(case);
    }
    let out = std::process::Command::new(&python)
        .args(["-c", SCRIPT, &serde_json::to_string(&cases).unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "tonic script failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (i, config) in configs().into_iter().enumerate() {
        let bytes = std::fs::read(dir.path().join(format!("{i}.f32"))).unwrap();
        let tonic: Vec<f32> = bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        let mut fx = DenseExtractor::new(config, res).unwrap();
        fx.push(events).unwrap();
        let per = fx.channels() * res.pixels();
        assert_eq!(tonic.len(), per * samples.len(), "{name} {config:?}");
        let allowed = match config {
            DenseConfig::TimeSurface(TimeSurfaceConfig {
                threshold: None, ..
            }) => 1,
            _ => 0,
        };
        let mut frame = vec![0f32; per];
        let (mut nonzero, mut off_by_one) = (0usize, 0usize);
        for (s, &t_k) in samples.iter().enumerate() {
            fx.advance_to(t_k).unwrap();
            fx.frame_into(&mut frame).unwrap();
            let want = &tonic[s * per..(s + 1) * per];
            for (k, (&a, &b)) in frame.iter().zip(want).enumerate() {
                let d = ulps(a, b);
                assert!(
                    d <= allowed,
                    "{name} {config:?} sample {s} (t_k {t_k}) value {k}: evtac {a} tonic {b}"
                );
                off_by_one += usize::from(d == 1);
                nonzero += usize::from(b != 0.0);
            }
            let want64: Vec<f64> = want.iter().map(|&v| f64::from(v)).collect();
            let pooled = pool_channels(&want64, res);
            for (k, (&a, &b)) in fx.features().iter().zip(&pooled).enumerate() {
                assert!(
                    (f64::from(a) - b).abs() <= 1e-6,
                    "{name} {config:?} sample {s} feature {k}: evtac {a} tonic's mean {b}"
                );
            }
        }
        // A comparison of empty frames would prove nothing.
        assert!(
            nonzero > samples.len(),
            "{name} {config:?}: tonic's frames are empty"
        );
        eprintln!("{name} {config:?}: {nonzero} non-zero values, {off_by_one} a float32 ulp apart");
    }
}

#[test]
fn random_streams_equal_tonic() {
    let res = Resolution::new(16, 8);
    for seed in 0..3 {
        // Dense enough that windows of milliseconds hold many events per pixel.
        let events = random_stream(
            seed,
            res,
            4_000,
            1_700_000_000_000_000 * (seed as i64 % 2),
            40,
        );
        compare(
            &format!("seed {seed}"),
            &events,
            res,
            &samples(&events, 60, seed),
        );
    }
}

#[test]
fn the_dvxplorer_recording_equals_tonic() {
    let Some(path) = evtac_testkit::real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let recording = evtac_formats::read_recording(&path).unwrap();
    let sensor = recording.resolution.expect("the recording states its size");
    let roi = Roi::centered(sensor, evtac_repr::CROP).unwrap();
    let mut events = Vec::new();
    roi.crop_into(&recording.events, &mut events);
    compare(
        "DVXplorer",
        &events,
        evtac_repr::CROP,
        &samples(&events, 12, 7),
    );
}

#[test]
fn a_simulated_trial_equals_tonic() {
    let sim = evtac_sim::Simulator::new(evtac_sim::SimParams::default(), 1);
    let spec = evtac_sim::plan(
        evtac_sim::Protocol::Exp1,
        evtac_sim::Scale::Tiny,
        1,
        &Default::default(),
    )
    .remove(0);
    let trial = sim.simulate(&spec);
    let camera = &sim.params().camera;
    let sensor = Resolution::new(camera.width, camera.height);
    let roi = Roi::centered(sensor, evtac_repr::CROP).unwrap();
    let mut events = Vec::new();
    roi.crop_into(&trial.events, &mut events);
    // A stretch of the motion, where the pins move.
    let from = trial.motion_start_us;
    events.retain(|e| e.t >= from && e.t < from + 400_000);
    compare(
        "simulated",
        &events,
        evtac_repr::CROP,
        &samples(&events, 10, 3),
    );
}
