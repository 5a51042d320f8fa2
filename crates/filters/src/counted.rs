//! The count every filter keeps: [`Counted`] wraps a [`Rule`] (the filter's decision, from its
//! own state) and counts the events it removed, so that the rules themselves only decide.

use evtac_events::Event;

use crate::Filter;

/// A filter's decision, event by event in stream order, from its own state: the part that
/// differs from filter to filter. [`Counted`] makes it a [`Filter`].
pub trait Rule: Send {
    /// The filter's name on the command line (`background-activity`, `k-noise`, ...).
    const NAME: &'static str;

    /// Whether to keep `event`, which comes after every event seen before; updates the state.
    fn accept(&mut self, event: &Event) -> bool;

    /// The rule as a [`Filter`] that counts what it removes.
    fn counted(self) -> Counted<Self>
    where
        Self: Sized,
    {
        Counted::new(self)
    }
}

/// A [`Rule`] with the count of the events it removed.
#[derive(Debug, Clone)]
pub struct Counted<R> {
    rule: R,
    removed: u64,
}

impl<R: Rule> Counted<R> {
    /// `rule`, nothing removed yet.
    pub fn new(rule: R) -> Self {
        Self { rule, removed: 0 }
    }
}

impl<R: Rule> Filter for Counted<R> {
    fn name(&self) -> &'static str {
        R::NAME
    }

    fn keep(&mut self, event: &Event) -> bool {
        let keep = self.rule.accept(event);
        self.removed += u64::from(!keep);
        keep
    }

    fn removed(&self) -> u64 {
        self.removed
    }
}
