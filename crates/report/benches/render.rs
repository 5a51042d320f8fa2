//! `evtac render`'s speed against real time: one second of a 300k events/s stream over the
//! 240x240 crop rendered at 30 fps with the default panels (events, static, dynamic, combined)
//! into a GIF, and into an MP4 when `ffmpeg` is on the PATH. Faster than real time when one
//! iteration takes under 1 s.
//!
//! `nice cargo bench -p evtac-report --bench render -- --warm-up-time 1 --measurement-time 5`

use criterion::Criterion;
use evtac_events::Event;
use evtac_report::render::{self, Output, Panel, Scene, Timing};
use evtac_repr::{DynamicConfig, ReprConfig, StaticConfig};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

const RATE_HZ: f64 = 300_000.0;
const DURATION_US: i64 = 1_000_000;

/// Events at `RATE_HZ` (uniform arrival times, seeded): 85 % in a disc of radius 60 that
/// circles the centre once a second, the rest uniform background.
fn stream() -> Vec<Event> {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let n = (RATE_HZ * DURATION_US as f64 / 1e6) as i64;
    (0..n)
        .map(|i| {
            let t = i * DURATION_US / n;
            let phase = t as f64 / 1e6 * std::f64::consts::TAU;
            let (x, y) = if rng.random_bool(0.85) {
                let (a, r) = (
                    rng.random::<f64>() * std::f64::consts::TAU,
                    rng.random::<f64>() * 60.0,
                );
                (
                    120.0 + 40.0 * phase.cos() + r * a.cos(),
                    120.0 + 40.0 * phase.sin() + r * a.sin(),
                )
            } else {
                (rng.random::<f64>() * 240.0, rng.random::<f64>() * 240.0)
            };
            Event {
                t,
                x: x.clamp(0.0, 239.0) as u16,
                y: y.clamp(0.0, 239.0) as u16,
                polarity: rng.random_bool(0.5),
            }
        })
        .collect()
}

fn main() {
    let events = stream();
    let reprs = evtac_experiments::exp1::paper_representations(
        ReprConfig::Static(StaticConfig::default()),
        ReprConfig::Dynamic(DynamicConfig::default()),
    );
    let dir = tempfile::tempdir().expect("a temporary folder");
    let Ok(timing) = Timing::new(&events, Some(0), Some(DURATION_US), 30.0, 1.0) else {
        eprintln!("the synthetic stream is empty");
        return;
    };
    let ffmpeg = std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ffmpeg {
        eprintln!("no ffmpeg on the PATH: the MP4 case is skipped");
    }
    let mut c = Criterion::default().sample_size(10).configure_from_args();
    for (output, name) in [(Output::Gif, "GIF"), (Output::Mp4, "MP4")] {
        if output == Output::Mp4 && !ffmpeg {
            continue;
        }
        let out = dir.path().join(format!("bench.{}", name.to_lowercase()));
        c.bench_function(
            &format!("render 1 s of 300k ev/s, 30 fps, 4 panels, {name}"),
            |b| {
                b.iter(|| {
                    let scene = Scene::new(&Panel::DEFAULT, timing, None)?;
                    render::render(&out, output, &events, &reprs, &[None, None, None], scene)
                })
            },
        );
        if let Ok(meta) = std::fs::metadata(&out) {
            eprintln!("{name} of {} frames: {} bytes", timing.count, meta.len());
        }
    }
    c.final_summary();
}
