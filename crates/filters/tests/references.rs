//! The two filters dv-processing's Python bindings do not have, against references written
//! here another way: the refractory period by searching back for each event's previous event at
//! its pixel (no per-pixel state), the disc in integers on coordinates counted in quarters.

use evtac_events::Event;
use evtac_filters::{Filter, FilterSpec};
use proptest::prelude::*;

use crate::common::{CAMERA_T0, SENSOR, assert_same_events, random_cuts, run_in_batches, stream};

/// dv-processing's `RefractoryPeriodFilter` rule, from scratch: kept when the previous event at
/// the pixel (or the time 0 a pixel starts from) is at least `period` before.
fn refractory_reference(events: &[Event], period: i64) -> Vec<Event> {
    (0..events.len())
        .filter(|&i| {
            let e = events[i];
            let previous = events[..i]
                .iter()
                .rev()
                .find(|p| (p.x, p.y) == (e.x, e.y))
                .map_or(0, |p| p.t);
            e.t - previous >= period
        })
        .map(|i| events[i])
        .collect()
}

/// The disc, in integers: `(4x - 4cx)^2 + (4y - 4cy)^2 <= (4r)^2`.
fn circle_reference(events: &[Event], cx4: i64, cy4: i64, r4: i64) -> Vec<Event> {
    events
        .iter()
        .filter(|e| {
            let dx = 4 * i64::from(e.x) - cx4;
            let dy = 4 * i64::from(e.y) - cy4;
            dx * dx + dy * dy <= r4 * r4
        })
        .copied()
        .collect()
}

fn run(spec: &str, events: &[Event], cuts: &[usize]) -> (Vec<Event>, u64) {
    let spec: FilterSpec = spec.parse().unwrap();
    let mut filter = spec.build(SENSOR).unwrap();
    let kept = run_in_batches(&mut filter, events, cuts);
    (kept, filter.removed())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn refractory_matches_its_reference(
        seed in any::<u64>(),
        camera_clock in any::<bool>(),
        period in 1i64..5_000,
        batches in 1usize..20,
    ) {
        let t0 = if camera_clock { CAMERA_T0 } else { 0 };
        let events = stream(seed, SENSOR, 800, t0);
        let cuts = random_cuts(seed, events.len(), batches);
        let (kept, removed) = run(&format!("refractory={period}us"), &events, &cuts);
        let expected = refractory_reference(&events, period);
        assert_same_events("refractory", &kept, &expected);
        prop_assert_eq!(removed, (events.len() - expected.len()) as u64);
    }

    #[test]
    fn circle_matches_its_reference(
        seed in any::<u64>(),
        cx4 in 0i64..=4 * 63,
        cy4 in 0i64..=4 * 47,
        r4 in 1i64..=4 * 80,
        batches in 1usize..20,
    ) {
        let events = stream(seed, SENSOR, 800, CAMERA_T0);
        let spec = format!("circle={},{},{}", cx4 as f64 / 4.0, cy4 as f64 / 4.0, r4 as f64 / 4.0);
        let (kept, removed) = run(&spec, &events, &random_cuts(seed, events.len(), batches));
        let expected = circle_reference(&events, cx4, cy4, r4);
        assert_same_events(&spec, &kept, &expected);
        prop_assert_eq!(removed, (events.len() - expected.len()) as u64);
    }
}

#[test]
fn the_references_see_both_outcomes() {
    // Guards the properties above against streams where every event is kept (or none is).
    let events = stream(7, SENSOR, 2_000, CAMERA_T0);
    let kept = refractory_reference(&events, 300).len();
    assert!(
        0 < kept && kept < events.len(),
        "{kept} of {}",
        events.len()
    );
    let kept = circle_reference(&events, 4 * 30, 4 * 20, 4 * 12).len();
    assert!(
        0 < kept && kept < events.len(),
        "{kept} of {}",
        events.len()
    );
    // Starting at t = 0, a pixel's first event before the period is removed, as in the C++.
    let early = [Event {
        t: 50,
        x: 1,
        y: 1,
        polarity: true,
    }];
    assert!(refractory_reference(&early, 100).is_empty());
    assert!(run("refractory=100us", &early, &[1]).0.is_empty());
}
