//! The real-valued kinds as [`ReprConfig`]s run by [`FeatureExtractor`]: beside binary configs
//! in one extractor, each output equals what a standalone [`DenseExtractor`] (tested against
//! tonic and the definitions) or a binary-only extractor gives, for any chunking and through
//! every way of feeding events (`push`, `push_with_roi`, `push_and_prepare`).

use crate::common::{random_batches, random_stream};
use evtac_events::{Event, Resolution, Roi};
use evtac_repr::{
    DenseExtractor, FeatureExtractor, HistogramConfig, ReprConfig, ReprKind, TimeSurfaceConfig,
    VoxelGridConfig,
};
use proptest::prelude::*;

const RES: Resolution = Resolution::new(16, 8);

fn dense_configs() -> [ReprConfig; 4] {
    [
        ReprConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 0.05,
            threshold: None,
        }),
        ReprConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 0.1,
            threshold: Some(0.4),
        }),
        ReprConfig::Histogram(HistogramConfig { window_ms: 0.2 }),
        ReprConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 0.15,
            bins: 3,
        }),
    ]
}

/// Binary configs with short windows and taus, so frames change within the streams.
fn binary_configs() -> [ReprConfig; 2] {
    let mut combined = ReprConfig::default();
    if let ReprConfig::Combined {
        static_part,
        dynamic_part,
    } = &mut combined
    {
        static_part.tau_ms = 0.1;
        dynamic_part.window_ms = 0.1;
    }
    let stacked = ReprKind::Stacked.config(
        *combined.static_part().expect("combined has one"),
        *combined.dynamic_part().expect("combined has one"),
    );
    [combined, stacked]
}

#[derive(Debug, Clone, Copy)]
enum Feed {
    Push,
    PushAndPrepare,
}

fn check(events: &[Event], cuts: &[usize], feed: Feed) {
    let [a, b, c, d] = dense_configs();
    let [e, f] = binary_configs();
    // Binary and real-valued configs interleaved.
    let configs = [a, e, b, c, f, d];
    let mut mixed = FeatureExtractor::new(&configs, RES, None).expect("valid configs");
    let mut binary = FeatureExtractor::new(&[e, f], RES, None).expect("valid configs");
    let mut alone: Vec<DenseExtractor> = [a, b, c, d]
        .iter()
        .map(|c| DenseExtractor::new(c.dense_part().expect("dense"), RES).expect("valid"))
        .collect();
    let mut start = 0;
    let mut values = Vec::new();
    let mut want = Vec::new();
    for &end in cuts {
        let chunk = &events[start..end];
        start = end;
        // Sample at the next event's time (events before it are all pushed).
        let t_k = events.get(end).map_or(i64::MAX / 4, |e| e.t);
        match feed {
            Feed::Push => mixed.push(chunk).unwrap(),
            Feed::PushAndPrepare => mixed.push_and_prepare(chunk, t_k).unwrap(),
        }
        binary.push(chunk).unwrap();
        for fx in &mut alone {
            fx.push(chunk).unwrap();
        }
        mixed.advance_to(t_k).unwrap();
        binary.advance_to(t_k).unwrap();
        for (k, fx) in alone.iter_mut().enumerate() {
            fx.advance_to(t_k).unwrap();
            let i = [0, 2, 3, 5][k];
            assert_eq!(mixed.features(i), fx.features(), "config {i} at {t_k}");
            assert_eq!(mixed.feature_len(i), fx.channels() * 2);
            mixed.frame_values_into(i, &mut values);
            want.resize(fx.channels() * RES.pixels(), 0.0);
            fx.frame_into(&mut want).unwrap();
            assert_eq!(values, want, "config {i} frame at {t_k}");
            assert!(mixed.potentials(i).is_none() && mixed.counts(i).is_none());
        }
        for (k, i) in [1, 4].into_iter().enumerate() {
            assert_eq!(mixed.features(i), binary.features(k), "config {i} at {t_k}");
            assert_eq!(mixed.frame(i), binary.frame(k));
            mixed.frame_values_into(i, &mut values);
            let ones: Vec<f32> = binary.frame(k).iter().map(|&b| f32::from(b)).collect();
            assert_eq!(values, ones);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn real_valued_configs_beside_binary_ones_equal_their_own_extractors(
        seed in any::<u64>(),
        n in 0usize..500,
        batches in 1usize..30,
        prepare in any::<bool>(),
    ) {
        let events = random_stream(seed, RES, n, 1_000, 7);
        let cuts = random_batches(seed, n, batches);
        let feed = if prepare { Feed::PushAndPrepare } else { Feed::Push };
        check(&events, &cuts, feed);
    }
}

#[test]
fn a_region_of_interest_crops_for_every_output() {
    let sensor = Resolution::new(32, 24);
    let roi = Roi::centered(sensor, RES).expect("fits");
    let events = random_stream(7, sensor, 400, 0, 3);
    let configs = dense_configs();
    let mut fx = FeatureExtractor::new(&configs, RES, None).unwrap();
    fx.push_with_roi(&events, &roi).unwrap();
    let mut cropped = Vec::new();
    roi.crop_into(&events, &mut cropped);
    let t_k = events.last().map_or(0, |e| e.t) + 1;
    fx.advance_to(t_k).unwrap();
    for (i, config) in configs.iter().enumerate() {
        let mut alone = DenseExtractor::new(config.dense_part().unwrap(), RES).unwrap();
        alone.push(&cropped).unwrap();
        alone.advance_to(t_k).unwrap();
        assert_eq!(fx.features(i), alone.features(), "{config:?}");
        assert!(
            fx.features(i).iter().any(|&v| v != 0.0),
            "{config:?} saw events"
        );
    }
    // A second trial after reset is the first again.
    fx.reset();
    fx.push_with_roi(&events, &roi).unwrap();
    fx.advance_to(t_k).unwrap();
    let mut again = DenseExtractor::new(configs[2].dense_part().unwrap(), RES).unwrap();
    again.push(&cropped).unwrap();
    again.advance_to(t_k).unwrap();
    assert_eq!(fx.features(2), again.features());
}

#[test]
fn kinds_configs_and_keys() {
    for kind in ReprKind::BEYOND {
        let config = kind.config(Default::default(), Default::default());
        assert_eq!(config.kind(), kind);
        assert!(kind.is_dense() && config.dense_part().is_some());
        assert_eq!(kind.parts(), (false, false));
        assert_eq!(ReprConfig::from_dense(config.dense_part().unwrap()), config);
        let json = serde_json::to_string(&config).unwrap();
        assert!(
            json.contains(&format!("\"kind\":\"{}\"", kind.name())),
            "{json}"
        );
        assert_eq!(serde_json::from_str::<ReprConfig>(&json).unwrap(), config);
        assert!(config.cache_key().starts_with("v1_"));
        assert!(config.validate().is_ok());
    }
    let voxel = ReprConfig::VoxelGrid(VoxelGridConfig {
        window_ms: 640.0,
        bins: 5,
    });
    assert_eq!(voxel.frames(), 5);
    assert_eq!(
        ReprKind::Histogram
            .config(Default::default(), Default::default())
            .frames(),
        2
    );
    let keys: std::collections::HashSet<String> =
        dense_configs().iter().map(ReprConfig::cache_key).collect();
    assert_eq!(keys.len(), 4);
    let bad = ReprConfig::Histogram(HistogramConfig { window_ms: 0.0 });
    assert!(FeatureExtractor::new(&[bad], RES, None).is_err());
}

#[test]
#[should_panic(expected = "frame_values_into")]
fn a_binary_frame_of_a_real_valued_output_is_refused() {
    let fx = FeatureExtractor::new(&dense_configs()[..1], RES, None).unwrap();
    let _ = fx.frame(0);
}

#[test]
fn front_end_settings_build_each_kind_and_refuse_what_it_does_not_take() {
    use evtac_repr::{DenseSettings, ReprError};
    let surface = ReprKind::TimeSurface
        .dense_config(DenseSettings {
            tau_ms: Some(30.0),
            threshold: Some(0.5),
            ..DenseSettings::default()
        })
        .unwrap();
    assert_eq!(
        surface,
        ReprConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 30.0,
            threshold: Some(0.5)
        })
    );
    let voxel = ReprKind::VoxelGrid
        .dense_config(DenseSettings {
            bins: Some(3),
            ..DenseSettings::default()
        })
        .unwrap();
    assert_eq!(
        voxel,
        ReprConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 640.0,
            bins: 3
        })
    );
    for kind in ReprKind::BEYOND {
        assert_eq!(
            kind.dense_config(DenseSettings::default()).unwrap(),
            kind.config(Default::default(), Default::default())
        );
    }
    let refused = |kind: ReprKind, settings| match kind.dense_config(settings) {
        Err(ReprError::InvalidConfig { field, .. }) => field,
        other => panic!("{kind}: {other:?}"),
    };
    let bins = DenseSettings {
        bins: Some(2),
        ..DenseSettings::default()
    };
    assert_eq!(refused(ReprKind::Histogram, bins), "bins");
    assert_eq!(refused(ReprKind::TimeSurface, bins), "bins");
    let tau = DenseSettings {
        tau_ms: Some(2.0),
        ..DenseSettings::default()
    };
    assert_eq!(refused(ReprKind::VoxelGrid, tau), "tau_ms");
    assert_eq!(refused(ReprKind::Static, tau), "kind");
    let bad = DenseSettings {
        threshold: Some(1.5),
        ..DenseSettings::default()
    };
    assert_eq!(refused(ReprKind::TimeSurface, bad), "threshold");
}
