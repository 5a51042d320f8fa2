//! Tests of `evtac predict`.

use crate::common::{evtac, run_ok};
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
            .output()
            .expect("evtac runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name} accepted");
        assert!(stderr.contains(message), "{name}: {stderr}");
    }
}
