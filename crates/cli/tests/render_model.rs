//! Tests of `evtac render --model`: the angles panel is drawn below the frames, and the
//! estimates it draws (written by `--estimates-csv`) are `evtac predict`'s on the features
//! `evtac represent` computes at the same times with the model's settings and mask.

use crate::common::{run_ok, simulate_tiny};
use crate::render::SIZE;
use evtac_learn::{ModelBundle, Representation};
use evtac_repr::{CROP, Mask, ReprConfig, StaticConfig};
use ndarray::Array2;
use std::fs::File;
use std::path::Path;

/// Height the angles panel adds: 240 pixels and a 10-pixel margin.
const ANGLES: usize = 250;
/// The static model's curve colour (the report's colour of the static representation).
const STATIC_CURVE: [u8; 3] = [31, 119, 180];

/// A static-representation bundle with seeded weights (the estimates do not need training)
/// and the dataset's no-contact mask, with a `tau_ms` unlike the default so the frames'
/// settings are seen to come from the model.
fn write_bundle(dir: &Path, ds: &Path) -> StaticConfig {
    let config = StaticConfig {
        tau_ms: 500.0,
        ..StaticConfig::default()
    };
    let no_contact =
        evtac_experiments::dataset::read_cropped(&ds.join("no_contact.aedat4")).unwrap();
    let mask = Mask::from_no_contact(CROP, &config, &no_contact).unwrap();
    let representation = Representation::new(ReprConfig::Static(config));
    ModelBundle::untrained(5, representation, Some(mask))
        .save(dir)
        .unwrap();
    config
}

#[test]
fn model_estimates_are_drawn_and_equal_predict_on_represent_features() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("ds");
    simulate_tiny("exp1", 4, &ds, 1);
    let model = dir.path().join("model");
    write_bundle(&model, &ds);
    let manifest = evtac_events::manifest::Manifest::read(&ds).unwrap();
    let trial = &manifest.trials[0];
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (gif, csv) = (dir.path().join("r.gif"), dir.path().join("est.csv"));
    let from = trial.motion_start_us.to_string();
    let to = (trial.motion_start_us + 1_000_000).to_string();
    run_ok(&[
        "render",
        &s(&ds),
        "--trial",
        &trial.trial,
        "--model",
        &s(&model),
        "--estimates-csv",
        &s(&csv),
        "--out",
        &s(&gif),
        "--from-us",
        &from,
        "--to-us",
        &to,
        "--fps",
        "10",
    ]);

    // The angles panel below the frames, with the static model's curve in it.
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options.read_info(File::open(&gif).unwrap()).unwrap();
    let size = (usize::from(decoder.width()), usize::from(decoder.height()));
    assert_eq!(size, (SIZE.0, SIZE.1 + ANGLES));
    let frame = decoder.read_next_frame().unwrap().unwrap();
    let curve = frame.buffer[4 * size.0 * SIZE.1..]
        .chunks_exact(4)
        .filter(|p| p[..3] == STATIC_CURVE)
        .count();
    assert!(curve > 50, "{curve} pixels of the model's curve");

    // The estimates: 10 per 100 ms frame, the last at each frame's end.
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t_us,pitch_deg,roll_deg"));
    let rows: Vec<(i64, f32, f32)> = lines
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            (
                v[0].parse().unwrap(),
                v[1].parse().unwrap(),
                v[2].parse().unwrap(),
            )
        })
        .collect();
    assert_eq!(rows.len(), 100);
    assert_eq!(rows[9].0, trial.motion_start_us + 100_000);

    // The same times through `evtac represent` (the model's tau, its mask from the same
    // no-contact recording) and `evtac predict`.
    let times = dir.path().join("times.txt");
    let listed: Vec<String> = rows.iter().map(|r| r.0.to_string()).collect();
    std::fs::write(&times, listed.join("\n")).unwrap();
    let (features, predicted) = (dir.path().join("f.npy"), dir.path().join("y.npy"));
    run_ok(&[
        "represent",
        &s(&ds.join(&trial.file)),
        "--samples",
        &s(&times),
        "--repr",
        "static",
        "--what",
        "features",
        "--tau-ms",
        "500",
        "--mask",
        &s(&ds.join("no_contact.aedat4")),
        "--output",
        &s(&features),
    ]);
    run_ok(&[
        "predict",
        "--model",
        &s(&model),
        "--features",
        &s(&features),
        "--output",
        &s(&predicted),
    ]);
    let y: Array2<f32> = ndarray_npy::read_npy(&predicted).unwrap();
    assert_eq!(y.nrows(), rows.len());
    for (row, (t, pitch, roll)) in y.rows().into_iter().zip(&rows) {
        assert_eq!(
            (row[0].to_bits(), row[1].to_bits()),
            (pitch.to_bits(), roll.to_bits()),
            "at {t} us"
        );
    }
}
