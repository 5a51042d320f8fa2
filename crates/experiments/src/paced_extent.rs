//! How much the end-to-end replay at recorded pace ([`crate::paced_latency`]) replays: its
//! intervals and, per scale, its trials and stretch of motion. Its own file so that the cost
//! model of the stages ([`crate::stage`]), which sizes the replay before it runs, reads it without
//! importing the study (which reports its progress by stage).

use evtac_sim::Scale;

/// The intervals replayed, in ms: the paper's finest, and its coarsest (the same wall time,
/// little more CPU).
pub const INTERVALS_MS: [u32; 2] = [1, 10];

/// How much is replayed at a scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Extent {
    /// Test trials replayed (the fastest-moving ones).
    pub trials: usize,
    /// The longest stretch of each trial's motion replayed, from its onset, in ms.
    pub motion_ms: i64,
}

/// How much is replayed at `scale`: each (representation, interval, load) replays
/// `trials x motion_ms` of events on the wall clock, so at `small` 2 x 2 s for each of
/// 5 x 2 x 2 cells, about 80 s.
pub const fn extent(scale: Scale) -> Extent {
    match scale {
        Scale::Tiny => Extent {
            trials: 1,
            motion_ms: 500,
        },
        Scale::Small => Extent {
            trials: 2,
            motion_ms: 2000,
        },
        Scale::Paper => Extent {
            trials: 4,
            motion_ms: 2000,
        },
    }
}
