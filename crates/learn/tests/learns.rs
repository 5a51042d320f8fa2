//! The regressor learns: on a small synthetic task shaped like the sensor's (a contact blob on a
//! 30 x 30 grid displaced by pitch and roll), test MAE ends far below the label spread.

use evtac_learn::{FeatureSet, Predictor, TrainConfig, mae, train};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `n` samples with (pitch, roll) uniform in +-20 degrees; features are an anisotropic bump
/// whose centre and width follow the angles, plus a little noise.
fn synthetic(n: usize, seed: u64) -> FeatureSet {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut features = Vec::with_capacity(n * 900);
    let mut labels = Vec::with_capacity(n * 2);
    for _ in 0..n {
        let pitch: f32 = rng.random_range(-20.0..20.0);
        let roll: f32 = rng.random_range(-20.0..20.0);
        let (cx, cy) = (15.0 + 0.4 * pitch, 15.0 + 0.4 * roll);
        let width = 18.0 + 0.2 * (pitch.abs() + roll.abs());
        for j in 0..900 {
            let (u, v) = ((j % 30) as f32, (j / 30) as f32);
            let d = (u - cx).powi(2) + (v - cy).powi(2);
            let noise: f32 = rng.random_range(-0.02..0.02);
            features.push((-d / width).exp() + noise);
        }
        labels.extend([pitch, roll]);
    }
    FeatureSet::new(features, labels).expect("valid")
}

#[test]
fn test_mae_falls_far_below_the_label_spread() {
    let (train_set, val, test) = (synthetic(1500, 1), synthetic(300, 2), synthetic(300, 3));
    let cfg = TrainConfig {
        epochs: 8,
        seed: 5,
        ..TrainConfig::default()
    };
    let mut epochs = 0;
    let trained = train(&train_set, &val, &cfg, |_| epochs += 1).expect("trains");
    assert_eq!(epochs, 8);
    assert_eq!(trained.history.len(), 8);
    let best = trained
        .history
        .iter()
        .map(|r| r.val_mae)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(trained.best_val.overall, best);
    assert_eq!(trained.history[trained.best_epoch - 1].val_mae, best);

    let predictor = Predictor::new(&trained.parameters).expect("predictor");
    let m = mae(
        &predictor.predict(&test.features).expect("rows"),
        &test.labels,
    )
    .expect("mae");
    // Predicting the mean label gives an MAE of about 10 degrees (uniform on +-20).
    let spread = 10.0;
    assert!(m.overall < 0.15 * spread, "test MAE {m:?}");
    assert!(
        m.pitch < 0.2 * spread && m.roll < 0.2 * spread,
        "test MAE {m:?}"
    );
}
