//! Chunk boundaries do not change what a filter keeps, nor what it counts as removed: a stream
//! cut anywhere gives the same events as the stream whole, and as the events one by one.

use evtac_filters::{Chain, Filter, FilterSpec};
use proptest::collection::vec;
use proptest::prelude::*;

use crate::common::{CAMERA_T0, SENSOR, assert_same_events, run_in_batches, stream};

/// Every filter, some at settings where their edge cases show, and chains.
const SPECS: [&[&str]; 12] = [
    &["background-activity=2ms"],
    &["background-activity=1us"],
    &["fast-decay"],
    &["fast-decay=3ms,3,2.5"],
    &["k-noise=1ms"],
    &["k-noise=20ms"],
    &["polarity=off"],
    &["region=10,5,30,20"],
    &["refractory=300us"],
    &["circle=31.5,20,15"],
    &["polarity=on", "background-activity=2ms"],
    &["k-noise=1ms", "refractory=100us", "circle=0,0,50"],
];

fn build(specs: &[&str]) -> Chain {
    let specs: Vec<FilterSpec> = specs.iter().map(|s| s.parse().unwrap()).collect();
    Chain::build(&specs, SENSOR).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn chunk_boundaries_do_not_change_the_output(
        seed in any::<u64>(),
        camera_clock in any::<bool>(),
        mut cuts in vec(0usize..=1500, 0..25),
    ) {
        let t0 = if camera_clock { CAMERA_T0 } else { 0 };
        let events = stream(seed, SENSOR, 1500, t0);
        cuts.push(events.len());
        cuts.sort_unstable();
        for specs in SPECS {
            let what = specs.join(" ");
            let mut whole = build(specs);
            let mut expected = Vec::new();
            whole.retain(&events, &mut expected);

            let mut chunked = build(specs);
            let kept = run_in_batches(&mut chunked, &events, &cuts);
            assert_same_events(&what, &kept, &expected);
            prop_assert_eq!(chunked.removed(), whole.removed(), "{}", what);
            prop_assert_eq!(whole.removed(), (events.len() - expected.len()) as u64);

            // Event by event through `keep`, each filter of the chain in turn.
            let mut single = build(specs);
            let one_by_one: Vec<_> = events.iter().filter(|e| single.keep(e)).copied().collect();
            assert_same_events(&what, &one_by_one, &expected);
            let counts = |c: &Chain| c.filters().iter().map(|f| f.removed()).collect::<Vec<_>>();
            prop_assert_eq!(counts(&single), counts(&whole), "{}", what);
            prop_assert_eq!(counts(&chunked), counts(&whole), "{}", what);
        }
    }
}
