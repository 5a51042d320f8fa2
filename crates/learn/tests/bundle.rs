//! Bundles: PyTorch-layout safetensors readable by the `safetensors` Python package with a numpy
//! forward pass matching [`Predictor`], and byte-identical weights for identical seeds.

use evtac_learn::Representation;
use evtac_learn::bundle::MODEL_FILE;
use evtac_learn::{FeatureSet, ModelBundle, Predictor, TrainConfig, train};
use evtac_repr::{CROP, Mask, ReprConfig};
use ndarray::Array2;

/// A small deterministic training set: `n` samples whose features are bumps placed by the label.
fn tiny_set(n: usize, offset: usize) -> FeatureSet {
    let mut features = Vec::with_capacity(n * 900);
    let mut labels = Vec::with_capacity(n * 2);
    for s in offset..offset + n {
        let pitch = ((s * 37) % 41) as f32 - 20.0;
        let roll = ((s * 53) % 39) as f32 - 19.0;
        for j in 0..900 {
            let (u, v) = ((j % 30) as f32, (j / 30) as f32);
            let d = (u - 15.0 - pitch * 0.5).powi(2) + (v - 15.0 - roll * 0.5).powi(2);
            features.push((-d / 20.0).exp());
        }
        labels.extend([pitch, roll]);
    }
    FeatureSet::new(features, labels).expect("valid set")
}

fn quick_config(seed: u64) -> TrainConfig {
    TrainConfig {
        epochs: 2,
        seed,
        ..TrainConfig::default()
    }
}

fn train_bundle(seed: u64, dir: &std::path::Path) -> ModelBundle {
    let cfg = quick_config(seed);
    let trained = train(&tiny_set(96, 0), &tiny_set(32, 1000), &cfg, |_| {}).expect("trains");
    let bundle = ModelBundle::from_trained(
        trained,
        cfg,
        Representation::new(ReprConfig::default()),
        Some(Mask::from_pixels(CROP, &[1; 240 * 240]).expect("mask")),
    );
    bundle.save(dir).expect("saves");
    bundle
}

#[test]
fn same_seed_same_bytes_different_seed_different_weights() {
    let dirs: Vec<tempfile::TempDir> = (0..3).map(|_| tempfile::tempdir().expect("tmp")).collect();
    let a = train_bundle(3, dirs[0].path());
    let b = train_bundle(3, dirs[1].path());
    let c = train_bundle(4, dirs[2].path());
    let bytes = |d: &tempfile::TempDir| std::fs::read(d.path().join(MODEL_FILE)).expect("read");
    assert!(
        bytes(&dirs[0]) == bytes(&dirs[1]),
        "same seed gave different model files"
    );
    assert_eq!(a.history.len(), 2);
    assert_eq!(a.config.metrics, b.config.metrics);
    assert_ne!(a.parameters, c.parameters);
    assert!(bytes(&dirs[0]) != bytes(&dirs[2]));
    let loaded = ModelBundle::load(dirs[0].path()).expect("loads");
    assert_eq!(loaded.parameters, a.parameters);
    assert_eq!(loaded.config, a.config);
    assert_eq!(loaded.mask, a.mask);
}

/// Loads `model.safetensors` with the `safetensors` package and runs the MLP in numpy.
const NUMPY_FORWARD: &str = r#"
import sys, numpy as np
from safetensors.numpy import load_file
w = load_file(sys.argv[1])
h = np.load(sys.argv[2]).astype(np.float64)
for i in range(4):
    W, b = w[f"layers.{i}.weight"], w[f"layers.{i}.bias"]
    assert W.dtype == np.float32 and W.shape[0] == b.shape[0]
    h = h @ W.astype(np.float64).T + b
    if i < 3:
        h = np.maximum(h, 0.0)
np.save(sys.argv[3], h)
"#;

#[test]
fn safetensors_load_in_python_and_numpy_reproduces_the_predictor() {
    let dir = tempfile::tempdir().expect("tmp");
    let bundle = train_bundle(9, dir.path());
    let set = tiny_set(20, 500);
    let x = Array2::from_shape_vec((20, 900), set.features.clone()).expect("shape");
    let (x_path, y_path) = (dir.path().join("x.npy"), dir.path().join("y.npy"));
    ndarray_npy::write_npy(&x_path, &x).expect("write x");
    let model = dir.path().join(MODEL_FILE);
    let args = [model.to_str(), x_path.to_str(), y_path.to_str()].map(|p| p.expect("utf-8 path"));
    if evtac_testkit::run_python(NUMPY_FORWARD, &args).is_none() {
        return;
    }
    let reference: Array2<f64> = ndarray_npy::read_npy(&y_path).expect("read y");
    let predictor = Predictor::new(&bundle.parameters).expect("predictor");
    let ours = predictor.predict(&set.features).expect("predict");
    assert_eq!(reference.dim(), (20, 2));
    for (row, p) in reference.rows().into_iter().zip(&ours) {
        for k in 0..2 {
            assert!(
                (row[k] - f64::from(p[k])).abs() < 1e-4 * (1.0 + row[k].abs()),
                "numpy {row} vs ours {p:?}"
            );
        }
    }
}
