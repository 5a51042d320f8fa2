//! `polarity=on|off`: dv-processing's `dv::EventPolarityFilter`
//! (`include/dv-processing/core/filters.hpp`): keeps the events of one polarity, ON (`true`) or
//! OFF.

use evtac_events::Event;

use crate::Filter;

/// Keeps the events of one polarity.
#[derive(Debug, Clone)]
pub struct PolarityFilter {
    polarity: bool,
    removed: u64,
}

impl PolarityFilter {
    /// Keeps ON events when `polarity` is `true`, OFF events otherwise.
    pub fn new(polarity: bool) -> Self {
        Self {
            polarity,
            removed: 0,
        }
    }
}

impl Filter for PolarityFilter {
    fn name(&self) -> &'static str {
        "polarity"
    }

    fn keep(&mut self, event: &Event) -> bool {
        let keep = event.polarity == self.polarity;
        self.removed += u64::from(!keep);
        keep
    }

    fn removed(&self) -> u64 {
        self.removed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_one_polarity_and_counts_the_other() {
        let e = |polarity| Event {
            t: 0,
            x: 0,
            y: 0,
            polarity,
        };
        let events = [e(true), e(false), e(false), e(true)];
        let mut on = PolarityFilter::new(true);
        let mut kept = Vec::new();
        on.retain(&events, &mut kept);
        assert_eq!(kept, [e(true), e(true)]);
        assert_eq!(on.removed(), 2);
        let mut off = PolarityFilter::new(false);
        kept.clear();
        off.retain(&events, &mut kept);
        assert_eq!(kept, [e(false), e(false)]);
    }
}
