//! Bad input: clear errors, or the documented behaviour.

use evtac_events::{Event, Resolution, Roi};
use evtac_repr::{FeatureExtractor, Mask, ReprConfig, ReprError, StaticConfig};

fn ev(t: i64, x: u16, y: u16) -> Event {
    Event {
        t,
        x,
        y,
        polarity: true,
    }
}

fn extractor() -> FeatureExtractor {
    FeatureExtractor::new(&[ReprConfig::default()], Resolution::new(240, 240), None).unwrap()
}

#[test]
fn events_out_of_time_order_are_rejected_within_and_across_chunks() {
    let mut fx = extractor();
    let err = fx.push(&[ev(10, 0, 0), ev(9, 0, 0)]).unwrap_err();
    assert_eq!(
        err,
        ReprError::EventOutOfOrder {
            index: 1,
            t: 9,
            previous: 10
        }
    );
    assert_eq!(fx.pending(), 0, "a rejected chunk is not queued");
    fx.push(&[ev(10, 0, 0)]).unwrap();
    assert!(matches!(
        fx.push(&[ev(5, 0, 0)]),
        Err(ReprError::EventOutOfOrder { index: 0, t: 5, .. })
    ));
    assert!(err.to_string().contains("t=9"));
}

#[test]
fn events_outside_the_frame_are_rejected_with_their_coordinates() {
    let mut fx = extractor();
    let err = fx.push(&[ev(1, 3, 3), ev(2, 240, 7)]).unwrap_err();
    assert!(matches!(
        err,
        ReprError::EventOutOfFrame {
            index: 1,
            x: 240,
            y: 7,
            width: 240,
            ..
        }
    ));
    assert!(err.to_string().contains("x=240"), "{err}");
    // Uncropped sensor events go through `push_with_roi`, which drops what lies outside.
    let roi = Roi::centered(Resolution::new(640, 480), Resolution::new(240, 240)).unwrap();
    fx.push_with_roi(&[ev(1, 0, 0), ev(2, 320, 240)], &roi)
        .unwrap();
    assert_eq!(fx.pending(), 1);
    let small = Roi::centered(Resolution::new(640, 480), Resolution::new(8, 8)).unwrap();
    assert!(matches!(
        fx.push_with_roi(&[ev(3, 0, 0)], &small),
        Err(ReprError::RoiSize { roi_width: 8, .. })
    ));
}

#[test]
fn non_monotonic_sample_times_are_rejected_and_equal_ones_allowed() {
    let mut fx = extractor();
    fx.advance_to(100).unwrap();
    fx.advance_to(100).unwrap();
    assert_eq!(
        fx.advance_to(99),
        Err(ReprError::SampleTimeBackwards {
            t: 99,
            previous: 100
        })
    );
}

#[test]
fn empty_stream_and_samples_before_the_first_event_give_the_initial_state() {
    let mut fx = extractor();
    fx.advance_to(-5).unwrap();
    assert!(fx.features(0).iter().all(|&f| f == 0.0));
    fx.push(&[ev(1_000, 8, 8), ev(1_000, 8, 8), ev(1_000, 8, 8)])
        .unwrap();
    fx.advance_to(999).unwrap();
    assert!(fx.frame(0).iter().all(|&b| b == 0));
    assert_eq!(fx.pending(), 3);
    fx.advance_to(1_000).unwrap();
    assert_eq!(fx.frame(0)[8 * 240 + 8], 1);

    // A neutral potential above the threshold sets every pixel from the start (documented).
    let hot = StaticConfig {
        neutral_potential: 0.5,
        ..StaticConfig::default()
    };
    let fx =
        FeatureExtractor::new(&[ReprConfig::Static(hot)], Resolution::new(16, 16), None).unwrap();
    assert!(fx.features(0).iter().all(|&f| f == 1.0));
}

#[test]
fn bad_configs_frames_and_masks_are_rejected() {
    let res = Resolution::new(240, 240);
    assert_eq!(
        FeatureExtractor::new(&[], res, None).unwrap_err(),
        ReprError::NoConfig
    );
    assert!(matches!(
        FeatureExtractor::new(&[ReprConfig::default()], Resolution::new(250, 240), None),
        Err(ReprError::FrameNotPoolable { width: 250, .. })
    ));
    let bad = ReprConfig::Static(StaticConfig {
        tau_ms: -1.0,
        ..StaticConfig::default()
    });
    let err = FeatureExtractor::new(&[bad], res, None).unwrap_err();
    assert!(err.to_string().contains("tau_ms"), "{err}");
    let mask = Mask::empty(Resolution::new(8, 8));
    assert!(matches!(
        FeatureExtractor::new(&[ReprConfig::default()], res, Some(&mask)),
        Err(ReprError::MaskSize { mask_width: 8, .. })
    ));
    assert!(matches!(
        FeatureExtractor::new_with_masks(&[ReprConfig::default()], res, &[]),
        Err(ReprError::MaskCount {
            masks: 0,
            configs: 1
        })
    ));
}

#[test]
fn a_sample_before_a_prepared_time_is_an_error() {
    let mut fx =
        FeatureExtractor::new(&[ReprConfig::default()], Resolution::new(8, 8), None).unwrap();
    fx.push(&[Event {
        t: 5,
        x: 1,
        y: 1,
        polarity: true,
    }])
    .unwrap();
    fx.prepare(10).unwrap();
    // The event at 5 is applied already: a sample at 4 would include it.
    assert!(matches!(
        fx.advance_to(4),
        Err(ReprError::SampleTimeBackwards { t: 4, previous: 10 })
    ));
    assert!(fx.prepare(9).is_err());
    fx.advance_to(10).unwrap();
    assert_eq!(
        fx.frame(0)[9],
        1,
        "the event is in the window of the default combined config"
    );
}

#[test]
fn push_and_prepare_rejects_what_push_and_prepare_reject() {
    let mut fx = extractor();
    // A bad chunk: nothing queued or applied.
    assert!(matches!(
        fx.push_and_prepare(&[ev(10, 0, 0), ev(9, 0, 0)], 20),
        Err(ReprError::EventOutOfOrder { index: 1, .. })
    ));
    assert!(matches!(
        fx.push_and_prepare(&[ev(10, 240, 0)], 20),
        Err(ReprError::EventOutOfFrame {
            index: 0,
            x: 240,
            ..
        })
    ));
    assert_eq!(fx.pending(), 0);
    fx.push_and_prepare(&[ev(10, 3, 0), ev(30, 4, 0)], 20)
        .unwrap();
    assert_eq!(fx.pending(), 1, "the event after the prepared time waits");
    // A prepared time before the previous one: an error, and the chunk stays queued as `push`
    // then a failing `prepare` would leave it.
    assert!(matches!(
        fx.push_and_prepare(&[ev(40, 5, 0)], 15),
        Err(ReprError::SampleTimeBackwards {
            t: 15,
            previous: 20
        })
    ));
    assert_eq!(fx.pending(), 2);
    fx.advance_to(40).unwrap();
    let set: Vec<usize> = (0..240).filter(|&x| fx.frame(0)[x] == 1).collect();
    assert_eq!(set, [3, 4, 5]);
}
