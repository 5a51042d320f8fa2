//! The benches' synthetic NeuroTac-like stream (seeded), shared by `represent.rs` and
//! `dense.rs` so that both kinds of representation are timed on the same events.

use evtac_events::{Event, Resolution};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const FRAME: Resolution = Resolution::new(240, 240);
pub const RATE_HZ: f64 = 300_000.0;
pub const DURATION_US: i64 = 3_000_000;
pub const STEP_US: i64 = 1_000;
pub const T0: i64 = 1_000_000;

/// A NeuroTac-like stream: a 14 x 14 grid of pins, those under a slowly moving contact region
/// emit events around their edges (85 % of events), plus uniform background noise; Poisson
/// arrivals at `RATE_HZ`, integer-microsecond timestamps (so many share a timestamp).
pub fn synthetic_stream(seed: u64) -> Vec<Event> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let pins: Vec<(f64, f64)> = (0..14)
        .flat_map(|i| {
            (0..14).map(move |j| (10.0 + 17.0 * f64::from(i), 10.0 + 17.0 * f64::from(j)))
        })
        .collect();
    let mut events = Vec::with_capacity((RATE_HZ * DURATION_US as f64 / 1e6 * 1.05) as usize);
    let mut t = T0 as f64;
    let end = (T0 + DURATION_US) as f64;
    let mut active = Vec::with_capacity(pins.len());
    let mut active_at = i64::MIN;
    loop {
        t += -(1.0 - rng.random::<f64>()).ln() * 1e6 / RATE_HZ;
        if t >= end {
            break;
        }
        let ti = t as i64;
        // The contact region circles around the centre once per 2 s.
        if ti - active_at >= 1_000 {
            active_at = ti;
            let phase = (ti - T0) as f64 / 2e6 * std::f64::consts::TAU;
            let (cx, cy) = (120.0 + 40.0 * phase.cos(), 120.0 + 40.0 * phase.sin());
            active.clear();
            active.extend(
                pins.iter()
                    .filter(|(px, py)| (px - cx).hypot(py - cy) < 70.0)
                    .copied(),
            );
        }
        let (x, y) = if rng.random_bool(0.85) && !active.is_empty() {
            let (px, py) = active[rng.random_range(0..active.len())];
            let angle = rng.random::<f64>() * std::f64::consts::TAU;
            let r = 3.0 + rng.random::<f64>() * 1.5;
            (px + r * angle.cos(), py + r * angle.sin())
        } else {
            (rng.random::<f64>() * 240.0, rng.random::<f64>() * 240.0)
        };
        events.push(Event {
            t: ti,
            x: (x.clamp(0.0, 239.0)) as u16,
            y: (y.clamp(0.0, 239.0)) as u16,
            polarity: rng.random_bool(0.5),
        });
    }
    events
}

/// Sample times every `STEP_US` over the stream.
pub fn samples() -> Vec<i64> {
    (1..=DURATION_US / STEP_US)
        .map(|k| T0 + k * STEP_US)
        .collect()
}

/// Runs the Python reference `script` (a file under `benches/`) with `python` on `events`
/// (written as N int64 times, N uint16 x, N uint16 y, N uint8 polarities) and the stream's
/// layout (`N WIDTH HEIGHT T0_US STEP_US SAMPLES`); its standard output, or `None` (said) when
/// it fails.
pub fn run_reference(
    python: &std::path::Path,
    script: &str,
    events: &[Event],
    samples: &[i64],
) -> Option<String> {
    let dir = tempfile::tempdir().ok()?;
    let path = dir.path().join("events.bin");
    let mut bytes = Vec::with_capacity(events.len() * 13);
    bytes.extend(events.iter().flat_map(|e| e.t.to_le_bytes()));
    bytes.extend(events.iter().flat_map(|e| e.x.to_le_bytes()));
    bytes.extend(events.iter().flat_map(|e| e.y.to_le_bytes()));
    bytes.extend(events.iter().map(|e| u8::from(e.polarity)));
    std::fs::write(&path, bytes).ok()?;
    let out = std::process::Command::new(python)
        .arg(script)
        .arg(&path)
        .args(
            [
                events.len() as i64,
                i64::from(FRAME.width),
                i64::from(FRAME.height),
                T0,
                STEP_US,
                samples.len() as i64,
            ]
            .map(|v| v.to_string()),
        )
        .output()
        .ok()?;
    if !out.status.success() {
        eprintln!("{script} failed:\n{}", String::from_utf8_lossy(&out.stderr));
        return None;
    }
    Some(String::from_utf8_lossy(&out.stdout).into_owned())
}
