//! Several filters applied in order, as dv-processing's `dv::EventFilterChain`: an event a
//! filter removes is not seen by the ones after it.

use evtac_events::{Event, Resolution};

use crate::{Error, Filter, FilterSpec};

/// Filters applied one after the other; its own count is of the events the whole chain removed
/// (each filter's is in [`Chain::filters`]).
pub struct Chain {
    filters: Vec<Box<dyn Filter>>,
    // Two buffers between the filters, reused chunk after chunk (bounded by the chunk size).
    scratch: [Vec<Event>; 2],
    removed: u64,
}

impl Chain {
    /// The chain of `filters`, first to last. No filters keep every event.
    pub fn new(filters: Vec<Box<dyn Filter>>) -> Self {
        Self {
            filters,
            scratch: [Vec::new(), Vec::new()],
            removed: 0,
        }
    }

    /// The chain of `specs` built for `sensor`, or the first spec's error.
    pub fn build(specs: &[FilterSpec], sensor: Resolution) -> Result<Self, Error> {
        Self::build_with(specs, sensor, None)
    }

    /// [`Self::build`], with the hot pixels learned from the recording to be filtered for
    /// `hot-pixels=auto` ([`FilterSpec::build_with`]).
    pub fn build_with(
        specs: &[FilterSpec],
        sensor: Resolution,
        hot_pixels: Option<&[(u16, u16)]>,
    ) -> Result<Self, Error> {
        let filters = specs
            .iter()
            .map(|spec| spec.build_with(sensor, hot_pixels))
            .collect::<Result<_, _>>()?;
        Ok(Self::new(filters))
    }

    /// The filters, first to last, each with its own count of removed events.
    pub fn filters(&self) -> &[Box<dyn Filter>] {
        &self.filters
    }

    /// Whether the chain has no filter (and so keeps everything).
    pub fn is_empty(&self) -> bool {
        self.filters.is_empty()
    }
}

impl std::fmt::Debug for Chain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Chain")
            .field(
                "filters",
                &self.filters.iter().map(|f| f.name()).collect::<Vec<_>>(),
            )
            .field("removed", &self.removed)
            .finish()
    }
}

impl Filter for Chain {
    fn name(&self) -> &'static str {
        "chain"
    }

    fn keep(&mut self, event: &Event) -> bool {
        // Short-circuits: the filters after one that removes the event never see it.
        let keep = self.filters.iter_mut().all(|f| f.keep(event));
        self.removed += u64::from(!keep);
        keep
    }

    fn removed(&self) -> u64 {
        self.removed
    }

    fn retain(&mut self, events: &[Event], out: &mut Vec<Event>) {
        // Filter by filter over the whole chunk, each in its own loop: the same events as
        // `keep` event by event, with one virtual call per filter rather than per event.
        let before = out.len();
        let [a, b] = &mut self.scratch;
        match self.filters.as_mut_slice() {
            [] => out.extend_from_slice(events),
            [only] => only.retain(events, out),
            [first, middle @ .., last] => {
                a.clear();
                first.retain(events, a);
                for filter in middle {
                    b.clear();
                    filter.retain(a, b);
                    std::mem::swap(a, b);
                }
                last.retain(a, out);
            }
        }
        self.removed += (events.len() - (out.len() - before)) as u64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rule;
    use crate::{PolarityFilter, Region};

    #[test]
    fn chunks_and_single_events_agree_and_counts_add_up() {
        let events: Vec<Event> = (0..40)
            .map(|i| Event {
                t: i,
                x: (i % 7) as u16,
                y: (i % 5) as u16,
                polarity: i % 3 != 0,
            })
            .collect();
        let make = || {
            Chain::new(vec![
                Box::new(PolarityFilter::new(true).counted()),
                Box::new(Region::new(1, 1, 4, 3).counted()),
                Box::new(Region::new(0, 0, 4, 10).counted()),
            ])
        };
        let mut whole = make();
        let mut kept = Vec::new();
        whole.retain(&events, &mut kept);
        let mut single = make();
        let one_by_one: Vec<Event> = events.iter().filter(|e| single.keep(e)).copied().collect();
        assert_eq!(kept, one_by_one);
        assert!(!kept.is_empty() && kept.len() < events.len());
        assert_eq!(whole.removed(), (events.len() - kept.len()) as u64);
        assert_eq!(single.removed(), whole.removed());
        let per_filter: u64 = whole.filters().iter().map(|f| f.removed()).sum();
        assert_eq!(per_filter, whole.removed());
        assert_eq!(
            whole
                .filters()
                .iter()
                .map(|f| f.removed())
                .collect::<Vec<_>>(),
            single
                .filters()
                .iter()
                .map(|f| f.removed())
                .collect::<Vec<_>>()
        );
    }

    #[test]
    fn an_empty_chain_keeps_everything() {
        let mut chain = Chain::new(Vec::new());
        let events = [Event::default(); 3];
        let mut kept = vec![Event::default()];
        chain.retain(&events, &mut kept);
        assert_eq!(kept.len(), 4);
        assert_eq!(chain.removed(), 0);
        assert!(chain.is_empty());
    }
}
