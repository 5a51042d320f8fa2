//! Seeded random event streams and batch cuts shared by the tests.

use evtac_events::{Event, Resolution};
use evtac_filters::Filter;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The small sensor of the random streams.
pub const SENSOR: Resolution = Resolution::new(64, 48);

/// A DVXplorer's clock: timestamps far from 0, where no filter's zero-initialised state matters.
pub const CAMERA_T0: i64 = 1_605_537_493_718_345;

/// `n` events on `sensor` from `t0`, in time order: lone events anywhere (noise, gaps up to a
/// few ms) between bursts of events within 2 pixels of a centre (edges and corners included)
/// and tens of microseconds apart, mostly of one polarity, so that the noise filters both keep
/// and remove. Gaps of 0 give equal timestamps. Same seed, same stream.
pub fn stream(seed: u64, sensor: Resolution, n: usize, t0: i64) -> Vec<Event> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut t = t0;
    let mut events = Vec::with_capacity(n);
    while events.len() < n {
        if rng.random_bool(0.3) {
            let (cx, cy) = (
                rng.random_range(0..sensor.width),
                rng.random_range(0..sensor.height),
            );
            let polarity = rng.random_bool(0.5);
            for _ in 0..rng.random_range(3..40) {
                t += rng.random_range(0..=60);
                let jitter = |c: u16, size: u16, rng: &mut ChaCha8Rng| {
                    (i32::from(c) + rng.random_range(-2..=2)).clamp(0, i32::from(size) - 1) as u16
                };
                events.push(Event {
                    t,
                    x: jitter(cx, sensor.width, &mut rng),
                    y: jitter(cy, sensor.height, &mut rng),
                    polarity: polarity ^ rng.random_bool(0.1),
                });
            }
        } else {
            t += rng.random_range(0..=3_000);
            events.push(Event {
                t,
                x: rng.random_range(0..sensor.width),
                y: rng.random_range(0..sensor.height),
                polarity: rng.random_bool(0.5),
            });
        }
    }
    events.truncate(n);
    events
}

/// Batch ends cutting `n` events into `batches` batches of any size (empty ones included),
/// the last end `n`.
pub fn random_cuts(seed: u64, n: usize, batches: usize) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let mut cuts: Vec<usize> = (1..batches).map(|_| rng.random_range(0..=n)).collect();
    cuts.push(n);
    cuts.sort_unstable();
    cuts
}

/// `filter`'s kept events over `events` fed in the batches ending at `cuts`.
pub fn run_in_batches(filter: &mut dyn Filter, events: &[Event], cuts: &[usize]) -> Vec<Event> {
    let mut kept = Vec::new();
    let mut start = 0;
    for &end in cuts {
        filter.retain(&events[start..end], &mut kept);
        start = end;
    }
    kept
}

/// Asserts two event lists are equal, naming the first difference and the events around it.
pub fn assert_same_events(what: &str, ours: &[Event], theirs: &[Event]) {
    if ours == theirs {
        return;
    }
    let first = ours
        .iter()
        .zip(theirs)
        .position(|(a, b)| a != b)
        .unwrap_or(ours.len().min(theirs.len()));
    let around = |v: &[Event]| v[first.saturating_sub(2)..(first + 3).min(v.len())].to_vec();
    panic!(
        "{what}: {} events kept here, {} by the reference; first difference at {first}:\n  \
         here:      {:?}\n  reference: {:?}",
        ours.len(),
        theirs.len(),
        around(ours),
        around(theirs)
    );
}
