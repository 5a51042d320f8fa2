//! Models of the real-valued kinds the paper did not choose (time surface, histogram, voxel
//! grid) estimate online exactly as offline: the estimator's extractor is the feature cache's,
//! so a replay in any chunking gives, bit for bit, the prediction on `extract_features` at the
//! estimate times. Their frames are not binary images: `--mcap-frames` refuses them by name.

use crate::support::{self, SENSOR, Synthetic};
use evtac_events::{Resolution, Roi};
use evtac_learn::Model;
use evtac_online::Estimator;
use evtac_repr::{
    HistogramConfig, ReprConfig, TimeSurfaceConfig, VoxelGridConfig, extract_features,
};

fn kinds() -> [ReprConfig; 3] {
    [
        ReprConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 30.0,
            threshold: None,
        }),
        ReprConfig::Histogram(HistogramConfig { window_ms: 50.0 }),
        ReprConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 80.0,
            bins: 3,
        }),
    ]
}

#[test]
fn real_valued_models_estimate_online_as_offline_in_any_chunking() {
    evtac_learn::flush_denormals();
    let events = Synthetic::new(7, 200_000.0, 1000, 300_000).collect();
    for repr in kinds() {
        let dir = tempfile::tempdir().unwrap();
        support::seeded_bundle(dir.path(), 3, &repr, None);
        let model = Model::load(dir.path()).unwrap();
        let online = support::replayed(&model, &events, 2_500);
        assert!(online.len() > 200, "{repr:?}: {} estimates", online.len());
        support::assert_same_estimates(&online, &support::replayed(&model, &events, 97));
        let crop = Resolution::new(240, 240);
        let mut cropped = Vec::new();
        Roi::centered(SENSOR, crop)
            .unwrap()
            .crop_into(&events, &mut cropped);
        let times: Vec<i64> = online.iter().map(|e| e.t_us).collect();
        let features = extract_features(&[repr], crop, None, &cropped, &times).unwrap();
        let inputs = model.predictor.inputs();
        assert_eq!(inputs, repr.frames() * 900);
        for (e, row) in online.iter().zip(features[0].chunks_exact(inputs)) {
            let want = model.predictor.predict_one(row);
            assert_eq!(
                [e.pitch_deg.to_bits(), e.roll_deg.to_bits()],
                [want[0].to_bits(), want[1].to_bits()],
                "{repr:?} at {} us",
                e.t_us
            );
        }
        let distinct: std::collections::HashSet<u32> =
            online.iter().map(|e| e.pitch_deg.to_bits()).collect();
        assert!(
            distinct.len() > 10,
            "{repr:?}: the estimates follow the events"
        );
    }
}

#[test]
fn frames_of_a_real_valued_model_are_refused_by_name() {
    for repr in kinds() {
        let dir = tempfile::tempdir().unwrap();
        support::seeded_bundle(dir.path(), 3, &repr, None);
        let model = Model::load(dir.path()).unwrap();
        let mut estimator = Estimator::for_model(&model, SENSOR, 1000).unwrap();
        let err = estimator.capture_frames(100_000).unwrap_err().to_string();
        assert!(
            err.contains(repr.kind_name()) && err.contains("real-valued"),
            "{err}"
        );
    }
}
