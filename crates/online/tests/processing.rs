//! Processing time: each estimate is charged the estimator's own work since the previous one,
//! once, and never the time spent outside it (handing estimates over, waiting for chunks).

use crate::support::{self, SENSOR, Synthetic};
use evtac_learn::Model;
use evtac_online::Estimator;
use std::time::{Duration, Instant};

#[test]
fn processing_time_excludes_handing_over_and_counts_each_moment_once() {
    let dir = tempfile::tempdir().unwrap();
    let (_, combined) = support::representations()[2];
    support::seeded_bundle(dir.path(), 5, &combined, None);
    let model = Model::load(dir.path()).unwrap();
    // 40 ms of events in 250 us packets: four chunks per estimate, so work is carried from
    // chunks that make no estimate to the one that does.
    let events = Synthetic::new(3, 300_000.0, 250, 40_000).collect();
    let mut estimator = Estimator::for_model(&model, SENSOR, 1000).unwrap();
    estimator.start_grid_at(1000);
    // Handing an estimate over takes (at least) this long; none of it is processing.
    let hand_over = Duration::from_millis(2);
    let mut processing = Vec::new();
    let started = Instant::now();
    let mut emit = |e: &evtac_online::Estimate| {
        processing.push(e.processing);
        std::thread::sleep(hand_over);
    };
    let mut cursor = 0;
    for t1 in (250..=40_000).step_by(250) {
        let end = cursor + events[cursor..].partition_point(|e| e.t < t1);
        estimator
            .process(
                &events[cursor..end],
                Some(t1 - 1),
                Instant::now(),
                &mut emit,
            )
            .unwrap();
        cursor = end;
        // Time between chunks, as a live stream has: not processing either.
        std::thread::sleep(Duration::from_micros(200));
    }
    let wall = started.elapsed();
    let n = processing.len() as u32;
    assert_eq!(n, 39, "one estimate per millisecond from 1 ms to 39 ms");
    assert_eq!(estimator.processing_stats().count(), u64::from(n));
    assert!(processing.iter().all(|p| !p.is_zero()));
    // The processing times, the hand-overs and the gaps are disjoint stretches of the run.
    let total: Duration = processing.iter().sum();
    let gaps = Duration::from_micros(200) * 160;
    assert!(
        total + hand_over * n + gaps <= wall,
        "processing {total:?} + hand-overs + gaps exceed the run's {wall:?}"
    );
}
