//! Event filters, streaming, as dv-processing 2.0.4 has them.
//!
//! Each filter decides event by event whether to keep it, from per-pixel (or per-row and
//! per-column) state sized by the sensor, so a stream can be filtered one chunk at a time in
//! bounded memory and the output does not depend on where the chunks were cut. Each counts the
//! events it removed.
//!
//! | SPEC | filter | dv-processing |
//! | --- | --- | --- |
//! | `background-activity=DURATION` | [`BackgroundActivity`] | `dv.noise.BackgroundActivityNoiseFilter` |
//! | `fast-decay=HALF_LIFE[,SUBDIVISION[,THRESHOLD]]` | [`FastDecay`] | `dv.noise.FastDecayNoiseFilter` |
//! | `k-noise=DURATION` | [`KNoise`] | `dv.noise.KNoiseFilter` |
//! | `polarity=on\|off` | [`PolarityFilter`] | `dv.EventPolarityFilter` |
//! | `region=X,Y,W,H` | [`Region`] | `dv.EventRegionFilter` |
//! | `refractory=DURATION` | [`Refractory`] | C++ `dv::RefractoryPeriodFilter` (not in the Python bindings) |
//! | `circle=CX,CY,R` | [`Circle`] | none |
//! | `mask=FILE` | [`Mask`] | `dv.EventMaskFilter` |
//! | `hot-pixels=FILE` | [`HotPixels`] | none (`dv.EventMaskFilter` with the mask inverted) |
//! | `hot-pixels=auto` | [`HotPixels`], of the hot pixels learned from the recording | none |
//!
//! A [`FilterSpec`] is parsed from a SPEC and built for a sensor; a [`Chain`] applies several in
//! order, as `dv.EventFilterChain` does.
//!
//! ```
//! use evtac_events::{Event, Resolution};
//! use evtac_filters::{Chain, Filter, FilterSpec};
//!
//! let specs: Vec<FilterSpec> = ["polarity=on", "background-activity=2ms"]
//!     .iter()
//!     .map(|s| s.parse())
//!     .collect::<Result<_, _>>()?;
//! let mut chain = Chain::build(&specs, Resolution::new(64, 48))?;
//!
//! let e = |t, x, y, polarity| Event { t, x, y, polarity };
//! let events = [
//!     e(10_000, 5, 5, true),  // no neighbour yet: noise
//!     e(10_500, 6, 5, true),  // a neighbour 500 us before: kept
//!     e(10_600, 7, 5, false), // OFF: removed by the first filter
//!     e(20_000, 30, 30, true), // alone: noise
//! ];
//! let mut kept = Vec::new();
//! chain.retain(&events, &mut kept);
//! assert_eq!(kept, [e(10_500, 6, 5, true)]);
//! assert_eq!(chain.removed(), 3);
//! # Ok::<(), evtac_filters::Error>(())
//! ```

mod background_activity;
mod chain;
mod circle;
mod counted;
mod duration;
mod fast_decay;
mod hot_pixels;
mod k_noise;
mod mask;
pub mod mask_file;
mod polarity;
mod refractory;
mod region;
pub mod spec;
mod surface;

pub use background_activity::BackgroundActivity;
pub use chain::Chain;
pub use circle::Circle;
pub use counted::{Counted, Rule};
pub use duration::{Micros, ParseDurationError};
pub use fast_decay::FastDecay;
pub use hot_pixels::HotPixels;
pub use k_noise::KNoise;
pub use mask::Mask;
pub use polarity::PolarityFilter;
pub use refractory::Refractory;
pub use region::Region;
pub use spec::{Error, FilterSpec};

use evtac_events::Event;

/// One event filter: keeps or removes each event in stream order, from its own state.
///
/// Feeding a stream in chunks of any size gives the same events as feeding it whole: the state
/// carries over from one call to the next, and nothing is held back.
pub trait Filter: Send {
    /// The filter's name on the command line (`background-activity`, `k-noise`, ...).
    fn name(&self) -> &'static str;

    /// Whether to keep `event`, which comes after every event seen before; updates the state
    /// (and the count of removed events).
    fn keep(&mut self, event: &Event) -> bool;

    /// Events removed so far.
    fn removed(&self) -> u64;

    /// Appends the kept events of `events` to `out`, in order (`out` is not cleared, so a caller
    /// can collect a whole stream chunk by chunk).
    fn retain(&mut self, events: &[Event], out: &mut Vec<Event>) {
        out.reserve(events.len());
        for event in events {
            if self.keep(event) {
                out.push(*event);
            }
        }
    }
}

impl<F: Filter + ?Sized> Filter for Box<F> {
    fn name(&self) -> &'static str {
        (**self).name()
    }

    fn keep(&mut self, event: &Event) -> bool {
        (**self).keep(event)
    }

    fn removed(&self) -> u64 {
        (**self).removed()
    }

    fn retain(&mut self, events: &[Event], out: &mut Vec<Event>) {
        // The boxed filter's own loop, compiled for its type, not one virtual call per event.
        (**self).retain(events, out)
    }
}
