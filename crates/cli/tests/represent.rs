//! Tests of `evtac represent`: NPY shapes and dtypes, equality with the library on the same
//! stream, the default centered ROI, both kinds of `--mask`, and clear errors.

use crate::common::{evtac, run_ok};
use evtac_events::{Event, Resolution};
use evtac_repr::{DynamicConfig, Mask, ReprConfig, StaticConfig, extract_features};
use ndarray::{Array2, Array3};
use std::fmt::Write as _;
use std::path::Path;

/// A deterministic stream on a `w x h` sensor: bursts on a few pixels plus a sweep.
fn stream(w: u16, h: u16) -> Vec<Event> {
    let mut events = Vec::new();
    for i in 0..3000i64 {
        let k = i as u16;
        events.push(Event {
            t: 100 + i * 7,
            x: (k * 13 + (k / 50)) % w,
            y: (k * 7 + k / 3) % h,
            polarity: i % 3 != 0,
        });
    }
    events
}

fn write_csv(path: &Path, events: &[Event]) {
    let mut text = String::from("t,x,y,p\n");
    for e in events {
        writeln!(text, "{},{},{},{}", e.t, e.x, e.y, u8::from(e.polarity)).unwrap();
    }
    std::fs::write(path, text).unwrap();
}

fn write_samples(path: &Path, samples: &[i64]) -> Vec<i64> {
    let text: String = samples.iter().map(|t| format!("{t}\n")).collect();
    std::fs::write(path, format!("# sample times (us)\n{text}\n")).unwrap();
    samples.to_vec()
}

#[test]
fn features_equal_the_library_and_frames_have_the_crop_shape() {
    let dir = tempfile::tempdir().unwrap();
    let (events_path, samples_path) = (dir.path().join("e.csv"), dir.path().join("s.txt"));
    let events = stream(32, 24);
    write_csv(&events_path, &events);
    let samples = write_samples(&samples_path, &[50, 5_000, 9_000, 9_000, 21_000]);
    let out = dir.path().join("f.npy");
    let static_part = StaticConfig {
        tau_ms: 3.0,
        threshold: 1.0,
        ..StaticConfig::default()
    };
    let dynamic_part = DynamicConfig {
        window_ms: 2.5,
        count_threshold: 0,
    };
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let common = [
        s(&events_path),
        "--samples".into(),
        s(&samples_path),
        "--sensor".into(),
        "32x24".into(),
        "--roi".into(),
        "none".into(),
        "--tau-ms".into(),
        "3".into(),
        "--threshold".into(),
        "1".into(),
        "--window-ms".into(),
        "2.5".into(),
    ];
    let mut args: Vec<String> = vec!["represent".into()];
    args.extend(common.iter().cloned());
    args.extend(["--repr", "combined", "--what", "features", "--output"].map(String::from));
    args.push(s(&out));
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let got: Array2<f32> = ndarray_npy::read_npy(&out).unwrap();
    assert_eq!(got.dim(), (5, 12));
    let config = ReprConfig::Combined {
        static_part,
        dynamic_part,
    };
    let expected =
        extract_features(&[config], Resolution::new(32, 24), None, &events, &samples).unwrap();
    assert_eq!(got.iter().copied().collect::<Vec<_>>(), expected[0]);
    assert!(
        expected[0].iter().any(|&f| f > 0.0),
        "the test stream sets pixels"
    );

    let frames = dir.path().join("frames.npy");
    let mut args: Vec<String> = vec!["represent".into()];
    args.extend(common.iter().cloned());
    args.extend(["--repr", "static", "--what", "frames", "-o"].map(String::from));
    args.push(s(&frames));
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let frames: Array3<u8> = ndarray_npy::read_npy(&frames).unwrap();
    assert_eq!(frames.dim(), (5, 24, 32));
    assert!(frames.iter().all(|&b| b <= 1));

    let potential = dir.path().join("v.npy");
    let mut args: Vec<String> = vec!["represent".into()];
    args.extend(common.iter().cloned());
    args.extend(["--repr", "static", "--what", "potential", "-o"].map(String::from));
    args.push(s(&potential));
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let v: Array3<f32> = ndarray_npy::read_npy(&potential).unwrap();
    assert_eq!(v.dim(), (5, 24, 32));
    assert!(v.iter().all(|&x| (0.0..=1.0).contains(&x)));
}

#[test]
fn default_roi_is_the_centered_240_crop_and_masks_apply() {
    let dir = tempfile::tempdir().unwrap();
    let (events_path, samples_path) = (dir.path().join("e.csv"), dir.path().join("s.txt"));
    // Events in the crop (200..440, 120..360 on 640x480) and outside it.
    let events: Vec<Event> = (0..40)
        .map(|i| Event {
            t: 10 + i,
            x: if i % 2 == 0 { 200 } else { 10 },
            y: 120,
            polarity: true,
        })
        .collect();
    write_csv(&events_path, &events);
    write_samples(&samples_path, &[100]);
    let out = dir.path().join("frames.npy");
    let base = |out: &Path| {
        vec![
            "represent".to_string(),
            events_path.to_str().unwrap().into(),
            "--samples".into(),
            samples_path.to_str().unwrap().into(),
            "--sensor".into(),
            "640x480".into(),
            "--repr".into(),
            "static".into(),
            "--what".into(),
            "frames".into(),
            "--output".into(),
            out.to_str().unwrap().into(),
        ]
    };
    let args = base(&out);
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let frames: Array3<u8> = ndarray_npy::read_npy(&out).unwrap();
    assert_eq!(frames.dim(), (1, 240, 240));
    assert_eq!(frames[[0, 0, 0]], 1);
    assert_eq!(frames.iter().map(|&b| u32::from(b)).sum::<u32>(), 1);

    // An NPY mask over that pixel clears it.
    let mut mask = Array2::<u8>::zeros((240, 240));
    mask[[0, 0]] = 1;
    let mask_path = dir.path().join("mask.npy");
    ndarray_npy::write_npy(&mask_path, &mask).unwrap();
    let masked = dir.path().join("masked.npy");
    let mut args = base(&masked);
    args.extend(["--mask".into(), mask_path.to_str().unwrap().into()]);
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let frames: Array3<u8> = ndarray_npy::read_npy(&masked).unwrap();
    assert!(frames.iter().all(|&b| b == 0));

    // So does a no-contact recording with activity there.
    let no_contact = dir.path().join("no_contact.csv");
    write_csv(&no_contact, &events[..2]);
    let expected = Mask::from_no_contact(
        Resolution::new(240, 240),
        &StaticConfig::default(),
        &[Event {
            x: 0,
            y: 0,
            ..events[0]
        }],
    )
    .unwrap();
    assert!(expected.is_masked(0));
    let mut args = base(&masked);
    args.extend(["--mask".into(), no_contact.to_str().unwrap().into()]);
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let frames: Array3<u8> = ndarray_npy::read_npy(&masked).unwrap();
    assert!(frames.iter().all(|&b| b == 0));
}

#[test]
fn bad_inputs_fail_with_clear_messages() {
    let dir = tempfile::tempdir().unwrap();
    let (events_path, samples_path) = (dir.path().join("e.csv"), dir.path().join("s.txt"));
    write_csv(&events_path, &stream(32, 24));
    std::fs::write(&samples_path, "100\n50\n").unwrap();
    let out = dir.path().join("o.npy");
    let run = |extra: &[&str]| {
        let mut cmd = evtac();
        cmd.arg("represent")
            .arg(&events_path)
            .arg("--samples")
            .arg(&samples_path)
            .arg("--output")
            .arg(&out)
            .args(extra);
        let o = cmd.output().unwrap();
        assert!(!o.status.success(), "{extra:?} should fail");
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let err = run(&["--sensor", "32x24", "--roi", "none"]);
    assert!(err.contains("line 2") && err.contains("before"), "{err}");

    std::fs::write(&samples_path, "100\n").unwrap();
    let err = run(&["--sensor", "32x24"]);
    assert!(err.contains("does not fit"), "{err}");
    let err = run(&["--roi", "none"]);
    assert!(err.contains("--sensor"), "{err}");
    let err = run(&[
        "--sensor",
        "32x24",
        "--roi",
        "none",
        "--repr",
        "dynamic",
        "--what",
        "potential",
    ]);
    assert!(err.contains("potential"), "{err}");
    let err = run(&["--sensor", "32x24", "--roi", "none", "--tau-ms", "0"]);
    assert!(err.contains("tau_ms"), "{err}");
    let err = run(&["--sensor", "30x24", "--roi", "none"]);
    assert!(err.contains("multiples of 8"), "{err}");
}

#[test]
fn filters_apply_before_the_representation_and_are_recorded_beside_the_features() {
    let dir = tempfile::tempdir().unwrap();
    let (raw, samples) = (dir.path().join("raw.csv"), dir.path().join("s.txt"));
    let events = stream(32, 24);
    write_csv(&raw, &events);
    write_samples(&samples, &[5_000, 12_000, 21_000]);
    // The reference: the same events filtered here by hand (ON events in the left half).
    let kept: Vec<Event> = events
        .iter()
        .copied()
        .filter(|e| e.polarity && e.x < 16)
        .collect();
    assert!(!kept.is_empty() && kept.len() < events.len());
    let prefiltered = dir.path().join("kept.csv");
    write_csv(&prefiltered, &kept);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let represent = |input: &Path, out: &Path, extra: &[&str]| {
        let mut args: Vec<String> = ["represent", &s(input), "--samples", &s(&samples)]
            .map(String::from)
            .to_vec();
        args.extend(["--sensor", "32x24", "--roi", "none", "--repr", "combined"].map(String::from));
        args.extend(["--tau-ms", "3", "--window-ms", "4", "--output"].map(String::from));
        args.push(s(out));
        args.extend(extra.iter().map(|a| a.to_string()));
        crate::common::run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let (filtered, reference) = (dir.path().join("f.npy"), dir.path().join("r.npy"));
    let ran = represent(
        &raw,
        &filtered,
        &["--filter", "polarity=on", "--filter", "region=0,0,16,24"],
    );
    let said = String::from_utf8_lossy(&ran.stderr);
    let off = events.iter().filter(|e| !e.polarity).count();
    assert!(said.contains(&format!("removed {off} events")), "{said}");
    represent(&prefiltered, &reference, &[]);
    let got: Array2<f32> = ndarray_npy::read_npy(&filtered).unwrap();
    let want: Array2<f32> = ndarray_npy::read_npy(&reference).unwrap();
    assert_eq!(
        got, want,
        "filtering in represent = representing the filtered events"
    );
    let made: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("f.npy.json")).unwrap())
            .unwrap();
    assert_eq!(
        made["filters"],
        serde_json::json!(["polarity=on", "region=0,0,16,24"])
    );
    let unfiltered = std::fs::read_to_string(dir.path().join("r.npy.json")).unwrap();
    assert!(!unfiltered.contains("filters"), "{unfiltered}");

    let bad = dir.path().join("bad.npy");
    let err = crate::common::run_err(&[
        "represent",
        &s(&raw),
        "--samples",
        &s(&samples),
        "--sensor",
        "32x24",
        "--roi",
        "none",
        "--filter",
        "region=20,0,16,24",
        "--output",
        &s(&bad),
    ]);
    assert!(err.contains("region=20,0,16,24"), "{err}");
    assert!(!bad.exists(), "nothing written");
}

/// `represent` of a kind the paper did not choose on the same stream as the library, with the
/// settings its flags name.
fn dense_case(dir: &Path, flags: &[&str], what: &str, config: ReprConfig) {
    let (events_path, samples_path) = (dir.join("e.csv"), dir.join("s.txt"));
    let events = stream(32, 24);
    write_csv(&events_path, &events);
    let samples = write_samples(&samples_path, &[50, 5_000, 9_000, 9_000, 21_000]);
    let out = dir.join(format!("{what}.npy"));
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let mut args: Vec<String> = [
        "represent",
        &s(&events_path),
        "--samples",
        &s(&samples_path),
    ]
    .map(String::from)
    .to_vec();
    args.extend(["--sensor", "32x24", "--roi", "none", "--what", what, "-o"].map(String::from));
    args.push(s(&out));
    args.extend(flags.iter().map(|f| f.to_string()));
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let frame = Resolution::new(32, 24);
    let mut fx = evtac_repr::FeatureExtractor::new(&[config], frame, None).unwrap();
    let (mut want, mut values) = (Vec::new(), Vec::new());
    fx.run(&events, &samples, |_, fx| {
        if what == "frames" {
            fx.frame_values_into(0, &mut values);
            want.extend_from_slice(&values);
        } else {
            want.extend_from_slice(fx.features(0));
        }
    })
    .unwrap();
    let channels = config.frames();
    if what == "frames" {
        let got: ndarray::Array4<f32> = ndarray_npy::read_npy(&out).unwrap();
        assert_eq!(got.dim(), (5, channels, 24, 32), "{flags:?}");
        assert_eq!(got.iter().copied().collect::<Vec<_>>(), want, "{flags:?}");
    } else {
        let got: Array2<f32> = ndarray_npy::read_npy(&out).unwrap();
        assert_eq!(got.dim(), (5, channels * 12), "{flags:?}");
        assert_eq!(got.iter().copied().collect::<Vec<_>>(), want, "{flags:?}");
        let made = std::fs::read_to_string(dir.join(format!("{what}.npy.json"))).unwrap();
        assert!(made.contains(config.kind_name()), "{made}");
    }
    assert!(
        want.iter().any(|&v| v != 0.0),
        "{flags:?}: the case sees events"
    );
}

#[test]
fn time_surfaces_histograms_and_voxel_grids_are_the_librarys_with_their_flags() {
    use evtac_repr::{HistogramConfig, TimeSurfaceConfig, VoxelGridConfig};
    let dir = tempfile::tempdir().unwrap();
    let surface = ReprConfig::TimeSurface(TimeSurfaceConfig {
        tau_ms: 2.0,
        threshold: None,
    });
    let binarized = ReprConfig::TimeSurface(TimeSurfaceConfig {
        tau_ms: 2.0,
        threshold: Some(0.25),
    });
    let histogram = ReprConfig::Histogram(HistogramConfig { window_ms: 3.0 });
    let voxel = ReprConfig::VoxelGrid(VoxelGridConfig {
        window_ms: 3.0,
        bins: 3,
    });
    let cases: [(&[&str], ReprConfig); 4] = [
        (&["--repr", "time-surface", "--tau-ms", "2"], surface),
        (
            &[
                "--repr",
                "time-surface",
                "--tau-ms",
                "2",
                "--threshold",
                "0.25",
            ],
            binarized,
        ),
        (&["--repr", "histogram", "--window-ms", "3"], histogram),
        (
            &["--repr", "voxel-grid", "--window-ms", "3", "--bins", "3"],
            voxel,
        ),
    ];
    for (flags, config) in cases {
        for what in ["frames", "features"] {
            dense_case(dir.path(), flags, what, config);
        }
    }
}

#[test]
fn settings_a_kind_does_not_take_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (events_path, samples_path) = (dir.path().join("e.csv"), dir.path().join("s.txt"));
    write_csv(&events_path, &stream(32, 24));
    write_samples(&samples_path, &[5_000]);
    let out = dir.path().join("x.npy");
    let mask = dir.path().join("mask.npy");
    ndarray_npy::write_npy(&mask, &Array2::<u8>::zeros((24, 32))).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let base = [
        "represent".to_string(),
        s(&events_path),
        "--samples".into(),
        s(&samples_path),
        "--sensor".into(),
        "32x24".into(),
        "--roi".into(),
        "none".into(),
        "-o".into(),
        s(&out),
    ];
    let cases: [(&[&str], &str); 5] = [
        (&["--repr", "histogram", "--bins", "3"], "bins"),
        (&["--repr", "combined", "--bins", "3"], "--bins 3"),
        (&["--repr", "time-surface", "--eta", "0.2"], "--eta"),
        (&["--repr", "time-surface", "--threshold", "2"], "threshold"),
        (&["--repr", "voxel-grid", "--bins", "0"], "bins"),
    ];
    for (flags, named) in cases {
        let mut args: Vec<&str> = base.iter().map(String::as_str).collect();
        args.extend(flags);
        let err = crate::common::run_err(&args);
        assert!(err.contains(named), "{flags:?}: {err}");
    }
    let mut args: Vec<&str> = base.iter().map(String::as_str).collect();
    let mask = s(&mask);
    args.extend(["--repr", "histogram", "--mask", &mask]);
    let err = crate::common::run_err(&args);
    assert!(err.contains("--mask") && err.contains("histogram"), "{err}");
    assert!(!out.exists());
}
