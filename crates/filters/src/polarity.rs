//! `polarity=on|off`: dv-processing's `dv::EventPolarityFilter`
//! (`include/dv-processing/core/filters.hpp`): keeps the events of one polarity, ON (`true`) or
//! OFF.

use evtac_events::Event;

use crate::Rule;

/// Keeps the events of one polarity.
#[derive(Debug, Clone)]
pub struct PolarityFilter {
    polarity: bool,
}

impl PolarityFilter {
    /// Keeps ON events when `polarity` is `true`, OFF events otherwise.
    pub fn new(polarity: bool) -> Self {
        Self { polarity }
    }
}

impl Rule for PolarityFilter {
    const NAME: &'static str = "polarity";

    #[inline]
    fn accept(&mut self, event: &Event) -> bool {
        event.polarity == self.polarity
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Filter;

    #[test]
    fn keeps_one_polarity_and_counts_the_other() {
        let e = |polarity| Event {
            t: 0,
            x: 0,
            y: 0,
            polarity,
        };
        let events = [e(true), e(false), e(false), e(true)];
        let mut on = PolarityFilter::new(true).counted();
        let mut kept = Vec::new();
        on.retain(&events, &mut kept);
        assert_eq!(kept, [e(true), e(true)]);
        assert_eq!(on.removed(), 2);
        let mut off = PolarityFilter::new(false).counted();
        kept.clear();
        off.retain(&events, &mut kept);
        assert_eq!(kept, [e(false), e(false)]);
    }
}
