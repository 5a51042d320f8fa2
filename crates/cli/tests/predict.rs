//! Tests of `evtac predict`.

use crate::common::{evtac, run_err, run_ok};
use evtac_learn::{ModelBundle, Parameters, Predictor, Representation};
use evtac_repr::ReprConfig;
use ndarray::Array2;

/// A bundle with seeded initial weights (prediction does not care whether they were trained).
fn write_bundle(dir: &std::path::Path) -> Parameters {
    let bundle = ModelBundle::untrained(21, Representation::new(ReprConfig::default()), None);
    bundle.save(dir).expect("bundle saved");
    bundle.parameters
}

fn features(n: usize) -> Array2<f32> {
    Array2::from_shape_fn((n, 900), |(r, j)| ((r * 7 + j * 3) % 11) as f32 / 10.0)
}

const NUMPY_FORWARD: &str = r#"
import sys, numpy as np
from safetensors.numpy import load_file
w = load_file(sys.argv[1])
h = np.load(sys.argv[2]).astype(np.float64)
for i in range(4):
    h = h @ w[f"layers.{i}.weight"].astype(np.float64).T + w[f"layers.{i}.bias"]
    h = np.maximum(h, 0.0) if i < 3 else h
print(" ".join(repr(float(v)) for v in h.ravel()))
"#;

#[test]
fn predicts_like_the_library_and_numpy() {
    let dir = tempfile::tempdir().expect("tmp");
    let model = dir.path().join("model");
    let parameters = write_bundle(&model);
    let (x_path, y_path) = (dir.path().join("x.npy"), dir.path().join("y.npy"));
    let x = features(6);
    ndarray_npy::write_npy(&x_path, &x).expect("write features");
    let s = |p: &std::path::Path| p.to_str().expect("utf-8").to_string();
    run_ok(&[
        "predict",
        "--model",
        &s(&model),
        "--features",
        &s(&x_path),
        "--output",
        &s(&y_path),
        "--unchecked-features",
    ]);
    let y: Array2<f32> = ndarray_npy::read_npy(&y_path).expect("float32 N x 2 output");
    assert_eq!(y.dim(), (6, 2));
    let flat: Vec<f32> = x.iter().copied().collect();
    let expected = Predictor::new(&parameters)
        .expect("predictor")
        .predict(&flat)
        .expect("rows");
    for (row, e) in y.rows().into_iter().zip(&expected) {
        assert_eq!([row[0], row[1]], *e);
    }
    let model_file = model.join("model.safetensors");
    let Some(out) = evtac_testkit::run_python(NUMPY_FORWARD, &[&s(&model_file), &s(&x_path)])
    else {
        return;
    };
    let numpy: Vec<f64> = out
        .split_whitespace()
        .map(|v| v.parse().expect("number"))
        .collect();
    assert_eq!(numpy.len(), 12);
    for (n, p) in numpy.iter().zip(y.iter()) {
        assert!(
            (n - f64::from(*p)).abs() < 1e-4 * (1.0 + n.abs()),
            "{n} vs {p}"
        );
    }
}

#[test]
fn rejects_wrong_dtype_and_shape_clearly() {
    let dir = tempfile::tempdir().expect("tmp");
    let model = dir.path().join("model");
    write_bundle(&model);
    type WriteInput = Box<dyn Fn(&std::path::Path)>;
    let cases: [(&str, WriteInput, &str); 2] = [
        (
            "f64.npy",
            Box::new(|p| ndarray_npy::write_npy(p, &features(2).mapv(f64::from)).expect("write")),
            "must be float32",
        ),
        (
            "narrow.npy",
            Box::new(|p| ndarray_npy::write_npy(p, &Array2::<f32>::zeros((3, 10))).expect("write")),
            "shape (N, 900), the file has [3, 10]",
        ),
    ];
    for (name, write, message) in cases {
        let path = dir.path().join(name);
        write(&path);
        let out = evtac()
            .args(["predict", "--model"])
            .arg(&model)
            .arg("--features")
            .arg(&path)
            .arg("--output")
            .arg(dir.path().join("out.npy"))
            .arg("--unchecked-features")
            .output()
            .expect("evtac runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name} accepted");
        assert!(stderr.contains(message), "{name}: {stderr}");
    }
}

fn as_refs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// A 320x240 recording with events all over the sensor, and sample times in it.
fn recording(dir: &std::path::Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let path = dir.join("trial.aedat4");
    let mut w = evtac_formats::EventWriter::create(
        &path,
        Some(evtac_events::Resolution::new(320, 240)),
        None,
    )
    .expect("writer");
    let events: Vec<evtac_events::Event> = (0..40_000i64)
        .map(|i| evtac_events::Event {
            t: i * 25,
            x: ((i * 7) % 320) as u16,
            y: ((i * 13) % 240) as u16,
            polarity: i % 3 != 0,
        })
        .collect();
    w.write_events(&events).expect("events");
    w.finish().expect("finish");
    let times = dir.join("times.txt");
    std::fs::write(&times, "200000\n500000\n900000\n").expect("times");
    (path, times)
}

#[test]
fn features_made_otherwise_than_the_models_are_refused_naming_both() {
    let dir = tempfile::tempdir().expect("tmp");
    let model = dir.path().join("model");
    let bundle = ModelBundle::untrained(
        3,
        Representation::new(ReprConfig::Static(evtac_repr::StaticConfig::default())),
        None,
    );
    bundle.save(&model).expect("bundle saved");
    let (trial, times) = recording(dir.path());
    let s = |p: &std::path::Path| p.to_str().expect("utf-8").to_string();
    let (features, out) = (dir.path().join("f.npy"), dir.path().join("y.npy"));
    let represent = |extra: &[&str]| {
        let mut args = vec![
            "represent".to_string(),
            s(&trial),
            "--samples".into(),
            s(&times),
            "--output".into(),
            s(&features),
        ];
        args.extend(extra.iter().map(|a| a.to_string()));
        args
    };
    let predict = [
        "predict".to_string(),
        "--model".into(),
        s(&model),
        "--features".into(),
        s(&features),
        "--output".into(),
        s(&out),
    ];

    // The README's chain with combined features and a static model: 900 columns each.
    run_ok(&as_refs(&represent(&["--repr", "combined"])));
    let provenance = std::fs::read_to_string(dir.path().join("f.npy.json")).expect("sidecar");
    assert!(provenance.contains("v1_combined_"), "{provenance}");
    let err = run_err(&as_refs(&predict));
    assert!(err.contains("the features are v1_combined_"), "{err}");
    assert!(err.contains("the model reads v1_static_"), "{err}");
    assert!(err.contains("evtac represent --model"), "{err}");
    assert!(!out.exists());
    // Other static settings, the same.
    run_ok(&as_refs(&represent(&[
        "--repr", "static", "--tau-ms", "800",
    ])));
    let err = run_err(&as_refs(&predict));
    assert!(err.contains("tau800"), "{err}");

    // The model's own features.
    run_ok(&as_refs(&represent(&["--model", &s(&model)])));
    run_ok(&as_refs(&predict));
    let checked: Array2<f32> = ndarray_npy::read_npy(&out).expect("output");
    assert_eq!(checked.dim(), (3, 2));
    // The model's settings on filtered events: the model's features were not filtered.
    run_ok(&as_refs(&represent(&[
        "--model",
        &s(&model),
        "--filter",
        "polarity=on",
    ])));
    let err = run_err(&as_refs(&predict));
    assert!(
        err.contains("went through polarity=on, the model's through no filter"),
        "{err}"
    );
    run_ok(&as_refs(&represent(&["--model", &s(&model)])));

    // Without a record of what made them: refused, unless the user vouches for them.
    std::fs::remove_file(dir.path().join("f.npy.json")).expect("remove");
    let err = run_err(&as_refs(&predict));
    assert!(err.contains("--unchecked-features"), "{err}");
    let mut unchecked = predict.to_vec();
    unchecked.push("--unchecked-features".into());
    run_ok(&as_refs(&unchecked));
    let y: Array2<f32> = ndarray_npy::read_npy(&out).expect("output");
    assert_eq!(y, checked);

    // --model sets the representation: settings beside it are refused.
    let err = run_err(&as_refs(&represent(&[
        "--model",
        &s(&model),
        "--tau-ms",
        "5",
    ])));
    assert!(err.contains("cannot be used with"), "{err}");
}
