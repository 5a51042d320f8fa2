//! `--filter SPEC`: the event filters (`evtac_filters`) flattened into every command that takes
//! them, so the flag, its help and the report of what each filter removed have one owner.
//! `evtac filter` streams a recording through them chunk by chunk; `evtac represent`, which
//! reads the whole recording into memory, filters it once read, with [`FilterArgs::apply`].

use std::path::Path;

use anyhow::Context;
use evtac_events::{Event, Resolution};
use evtac_filters::{Chain, Filter, FilterSpec};

/// The filter flags.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct FilterArgs {
    /// A filter, applied in the order given (repeat the flag for a chain):
    /// `background-activity=DURATION`, `fast-decay=HALF_LIFE[,SUBDIVISION[,THRESHOLD]]`,
    /// `k-noise=DURATION`, `polarity=on|off`, `region=X,Y,W,H`, `refractory=DURATION`,
    /// `circle=CX,CY,R`, `mask=FILE` (keeps the pixels a uint8 H x W NPY or 8-bit greyscale
    /// PNG marks non-zero), `hot-pixels=FILE` (removes them). Durations take `us`, `ms` or `s`.
    #[arg(long = "filter", value_name = "SPEC")]
    pub filters: Vec<FilterSpec>,
}

impl FilterArgs {
    /// The chain of these filters for `sensor`, an error naming the recording at `path` and
    /// the SPEC that does not fit it.
    pub fn chain(&self, path: &Path, sensor: Resolution) -> anyhow::Result<Chain> {
        Chain::build(&self.filters, sensor)
            .with_context(|| format!("{}: the {sensor} sensor", path.display()))
    }

    /// `events` of the recording at `path` through the filters (unchanged when there are none),
    /// printing on stderr what each removed.
    pub fn apply(
        &self,
        path: &Path,
        sensor: Resolution,
        events: Vec<Event>,
    ) -> anyhow::Result<Vec<Event>> {
        if self.filters.is_empty() {
            return Ok(events);
        }
        let mut chain = self.chain(path, sensor)?;
        let mut kept = Vec::with_capacity(events.len());
        chain.retain(&events, &mut kept);
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

/// Each filter of `chain`, first to last: its name and the events it removed.
pub fn removed(chain: &Chain) -> Vec<(&'static str, u64)> {
    chain
        .filters()
        .iter()
        .map(|f| (f.name(), f.removed()))
        .collect()
}
