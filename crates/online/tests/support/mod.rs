//! Shared by the integration tests and the benchmark: a seeded model bundle and a synthetic
//! event stream of a chosen rate.

#![allow(dead_code)]

pub mod dds;

use evtac_events::{Event, Resolution};
use evtac_learn::{Model, ModelBundle, Representation};
use evtac_online::input::{ChunkInfo, EventSource, MemorySource, Next};
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::{Estimate, Estimator, Notice};
use evtac_repr::{DynamicConfig, Mask, ReprConfig, StaticConfig};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::ops::ControlFlow;
use std::path::Path;

/// The simulated sensor (DVXplorer).
pub const SENSOR: Resolution = Resolution::new(640, 480);

/// The paper's three representations with its settings, then the two learned fusions of the
/// same parts (stacked, late: 1800 features, their own networks).
pub fn representations() -> [(&'static str, ReprConfig); 5] {
    let (static_part, dynamic_part) = (StaticConfig::default(), DynamicConfig::default());
    [
        ("static", ReprConfig::Static(static_part)),
        ("dynamic", ReprConfig::Dynamic(dynamic_part)),
        ("combined", ReprConfig::default()),
        (
            "stacked",
            ReprConfig::Stacked {
                static_part,
                dynamic_part,
            },
        ),
        (
            "late",
            ReprConfig::Late {
                static_part,
                dynamic_part,
            },
        ),
    ]
}

/// The kinds the paper did not choose, at their default settings (time surface tau 100 ms,
/// continuous; histogram over 640 ms; voxel grid of 5 bins over 640 ms).
pub fn beyond_representations() -> [(&'static str, ReprConfig); 3] {
    evtac_repr::ReprKind::BEYOND.map(|kind| {
        (
            kind.name(),
            kind.config(Default::default(), Default::default()),
        )
    })
}

/// A model bundle with weights initialised from `seed` (untrained: the tests compare online and
/// offline predictions, which needs varied outputs, not accurate ones), saved in `dir`.
pub fn seeded_bundle(dir: &Path, seed: u64, repr: &ReprConfig, mask: Option<Mask>) {
    ModelBundle::untrained(seed, Representation::new(*repr), mask)
        .save(dir)
        .expect("the bundle is saved");
}

/// The estimates of `events` replayed from memory in chunks of `chunk_len` events: what a live,
/// interrupted or reconnected run over the same events must give.
pub fn replayed(model: &Model, events: &[Event], chunk_len: usize) -> Vec<Estimate> {
    estimates_of(
        MemorySource::new(events.to_vec(), chunk_len),
        Estimator::for_model(model, SENSOR, 1000).unwrap(),
    )
}

/// Every estimate `estimator` makes from `source` through the pipeline.
pub fn estimates_of<S: EventSource + 'static>(source: S, estimator: Estimator) -> Vec<Estimate> {
    let mut estimates = Vec::new();
    pipeline::run(source, estimator, &PipelineConfig::default(), |out| {
        if let Output::Estimate(e) = out {
            estimates.push(e);
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    estimates
}

/// Asserts that two runs made the same estimates: the same times and the same values, bit for
/// bit (latencies differ).
pub fn assert_same_estimates(a: &[Estimate], b: &[Estimate]) {
    assert_eq!(a.len(), b.len(), "number of estimates");
    for (x, y) in a.iter().zip(b) {
        assert_eq!(
            (x.t_us, x.pitch_deg.to_bits(), x.roll_deg.to_bits()),
            (y.t_us, y.pitch_deg.to_bits(), y.roll_deg.to_bits())
        );
    }
}

/// An endless, seeded stream of events at `rate` events per second of event time, shaped like
/// a pressed NeuroTac: pins (dots on a hexagon-like grid within the centered crop) that fire
/// while a contact patch sweeps across them, plus uniform background noise. Handed out in
/// packets of `packet_us` microseconds of event time.
pub struct Synthetic {
    rng: ChaCha8Rng,
    pins: Vec<(u16, u16)>,
    rate: f64,
    packet_us: i64,
    t: i64,
    end_us: i64,
}

impl Synthetic {
    /// `duration_us` of events from time 0.
    pub fn new(seed: u64, rate: f64, packet_us: i64, duration_us: i64) -> Self {
        let mut pins = Vec::new();
        for row in 0..14u16 {
            for col in 0..14u16 {
                let x = 200 + 8 + col * 16 + (row % 2) * 8;
                let y = 120 + 8 + row * 16;
                if x < 440 && y < 360 {
                    pins.push((x, y));
                }
            }
        }
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
            pins,
            rate,
            packet_us: packet_us.max(1),
            t: 0,
            end_us: duration_us,
        }
    }

    /// Appends the events of `[t0, t1)` to `out`, in time order.
    pub fn fill(&mut self, t0: i64, t1: i64, out: &mut Vec<Event>) {
        let span = (t1 - t0) as f64;
        let n = (self.rate * span * 1e-6).round() as usize;
        let start = out.len();
        // Contact patch centre sweeps in a circle with a 2 s period.
        let phase = (t0 as f64) * 1e-6 * std::f64::consts::PI;
        let (cx, cy) = (320.0 + 60.0 * phase.cos(), 240.0 + 60.0 * phase.sin());
        for _ in 0..n {
            let t = t0 + self.rng.random_range(0..(t1 - t0).max(1));
            let (x, y) = if self.rng.random::<f32>() < 0.9 {
                let (px, py) = self.pins[self.rng.random_range(0..self.pins.len())];
                let near = ((f64::from(px) - cx).powi(2) + (f64::from(py) - cy).powi(2)).sqrt();
                if near > 90.0 && self.rng.random::<f32>() < 0.8 {
                    // Pins far from the contact fire rarely: move the event to the patch.
                    (
                        (cx as u16).wrapping_add(self.rng.random_range(0..16)),
                        (cy as u16).wrapping_add(self.rng.random_range(0..16)),
                    )
                } else {
                    (
                        px + self.rng.random_range(0..3),
                        py + self.rng.random_range(0..3),
                    )
                }
            } else {
                (
                    self.rng.random_range(0..SENSOR.width),
                    self.rng.random_range(0..SENSOR.height),
                )
            };
            out.push(Event {
                t,
                x: x.min(SENSOR.width - 1),
                y: y.min(SENSOR.height - 1),
                polarity: self.rng.random(),
            });
        }
        out[start..].sort_unstable_by_key(|e| e.t);
    }

    /// All events of the stream at once.
    pub fn collect(mut self) -> Vec<Event> {
        let mut out = Vec::new();
        let mut t = 0;
        while t < self.end_us {
            let t1 = (t + self.packet_us).min(self.end_us);
            self.fill(t, t1, &mut out);
            t = t1;
        }
        out
    }
}

impl EventSource for Synthetic {
    fn next_chunk(&mut self, out: &mut Vec<Event>, _notify: &mut dyn FnMut(Notice)) -> Next {
        out.clear();
        if self.t >= self.end_us {
            return Ok(None);
        }
        let t1 = (self.t + self.packet_us).min(self.end_us);
        self.fill(self.t, t1, out);
        self.t = t1;
        Ok(Some(ChunkInfo::default()))
    }
}

/// Runs `source` through the pipeline with the default settings until it ends: each estimate
/// goes to `on_estimate`, each notice into `notices`.
pub fn run_to_end(
    source: Box<dyn evtac_online::input::EventSource>,
    estimator: Estimator,
    notices: &mut Vec<Notice>,
    mut on_estimate: impl FnMut(Estimate),
) -> evtac_online::Summary {
    pipeline::run(source, estimator, &PipelineConfig::default(), |out| {
        match out {
            Output::Estimate(e) => on_estimate(e),
            Output::Notice(n) => notices.push(n),
            Output::Frames(_) => {}
        }
        ControlFlow::Continue(())
    })
    .unwrap()
}
