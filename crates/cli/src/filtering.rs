//! `--filter SPEC`: the event filters (`evtac_filters`) flattened into every command that takes
//! them, so the flag, its help and the report of what each filter removed have one owner.
//! `evtac filter` streams a recording through them chunk by chunk; `evtac represent`, which
//! reads the whole recording into memory, filters it once read, with [`FilterArgs::apply`].
//! `hot-pixels=auto` learns the recording's hot pixels first, as `evtac stats` measures them:
//! from the events in memory, or with a pass over the file before a streaming one.

use std::path::Path;

use evtac_events::{Event, Resolution};
use evtac_filters::{Chain, FilterSpec};
use evtac_formats::StreamSelection;
pub use evtac_import::filtering::removed;
use evtac_import::filtering::{Learned, filter_events};

/// The filter flags.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct FilterArgs {
    /// A filter, applied in the order given (repeat the flag for a chain):
    /// `background-activity=DURATION`, `fast-decay=HALF_LIFE[,SUBDIVISION[,THRESHOLD]]`,
    /// `k-noise=DURATION`, `polarity=on|off`, `region=X,Y,W,H`, `refractory=DURATION`,
    /// `circle=CX,CY,R`, `mask=FILE` (keeps the pixels a uint8 H x W NPY or 8-bit greyscale
    /// PNG marks non-zero), `hot-pixels=FILE` (removes them), `hot-pixels=auto` (removes the
    /// hot pixels learned from the recording's stretches at rest, as `evtac stats` finds them).
    /// Durations take `us`, `ms` or `s`.
    #[arg(long = "filter", value_name = "SPEC")]
    pub filters: Vec<FilterSpec>,
}

impl FilterArgs {
    /// The chain of these filters for the streams `streams` picks of the recording at `path` on
    /// `sensor` (given, or the file's own), an error naming the recording and the SPEC that does
    /// not fit it. `hot-pixels=auto` reads the file once here to learn its hot pixels.
    pub fn chain(
        &self,
        path: &Path,
        streams: &StreamSelection,
        sensor: Resolution,
    ) -> anyhow::Result<Chain> {
        let learned = Learned::from_file(path, streams, Some(sensor), &self.filters)?;
        say_learned(path, &learned);
        Ok(learned.chain(path, sensor, &self.filters)?)
    }

    /// `events` of the recording at `path` through the filters (unchanged when there are none),
    /// printing on stderr what each removed; `hot-pixels=auto` learns from `events`.
    pub fn apply(
        &self,
        path: &Path,
        sensor: Resolution,
        events: Vec<Event>,
    ) -> anyhow::Result<Vec<Event>> {
        if self.filters.is_empty() {
            return Ok(events);
        }
        let (kept, chain, learned) = filter_events(path, sensor, &self.filters, events)?;
        say_learned(path, &learned);
        self.say_removed(&removed(&chain));
        Ok(kept)
    }

    /// Prints each filter's removed count ([`removed`]), in order, beside its SPEC on stderr.
    pub fn say_removed(&self, removed: &[(&'static str, u64)]) {
        for (spec, (name, count)) in self.filters.iter().zip(removed) {
            eprintln!("{spec}: removed {count} events ({name})");
        }
    }
}

/// Says how many hot pixels `hot-pixels=auto` learned from the recording at `path`, if it ran.
fn say_learned(path: &Path, learned: &Learned) {
    if let Some(n) = learned.hot_pixels() {
        eprintln!(
            "hot-pixels=auto: {n} hot pixels learned from {}",
            path.display()
        );
    }
}
