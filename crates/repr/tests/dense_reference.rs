//! Time surfaces, histograms and voxel grids ([`DenseExtractor`]) against a reference written
//! here from the definitions alone: every sample recomputed from scratch over the events before
//! it, frames compared exactly and pooled features against the reference frames' 8x8 means, for
//! random streams pushed in random chunks with samples between them.

use crate::common::{pool_channels, random_batches, random_stream};
use evtac_events::{Event, Resolution};
use evtac_repr::{
    DenseConfig, DenseExtractor, HistogramConfig, ReprError, TimeSurfaceConfig, VoxelGridConfig,
};
use proptest::prelude::*;

const RES: Resolution = Resolution::new(16, 8);

/// The reference frame (channels x pixels, float64) at `t_k`, straight from the definitions.
fn reference_frame(config: &DenseConfig, events: &[Event], t_k: i64) -> Vec<f64> {
    let pixels = RES.pixels();
    let at = |e: &Event| usize::from(e.y) * usize::from(RES.width) + usize::from(e.x);
    let before: Vec<&Event> = events.iter().filter(|e| e.t < t_k).collect();
    match *config {
        DenseConfig::Histogram(c) => {
            let start = t_k - (c.window_ms * 1000.0).round() as i64;
            let mut out = vec![0.0; 2 * pixels];
            for e in before.iter().filter(|e| e.t >= start) {
                out[usize::from(e.polarity) * pixels + at(e)] += 1.0;
            }
            out
        }
        DenseConfig::TimeSurface(c) => {
            let mut last = vec![None; 2 * pixels];
            for e in &before {
                last[usize::from(e.polarity) * pixels + at(e)] = Some(e.t);
            }
            last.iter()
                .map(|t| match t {
                    None => 0.0,
                    Some(t) => {
                        let v = (-((t_k - t) as f64) / (c.tau_ms * 1000.0)).exp();
                        match c.threshold {
                            Some(x) => f64::from(u8::from(v > x)),
                            None => v,
                        }
                    }
                })
                .collect()
        }
        DenseConfig::VoxelGrid(c) => {
            let w = (c.window_ms * 1000.0).round() as i64;
            let bins = c.bins as usize;
            let mut out = vec![0.0; bins * pixels];
            for e in before.iter().filter(|e| e.t >= t_k - w) {
                // The triangle kernel of every bin, summed directly.
                let ts = bins as f64 * (e.t - (t_k - w)) as f64 / w as f64;
                let sign = if e.polarity { 1.0 } else { -1.0 };
                for (j, bin) in out.chunks_mut(pixels).enumerate() {
                    bin[at(e)] += sign * (1.0f64 - (ts - j as f64).abs()).max(0.0);
                }
            }
            out
        }
    }
}

fn configs() -> Vec<DenseConfig> {
    vec![
        DenseConfig::Histogram(HistogramConfig { window_ms: 0.05 }),
        DenseConfig::Histogram(HistogramConfig { window_ms: 0.333 }),
        DenseConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 0.04,
            threshold: None,
        }),
        DenseConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 0.1,
            threshold: Some(0.3),
        }),
        DenseConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 0.1,
            bins: 1,
        }),
        DenseConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 0.25,
            bins: 5,
        }),
        DenseConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 0.07,
            bins: 3,
        }),
    ]
}

/// Runs `config` over `events` pushed at `cuts`, sampling after each chunk at a time at or
/// after its last event (so no event is pushed after a sample it precedes), and checks every
/// sample against the reference.
fn check(config: DenseConfig, events: &[Event], cuts: &[usize], lags: &[i64]) {
    let mut fx = DenseExtractor::new(config, RES).expect("valid config");
    let mut frame = vec![0f32; fx.channels() * RES.pixels()];
    let mut start = 0;
    let mut sampled = i64::MIN;
    for (i, &end) in cuts.iter().enumerate() {
        fx.push(&events[start..end]).unwrap();
        start = end;
        let latest = events[..end].last().map_or(0, |e| e.t);
        // Sample no earlier than the latest pushed event, and never before an event still to
        // be pushed (it would come after a sample it precedes).
        let t_k = sampled.max(latest + lags[i % lags.len()]);
        if events.get(end).is_some_and(|e| e.t < t_k) {
            continue;
        }
        sampled = t_k;
        fx.advance_to(t_k).unwrap();
        let want = reference_frame(&config, events, t_k);
        fx.frame_into(&mut frame).unwrap();
        let exact: Vec<f32> = want.iter().map(|&v| v as f32).collect();
        match config {
            // The reference sums the kernel in another order: equal to float32 rounding.
            DenseConfig::VoxelGrid(_) => {
                for (k, (a, b)) in frame.iter().zip(&exact).enumerate() {
                    assert!(
                        (a - b).abs() <= 1e-6,
                        "{config:?} t_k {t_k} value {k}: {a} vs {b}"
                    );
                }
            }
            _ => assert_eq!(frame, exact, "{config:?} frame at t_k {t_k}"),
        }
        for (k, (a, b)) in fx
            .features()
            .iter()
            .zip(pool_channels(&want, RES))
            .enumerate()
        {
            assert!(
                (f64::from(*a) - b).abs() <= 1e-6,
                "{config:?} t_k {t_k} feature {k}: {a} vs {b}"
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn every_kind_equals_its_definition_for_any_chunking(
        seed in any::<u64>(),
        n in 0usize..600,
        batches in 1usize..40,
        t0 in prop_oneof![Just(0i64), 1_600_000_000_000_000i64..1_700_000_000_000_000],
        lags in proptest::collection::vec(0i64..200, 1..5),
    ) {
        let events = random_stream(seed, RES, n, t0, 6);
        let cuts = random_batches(seed, n, batches);
        for config in configs() {
            check(config, &events, &cuts, &lags);
        }
    }
}

#[test]
fn long_gaps_and_a_reset_change_nothing() {
    // Gaps of many taus (the surface's reference time moves) and a second trial after reset.
    let mut events = random_stream(7, RES, 300, 0, 3);
    let tail: Vec<Event> = random_stream(8, RES, 300, 5_000_000, 3);
    events.extend(tail);
    let cuts = random_batches(3, events.len(), 25);
    for config in configs() {
        check(config, &events, &cuts, &[0, 50, 10_000]);
        let mut fx = DenseExtractor::new(config, RES).unwrap();
        fx.push(&events).unwrap();
        fx.advance_to(6_000_000).unwrap();
        fx.reset();
        fx.advance_to(0).unwrap();
        assert!(fx.features().iter().all(|&f| f == 0.0), "{config:?}");
    }
}

#[test]
fn an_event_at_the_sample_time_waits_for_the_next() {
    let e = |t, x| Event {
        t,
        x,
        y: 0,
        polarity: true,
    };
    let config = DenseConfig::Histogram(HistogramConfig { window_ms: 1.0 });
    let mut fx = DenseExtractor::new(config, RES).unwrap();
    fx.push(&[e(0, 1), e(1_000, 2)]).unwrap();
    fx.advance_to(1_000).unwrap(); // [0, 1000): the first event only
    assert_eq!(fx.features()[2], 1.0 / 64.0);
    fx.advance_to(1_001).unwrap(); // [1, 1001): the second only
    assert_eq!(fx.features()[2], 1.0 / 64.0);
    let mut frame = vec![0f32; 2 * RES.pixels()];
    fx.frame_into(&mut frame).unwrap();
    assert_eq!(
        (frame[RES.pixels() + 1], frame[RES.pixels() + 2]),
        (0.0, 1.0)
    );
}

#[test]
fn bad_settings_and_inputs_are_errors_naming_them() {
    let bad = [
        DenseConfig::Histogram(HistogramConfig { window_ms: 0.0 }),
        DenseConfig::Histogram(HistogramConfig { window_ms: 0.0005 }),
        DenseConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: f64::NAN,
            threshold: None,
        }),
        DenseConfig::TimeSurface(TimeSurfaceConfig {
            tau_ms: 1.0,
            threshold: Some(1.0),
        }),
        DenseConfig::VoxelGrid(VoxelGridConfig {
            window_ms: 1.0,
            bins: 0,
        }),
    ];
    for config in bad {
        let err = DenseExtractor::new(config, RES).expect_err("invalid");
        assert!(matches!(err, ReprError::InvalidConfig { .. }), "{err}");
    }
    let config = DenseConfig::Histogram(HistogramConfig { window_ms: 1.0 });
    assert!(DenseExtractor::new(config, Resolution::new(12, 8)).is_err());
    let mut fx = DenseExtractor::new(config, RES).unwrap();
    let e = |t| Event {
        t,
        x: 0,
        y: 0,
        polarity: false,
    };
    fx.push(&[e(5)]).unwrap();
    assert!(matches!(
        fx.push(&[e(4)]),
        Err(ReprError::EventOutOfOrder { .. })
    ));
    fx.advance_to(10).unwrap();
    assert!(matches!(
        fx.advance_to(9),
        Err(ReprError::SampleTimeBackwards { .. })
    ));
    assert!(fx.frame_into(&mut [0.0; 3]).is_err());
}
