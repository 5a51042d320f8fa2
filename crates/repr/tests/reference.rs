//! The streaming extractor against straightforward references on random streams: the dynamic
//! frame recounted from scratch per sample, the static frame binarized from a plain accumulator,
//! their OR, and pooling recomputed from the full frame; and equal output for any chunking.

use crate::common::{random_batches, random_stream};
use evtac_events::{Event, Resolution};
use evtac_repr::{
    Comparison, DynamicConfig, FeatureExtractor, Mask, Polarity, ReprConfig, StaticAccumulator,
    StaticConfig, ThresholdSpace, dynamic_frame, or_frames, pool8, static_frame,
};
use proptest::prelude::*;

const RES: Resolution = Resolution::new(24, 16);

/// The static and dynamic settings the configs below vary: time constants short enough for the
/// random streams' microsecond spacing to exercise decay and window exits.
fn base_configs() -> (StaticConfig, DynamicConfig) {
    let s = StaticConfig {
        tau_ms: 0.2,
        ..StaticConfig::default()
    };
    let d = DynamicConfig {
        window_ms: 0.15,
        count_threshold: 0,
    };
    (s, d)
}

fn configs() -> Vec<ReprConfig> {
    let (s, d) = base_configs();
    vec![
        ReprConfig::Static(s),
        ReprConfig::Static(StaticConfig {
            threshold: 0.0,
            ..s
        }),
        ReprConfig::Static(StaticConfig {
            polarity: Polarity::Ignore,
            threshold_space: ThresholdSpace::U8,
            comparison: Comparison::Ge,
            threshold: 1.0,
            ..s
        }),
        ReprConfig::Static(StaticConfig {
            synchronous_decay: true,
            threshold: 0.5,
            ..s
        }),
        ReprConfig::Dynamic(d),
        ReprConfig::Dynamic(DynamicConfig {
            count_threshold: 1,
            ..d
        }),
        ReprConfig::Dynamic(DynamicConfig {
            window_ms: 0.04,
            count_threshold: 0,
        }),
        ReprConfig::Combined {
            static_part: s,
            dynamic_part: d,
        },
        // A static plane of its own under a count-threshold-0 window: the extractor then
        // thresholds it only when the dynamic pixel clears (the lazy path).
        ReprConfig::Combined {
            static_part: StaticConfig {
                threshold: 1.0,
                ..s
            },
            dynamic_part: DynamicConfig {
                window_ms: 0.04,
                count_threshold: 0,
            },
        },
        ReprConfig::Combined {
            static_part: StaticConfig {
                synchronous_decay: true,
                threshold: 0.5,
                ..s
            },
            dynamic_part: DynamicConfig {
                count_threshold: 2,
                ..d
            },
        },
        // Both parts side by side: the static plane is shared with a combined output above,
        // which must then keep it per event rather than lazily.
        ReprConfig::Stacked {
            static_part: s,
            dynamic_part: d,
        },
        ReprConfig::Late {
            static_part: StaticConfig {
                synchronous_decay: true,
                threshold: 0.5,
                ..s
            },
            dynamic_part: DynamicConfig {
                count_threshold: 1,
                ..d
            },
        },
    ]
}

/// Combined configs whose accumulators can take events as they leave the window (see
/// `FeatureExtractor::deferring_accumulation`), next to some that cannot.
fn deferrable_configs() -> Vec<ReprConfig> {
    let (s, d) = base_configs();
    let short = DynamicConfig {
        window_ms: 0.04,
        ..d
    };
    let ignore = StaticConfig {
        polarity: Polarity::Ignore,
        tau_ms: 0.1,
        ..s
    };
    let combined = |static_part, dynamic_part| ReprConfig::Combined {
        static_part,
        dynamic_part,
    };
    vec![
        // Deferred: two planes on one accumulator, both read by one window.
        combined(s, d),
        combined(
            StaticConfig {
                threshold: 1.0,
                threshold_space: ThresholdSpace::U8,
                ..s
            },
            d,
        ),
        // Deferred, under the short window.
        combined(StaticConfig { tau_ms: 0.05, ..s }, short),
        // Not deferred: one accumulator read by two windows.
        combined(ignore, d),
        combined(ignore, short),
        // Not deferred: synchronous decay, and a dynamic part that does not set a pixel at its
        // first event.
        combined(
            StaticConfig {
                synchronous_decay: true,
                tau_ms: 0.3,
                ..s
            },
            d,
        ),
        combined(
            StaticConfig { tau_ms: 0.4, ..s },
            DynamicConfig {
                count_threshold: 1,
                ..d
            },
        ),
        // A dynamic output on a window that feeds a deferred accumulator.
        ReprConfig::Dynamic(DynamicConfig {
            count_threshold: 1,
            ..d
        }),
    ]
}

fn sample_times(events: &[Event], n: usize) -> Vec<i64> {
    let end = events.last().map_or(0, |e| e.t) + 200;
    let mut t: Vec<i64> = (0..n)
        .map(|k| -50 + (end + 50) * k as i64 / n.max(1) as i64)
        .collect();
    // A repeated sample time and one exactly on an event are valid too.
    if let Some(&first) = t.first() {
        t.insert(0, first);
    }
    if let Some(e) = events.get(events.len() / 2) {
        t.push(e.t);
        t.sort_unstable();
    }
    t
}

/// Frame and features per config per sample.
type Outputs = Vec<Vec<(Vec<u8>, Vec<f32>)>>;

/// Frames and features per config per sample, computed the plain way.
fn reference(configs: &[ReprConfig], mask: &Mask, events: &[Event], samples: &[i64]) -> Outputs {
    let mut accs: Vec<Option<StaticAccumulator>> = configs
        .iter()
        .map(|c| {
            c.static_part()
                .map(|s| StaticAccumulator::new(RES, s).unwrap())
        })
        .collect();
    let mut out = vec![Vec::new(); configs.len()];
    let mut applied = 0;
    for &t_k in samples {
        let end = events.partition_point(|e| e.t <= t_k);
        for (i, config) in configs.iter().enumerate() {
            let static_bits = accs[i].as_mut().map(|acc| {
                acc.accumulate(&events[applied..end]).unwrap();
                acc.synchronize();
                static_frame(config.static_part().unwrap(), acc.potentials(), Some(mask))
            });
            let dynamic_bits = config.dynamic_part().map(|d| {
                let mut counts = vec![0u32; RES.pixels()];
                for e in &events[..end] {
                    if e.t > t_k - d.window_us() {
                        counts[usize::from(e.y) * usize::from(RES.width) + usize::from(e.x)] += 1;
                    }
                }
                dynamic_frame(d, &counts)
            });
            let (frame, features) = match (static_bits, dynamic_bits) {
                // Stacked and late: each part pooled on its own, static first; the frame is
                // the static one above the dynamic one.
                (Some(s), Some(d)) if config.frames() == 2 => {
                    let features = [pool8(RES, &s).unwrap(), pool8(RES, &d).unwrap()].concat();
                    ([s, d].concat(), features)
                }
                (Some(s), Some(d)) => {
                    let frame = or_frames(&s, &d);
                    let features = pool8(RES, &frame).unwrap();
                    (frame, features)
                }
                (Some(f), None) | (None, Some(f)) => {
                    let features = pool8(RES, &f).unwrap();
                    (f, features)
                }
                (None, None) => unreachable!(),
            };
            out[i].push((frame, features));
        }
        applied = end;
    }
    out
}

/// How `streamed` hands each chunk to the extractor.
#[derive(Clone, Copy, Debug)]
enum Feed {
    /// `push`; the events wait for `advance_to`.
    Push,
    /// `push`, then `prepare` up to the next sample, as each chunk arrives.
    PushThenPrepare,
    /// `push_and_prepare` up to the next sample.
    PushAndPrepare,
}

fn streamed(
    configs: &[ReprConfig],
    mask: &Mask,
    events: &[Event],
    samples: &[i64],
    cuts: &[usize],
    feed: Feed,
    defer: bool,
) -> Outputs {
    let mut fx = FeatureExtractor::new(configs, RES, Some(mask)).unwrap();
    if defer {
        fx = fx.deferring_accumulation();
    }
    let mut out = vec![Vec::new(); configs.len()];
    let mut pushed = 0;
    let mut next_cut = cuts.iter().copied().peekable();
    for &t_k in samples {
        // Push chunks (of the given random sizes) until every event <= t_k is queued.
        while pushed < events.len() && events[pushed].t <= t_k {
            let end = next_cut
                .by_ref()
                .find(|&c| c > pushed)
                .unwrap_or(events.len());
            let chunk = &events[pushed..end];
            pushed = end;
            // The last two are what a live estimator does as each chunk arrives.
            match feed {
                Feed::Push => fx.push(chunk).unwrap(),
                Feed::PushThenPrepare => {
                    fx.push(chunk).unwrap();
                    fx.prepare(t_k).unwrap();
                }
                Feed::PushAndPrepare => fx.push_and_prepare(chunk, t_k).unwrap(),
            }
        }
        fx.advance_to(t_k).unwrap();
        for (i, o) in out.iter_mut().enumerate() {
            o.push((fx.frame(i).to_vec(), fx.features(i).to_vec()));
        }
    }
    out
}

fn random_mask(seed: u64) -> Mask {
    let pixels: Vec<u8> = (0..RES.pixels())
        .map(|p| u8::from((p as u64).wrapping_mul(seed | 1).is_multiple_of(13)))
        .collect();
    Mask::from_pixels(RES, &pixels).unwrap()
}

/// A random stream with its sample times, mask and chunk boundaries, from the proptest inputs.
#[derive(Debug)]
struct Case {
    events: Vec<Event>,
    samples: Vec<i64>,
    mask: Mask,
    cuts: Vec<usize>,
}

impl Case {
    fn new(seed: u64, n: usize, max_gap: i64, samples: usize, chunks: usize) -> Self {
        let events = random_stream(seed, RES, n, 3, max_gap);
        Self {
            samples: sample_times(&events, samples),
            mask: random_mask(seed),
            cuts: random_batches(seed, events.len(), chunks),
            events,
        }
    }

    /// The proptest strategy: up to 600 events with gaps up to 40 us, up to 40 samples, up to
    /// 30 chunks.
    fn any() -> impl Strategy<Value = Case> {
        (any::<u64>(), 0usize..600, 0i64..40, 1usize..40, 1usize..30).prop_map(
            |(seed, n, max_gap, samples, chunks)| Case::new(seed, n, max_gap, samples, chunks),
        )
    }

    fn reference(&self, configs: &[ReprConfig]) -> Outputs {
        reference(configs, &self.mask, &self.events, &self.samples)
    }

    fn streamed(&self, configs: &[ReprConfig], cuts: &[usize], feed: Feed, defer: bool) -> Outputs {
        streamed(
            configs,
            &self.mask,
            &self.events,
            &self.samples,
            cuts,
            feed,
            defer,
        )
    }
}

/// Every frame and feature of `got` equal to `expected`, naming the first that differs.
fn check_outputs(got: &Outputs, expected: &Outputs) -> Result<(), TestCaseError> {
    for (i, (g, e)) in got.iter().zip(expected).enumerate() {
        for (k, (g, e)) in g.iter().zip(e).enumerate() {
            prop_assert_eq!(&g.0, &e.0, "frame of config {} at sample {}", i, k);
            prop_assert_eq!(&g.1, &e.1, "features of config {} at sample {}", i, k);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn extractor_matches_reference_for_any_chunking(case in Case::any()) {
        let configs = configs();
        let got = case.streamed(&configs, &case.cuts, Feed::Push, false);
        check_outputs(&got, &case.reference(&configs))?;
        // One push of everything gives the same, and so does applying each chunk ahead of its
        // sample as it arrives, either way.
        let whole = case.streamed(&configs, &[], Feed::Push, false);
        prop_assert_eq!(&whole, &got);
        for feed in [Feed::PushThenPrepare, Feed::PushAndPrepare] {
            let eager = case.streamed(&configs, &case.cuts, feed, false);
            prop_assert_eq!(&eager, &got, "{:?}", feed);
        }
    }

    #[test]
    fn deferred_accumulation_matches_reference(case in Case::any()) {
        let configs = deferrable_configs();
        let expected = case.reference(&configs);
        for feed in [Feed::Push, Feed::PushThenPrepare, Feed::PushAndPrepare] {
            check_outputs(&case.streamed(&configs, &case.cuts, feed, true), &expected)?;
        }
    }
}

#[test]
fn deferral_takes_only_accumulators_read_by_one_window() {
    let fx = FeatureExtractor::new(&deferrable_configs(), RES, None).unwrap();
    assert_eq!(fx.deferred_accumulators(), 0, "off unless asked for");
    let fx = fx.deferring_accumulation();
    assert_eq!(fx.deferred_accumulators(), 2);
    let deferred: Vec<bool> = (0..fx.len()).map(|i| fx.potentials(i).is_none()).collect();
    assert_eq!(
        deferred,
        [true, true, true, false, false, false, false, true],
        "potentials are withheld for deferred accumulators (and dynamic outputs)"
    );
}

#[test]
fn configs_share_work_but_not_results() {
    // A grid in one extractor equals each config in its own extractor.
    let events = random_stream(99, RES, 2000, 0, 5);
    let samples = sample_times(&events, 25);
    let configs = configs();
    let together = evtac_repr::extract_features(&configs, RES, None, &events, &samples).unwrap();
    for (i, c) in configs.iter().enumerate() {
        let alone =
            evtac_repr::extract_features(std::slice::from_ref(c), RES, None, &events, &samples)
                .unwrap();
        assert_eq!(alone[0], together[i], "config {i}");
    }
}

#[test]
fn reset_returns_to_the_initial_state() {
    let events = random_stream(5, RES, 500, 0, 5);
    let samples = sample_times(&events, 10);
    let mut fx = FeatureExtractor::new(&configs(), RES, None).unwrap();
    let mut first = Vec::new();
    fx.run(&events, &samples, |_, fx| {
        first.push(fx.features(7).to_vec())
    })
    .unwrap();
    fx.reset();
    let mut second = Vec::new();
    fx.run(&events, &samples, |_, fx| {
        second.push(fx.features(7).to_vec())
    })
    .unwrap();
    assert_eq!(first, second);
}
