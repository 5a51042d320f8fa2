//! The count every filter keeps: [`Counted`] wraps a [`Rule`] (the filter's decision, from its
//! own state) and counts the events it removed, so that the rules themselves only decide.
//!
//! [`Counted::retain`] is every rule's loop over a chunk, and it does not branch on the
//! decision: each event is copied to a small block and the block's length advances by the
//! decision (0 or 1), then the kept prefix is appended to the output. On real streams the
//! decision is close to a coin toss (background-activity keeps about 65% of a DVXplorer's
//! events, polarity half), so a `push` behind an `if` mispredicts on a large share of events;
//! the copy of every event costs less than those mispredictions (see docs/performance.md,
//! "Event filters").

use evtac_events::Event;

use crate::Filter;

/// Events decided per block in [`Counted::retain`]: 512 events (8 KiB) stay in L1 between
/// the copy and the append, and the block lives on the stack.
const BLOCK: usize = 512;

/// A filter's decision, event by event in stream order, from its own state: the part that
/// differs from filter to filter. [`Counted`] makes it a [`Filter`].
pub trait Rule: Send {
    /// The filter's name on the command line (`background-activity`, `k-noise`, ...).
    const NAME: &'static str;

    /// Whether to keep `event`, which comes after every event seen before; updates the state.
    ///
    /// Implementations are `#[inline]` (or `#[inline(always)]`): [`Counted::retain`] is generic and may be compiled in
    /// another codegen unit than the rule, and without the hint every event paid a call (and
    /// the registers it clobbers) instead of the rule's few instructions.
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

    fn retain(&mut self, events: &[Event], out: &mut Vec<Event>) {
        out.reserve(events.len());
        let before = out.len();
        let mut block = [Event::default(); BLOCK];
        for events in events.chunks(BLOCK) {
            let mut kept = 0;
            for event in events {
                // `kept` never exceeds the events seen before this one, so it is below BLOCK
                // and the mask changes nothing; it only lets the compiler drop the bounds
                // check (and its branch) from the loop.
                block[kept & (BLOCK - 1)] = *event;
                kept += usize::from(self.rule.accept(event));
            }
            out.extend_from_slice(&block[..kept]);
        }
        self.removed += (events.len() - (out.len() - before)) as u64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Keeps the events whose timestamp is in a fixed set: any pattern of decisions.
    struct Keeps(Vec<bool>);

    impl Rule for Keeps {
        const NAME: &'static str = "keeps";

        fn accept(&mut self, event: &Event) -> bool {
            self.0[event.t as usize]
        }
    }

    #[test]
    fn retain_keeps_what_accept_keeps_across_blocks() {
        // Several blocks, with all-kept, none-kept and alternating stretches, a partial last
        // block, and an output that already holds events.
        let n = 3 * BLOCK + 17;
        let pattern: Vec<bool> = (0..n)
            .map(|i| match i / BLOCK {
                0 => true,
                1 => false,
                _ => i % 3 == 0,
            })
            .collect();
        let events: Vec<Event> = (0..n as i64)
            .map(|t| Event {
                t,
                ..Event::default()
            })
            .collect();
        let mut f = Keeps(pattern.clone()).counted();
        let mut out = vec![Event::default()];
        f.retain(&events, &mut out);
        let expected: Vec<Event> = std::iter::once(Event::default())
            .chain(events.iter().copied().filter(|e| pattern[e.t as usize]))
            .collect();
        assert_eq!(out, expected);
        assert_eq!(f.removed(), (n + 1 - expected.len()) as u64);
    }
}
