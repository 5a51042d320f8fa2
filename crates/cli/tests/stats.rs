//! Tests of `evtac stats`: a session simulated with known, non-default noise is measured back
//! into simulator parameters close to the ones used, and `evtac simulate --params` with them
//! simulates that noise; bad parameter files name the file and the field.

use crate::common::{evtac, run_ok};
use evtac_sim::SimParams;

/// The noise the session is simulated with: every measured field off its default.
const NOISY: &str = r#"{
  "dvs": {"leak_rate_hz": 0.04, "shot_noise_rate_hz": 0.06, "hot_pixels": 25,
          "hot_pixel_rate_hz": [30.0, 60.0]},
  "imu": {"gyro_noise_deg_s": 0.12, "gyro_bias_deg_s": 0.8, "accel_noise_g": 0.004,
          "temperature_c": 24.5}
}"#;

/// Asserts `got` lies within `relative` of `want`.
fn close(what: &str, got: f64, want: f64, relative: f64) {
    assert!(
        (got - want).abs() <= relative * want.abs(),
        "{what}: measured {got}, simulated with {want} (allowed {relative})"
    );
}

/// Events in the recording at `path`.
fn events(path: &std::path::Path) -> usize {
    evtac_formats::read_recording(path).unwrap().events.len()
}

#[test]
fn stats_recover_the_simulated_noise_and_simulate_params_uses_them() {
    let dir = tempfile::tempdir().unwrap();
    let noisy = dir.path().join("noisy.json");
    std::fs::write(&noisy, NOISY).unwrap();
    let session = dir.path().join("session");
    let simulate = |out: &std::path::Path, params: Option<&std::path::Path>, session: bool| {
        let mut args = vec![
            "simulate",
            "--protocol",
            "exp1",
            "--scale",
            "tiny",
            "--seed",
            "5",
            "--limit",
        ];
        args.push(if session { "6" } else { "1" });
        args.extend(["--out", out.to_str().unwrap()]);
        if let Some(p) = params {
            args.extend(["--params", p.to_str().unwrap()]);
        }
        if session {
            args.push("--session");
        }
        run_ok(&args);
    };
    simulate(&session, Some(&noisy), true);

    let fitted = dir.path().join("fitted.json");
    let rates = dir.path().join("rates.csv");
    let out = run_ok(&[
        "stats",
        session.join("session.aedat4").to_str().unwrap(),
        "--sim-params",
        fitted.to_str().unwrap(),
        "--rates",
        rates.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains("dvs.leak_rate_hz"), "{stdout}");
    assert!(
        stdout.contains("every other field is the simulator's default"),
        "{stdout}"
    );
    let rates = std::fs::read_to_string(rates).unwrap();
    assert!(
        rates.starts_with("start_s,events_per_s,on_per_s,rest\n0.000,"),
        "{rates}"
    );
    assert!(
        rates.contains(",1\n") && rates.contains(",0\n"),
        "rest and motion bins"
    );

    let p: SimParams = evtac_sim::read_params(&fitted).unwrap();
    let d = SimParams::default();
    close("leak", p.dvs.leak_rate_hz, 0.04, 0.05);
    close("shot", p.dvs.shot_noise_rate_hz, 0.06, 0.05);
    assert_eq!(p.dvs.hot_pixels, 25);
    close("hot low", p.dvs.hot_pixel_rate_hz[0], 30.0, 0.15);
    close("hot high", p.dvs.hot_pixel_rate_hz[1], 60.0, 0.15);
    // The stamps jitter and each stretch of the session has its own clock offset (the simulated
    // IMU clock): the rate is measured to a few parts in 10^5.
    close("IMU rate", p.imu.rate_hz, 800.0, 2e-4);
    close("gyro noise", p.imu.gyro_noise_deg_s, 0.12, 0.03);
    // Ten or so independent biases per axis: the spread of their RMS is about a sixth.
    close("gyro bias", p.imu.gyro_bias_deg_s, 0.8, 0.35);
    close(
        "gyro step",
        p.imu.gyro_lsb_deg_s,
        d.imu.gyro_lsb_deg_s,
        1e-6,
    );
    close("accel noise", p.imu.accel_noise_g, 0.004, 0.03);
    close("accel step", p.imu.accel_lsb_g, d.imu.accel_lsb_g, 1e-6);
    close("temperature", p.imu.temperature_c, 24.5, 1e-6);
    // What a sensor at rest cannot show keeps its default.
    assert_eq!(
        (&p.contact, &p.timeline, &p.sensor),
        (&d.contact, &d.timeline, &d.sensor)
    );
    assert_eq!(p.dvs.pos_thres, d.dvs.pos_thres);
    assert_eq!(p.imu.gyro_scale_error, d.imu.gyro_scale_error);

    // Simulated with the fitted parameters, the sensor out of contact is as noisy as the
    // session's: about (0.1 Hz x 307200 pixels + 25 x 45 Hz) x 2 s, over three times the
    // defaults' (0.03 Hz, 12 hot pixels).
    let (fit_ds, default_ds) = (dir.path().join("fit"), dir.path().join("default"));
    simulate(&fit_ds, Some(&fitted), false);
    simulate(&default_ds, None, false);
    let fit_events = events(&fit_ds.join("no_contact.aedat4"));
    let default_events = events(&default_ds.join("no_contact.aedat4"));
    let session_events = events(&session.join("no_contact.aedat4"));
    close(
        "no-contact events",
        fit_events as f64,
        session_events as f64,
        0.1,
    );
    assert!(
        fit_events > 3 * default_events,
        "{fit_events} vs {default_events}"
    );

    hot_pixels_are_learned_written_and_removed(dir.path(), &session.join("session.aedat4"));
}

/// `stats --hot-pixels` writes the 25 simulated hot pixels as a mask, `--filter
/// hot-pixels=auto` removes the same pixels as `--filter hot-pixels=MASK`, and the recording
/// filtered so has no hot pixel left.
fn hot_pixels_are_learned_written_and_removed(dir: &std::path::Path, recording: &std::path::Path) {
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let mask = dir.join("hot.npy");
    let said = run_ok(&["stats", &s(recording), "--hot-pixels", &s(&mask)]);
    assert!(String::from_utf8_lossy(&said.stdout).contains("(25 hot pixels of 640x480)"));
    let mask: ndarray::Array2<u8> = ndarray_npy::read_npy(&mask).unwrap();
    let marked: std::collections::BTreeSet<(u16, u16)> = mask
        .indexed_iter()
        .filter(|(_, v)| **v != 0)
        .map(|((y, x), _)| (x as u16, y as u16))
        .collect();
    // Independently: the 25 busiest pixels of the recording out of contact, where every pixel
    // but the hot ones fires at the background's rate.
    let rest = evtac_formats::read_recording(recording.with_file_name("no_contact.aedat4"))
        .unwrap()
        .events;
    let mut counts = std::collections::HashMap::<(u16, u16), u32>::new();
    rest.iter()
        .for_each(|e| *counts.entry((e.x, e.y)).or_default() += 1);
    let mut busiest: Vec<_> = counts.into_iter().collect();
    busiest.sort_by_key(|&(p, n)| (std::cmp::Reverse(n), p));
    let top: std::collections::BTreeSet<_> = busiest[..25].iter().map(|&(p, _)| p).collect();
    assert_eq!(marked, top);

    let (auto, file) = (dir.join("auto.aedat4"), dir.join("file.aedat4"));
    let out = run_ok(&[
        "filter",
        &s(recording),
        &s(&auto),
        "--filter",
        "hot-pixels=auto",
    ]);
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("hot-pixels=auto: 25 hot pixels learned from"),
        "{said}"
    );
    run_ok(&[
        "filter",
        &s(recording),
        &s(&file),
        "--filter",
        &format!("hot-pixels={}", dir.join("hot.npy").display()),
    ]);
    let original = evtac_formats::read_recording(recording).unwrap();
    let kept: Vec<_> = original
        .events
        .iter()
        .filter(|e| !marked.contains(&(e.x, e.y)))
        .copied()
        .collect();
    assert!(kept.len() < original.events.len());
    assert_eq!(evtac_formats::read_recording(&auto).unwrap().events, kept);
    assert_eq!(evtac_formats::read_recording(&file).unwrap().events, kept);

    let json = run_ok(&[
        "stats",
        &s(recording),
        "--json",
        "--filter",
        "hot-pixels=auto",
    ]);
    let stats: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(stats["hot"], serde_json::json!([]), "{stats}");
    assert_eq!(stats["events"], kept.len());
}

#[test]
fn bad_params_files_name_the_file_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let fails = |text: &str, want: &str| {
        let path = dir.path().join("p.json");
        std::fs::write(&path, text).unwrap();
        let out = dir.path().join("out");
        let o = evtac()
            .args([
                "simulate",
                "--protocol",
                "exp1",
                "--scale",
                "tiny",
                "--limit",
                "1",
            ])
            .args([
                "--out",
                out.to_str().unwrap(),
                "--params",
                path.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(!o.status.success(), "{text} was accepted");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains(&format!("{}: field `{want}`", path.display())),
            "{err}"
        );
        assert!(!out.exists(), "nothing is simulated");
    };
    fails(r#"{"dvs": {"leak_rate": 0.1}}"#, "dvs.leak_rate");
    fails(r#"{"imu": {"rate_hz": "fast"}}"#, "imu.rate_hz");
    fails(
        r#"{"imu": {"gyro_noise_deg_s": -0.1}}"#,
        "imu.gyro_noise_deg_s",
    );
}
