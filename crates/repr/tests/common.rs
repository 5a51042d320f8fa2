//! Seeded random event streams shared by the tests.

use evtac_events::{Event, Resolution};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `n` events over `res` starting at `t0`, in time order, with gaps drawn from `0..=max_gap` us
/// (zero gaps give equal timestamps), a few hot pixels (so potentials build up) and mixed
/// polarity. Same seed, same stream.
pub fn random_stream(seed: u64, res: Resolution, n: usize, t0: i64, max_gap: i64) -> Vec<Event> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let hot: Vec<(u16, u16)> = (0..4)
        .map(|_| {
            (
                rng.random_range(0..res.width),
                rng.random_range(0..res.height),
            )
        })
        .collect();
    let mut t = t0;
    (0..n)
        .map(|_| {
            t += rng.random_range(0..=max_gap);
            let (x, y) = if rng.random_bool(0.3) {
                hot[rng.random_range(0..hot.len())]
            } else {
                (
                    rng.random_range(0..res.width),
                    rng.random_range(0..res.height),
                )
            };
            Event {
                t,
                x,
                y,
                polarity: rng.random_bool(0.6),
            }
        })
        .collect()
}

/// Random split points cutting `n` items into batches of any size (including empty ones).
pub fn random_batches(seed: u64, n: usize, batches: usize) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let mut cuts: Vec<usize> = (0..batches.saturating_sub(1))
        .map(|_| rng.random_range(0..=n))
        .collect();
    cuts.push(n);
    cuts.sort_unstable();
    cuts
}

/// Events as the Python references read them: N int64 times, N uint16 x, N uint16 y, N uint8
/// polarities, back to back.
pub fn encode(events: &[Event]) -> Vec<u8> {
    let mut out = Vec::with_capacity(events.len() * 13);
    out.extend(events.iter().flat_map(|e| e.t.to_le_bytes()));
    out.extend(events.iter().flat_map(|e| e.x.to_le_bytes()));
    out.extend(events.iter().flat_map(|e| e.y.to_le_bytes()));
    out.extend(events.iter().map(|e| u8::from(e.polarity)));
    out
}

/// 8x8 means, in float64, of each channel of a channel-major `res` frame.
pub fn pool_channels(frame: &[f64], res: Resolution) -> Vec<f64> {
    let (w, h) = (usize::from(res.width), usize::from(res.height));
    let mut out = Vec::new();
    for channel in frame.chunks(w * h) {
        for cy in 0..h / 8 {
            for cx in 0..w / 8 {
                let mut sum = 0.0;
                for y in cy * 8..cy * 8 + 8 {
                    for x in cx * 8..cx * 8 + 8 {
                        sum += channel[y * w + x];
                    }
                }
                out.push(sum / 64.0);
            }
        }
    }
    out
}
