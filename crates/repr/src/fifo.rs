//! [`Fifo`]: a first-in first-out queue in fixed-size blocks, which grows without copying.
//!
//! A sliding window holds every event of its last `window` microseconds: at 3 M events/s and
//! the paper's 640 ms window, 1.9 M entries. A `VecDeque` that doubles to get there copies its
//! contents each time, and the last doublings (16-32 MB) stalled one estimate for about 10 ms
//! while a live run warmed up (measured in `crates/online/benches/latency.rs`: the only late
//! estimates at 10x the realistic rate). Here the queue is a list of blocks of [`BLOCK`]
//! entries: growing adds a block, emptied blocks are kept for reuse, and nothing is ever moved.
//! Why by hand: the well-kept deque crates either copy on growth or are concurrent queues with
//! per-operation synchronisation; this is 60 lines.

use std::collections::VecDeque;

/// Entries per block: 64 KiB blocks of 16-byte entries, large enough that the per-block
/// bookkeeping is negligible, small enough that growth is a cheap allocation.
const BLOCK: usize = 4096;

/// A FIFO queue of `T` stored in blocks of [`BLOCK`] entries.
#[derive(Debug, Clone)]
pub(crate) struct Fifo<T> {
    /// Full blocks, oldest first.
    full: VecDeque<Vec<T>>,
    /// The block being filled (after every full block).
    tail: Vec<T>,
    /// Entries already taken from the oldest block (the first full one, else `tail`).
    head: usize,
    /// Emptied blocks, kept for reuse.
    spare: Vec<Vec<T>>,
}

impl<T: Copy> Fifo<T> {
    /// An empty queue.
    pub(crate) fn new() -> Self {
        Self {
            full: VecDeque::new(),
            tail: Vec::with_capacity(BLOCK),
            head: 0,
            spare: Vec::new(),
        }
    }

    /// Appends `item` at the back.
    #[inline]
    pub(crate) fn push_back(&mut self, item: T) {
        self.make_room();
        self.tail.push(item);
    }

    /// Makes sure the block being filled has room: a full one moves to the full blocks and a
    /// spare (or new) block takes its place. Blocks are allocated with room for [`BLOCK`]
    /// entries, so filling one does not reallocate it.
    #[inline]
    fn make_room(&mut self) {
        if self.tail.len() == BLOCK {
            let fresh = self
                .spare
                .pop()
                .unwrap_or_else(|| Vec::with_capacity(BLOCK));
            let done = std::mem::replace(&mut self.tail, fresh);
            self.full.push_back(done);
        }
    }

    /// Appends every item of `items` at the back, a block at a time.
    #[inline]
    pub(crate) fn extend(&mut self, items: impl IntoIterator<Item = T>) {
        let mut items = items.into_iter().peekable();
        while items.peek().is_some() {
            self.make_room();
            let room = BLOCK - self.tail.len();
            self.tail.extend(items.by_ref().take(room));
        }
    }

    /// Removes entries from the front while `take` accepts them, handing each to `on_pop`.
    #[inline]
    pub(crate) fn pop_while(
        &mut self,
        mut take: impl FnMut(&T) -> bool,
        mut on_pop: impl FnMut(T),
    ) {
        let Self {
            full,
            tail,
            head,
            spare,
        } = self;
        loop {
            let block = full.front().unwrap_or(tail);
            for item in &block[*head..] {
                if !take(item) {
                    return;
                }
                *head += 1;
                on_pop(*item);
            }
            // The oldest block is used up.
            *head = 0;
            match full.pop_front() {
                Some(mut done) => {
                    done.clear();
                    spare.push(done);
                }
                None => {
                    tail.clear();
                    return;
                }
            }
        }
    }

    /// Number of entries: the full blocks and the one being filled, less those taken from
    /// the oldest.
    pub(crate) fn len(&self) -> usize {
        self.full.len() * BLOCK + self.tail.len() - self.head
    }

    /// Whether the queue holds no entry.
    pub(crate) fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Removes every entry (keeping the blocks for reuse).
    pub(crate) fn clear(&mut self) {
        for mut block in self.full.drain(..) {
            block.clear();
            self.spare.push(block);
        }
        self.tail.clear();
        self.head = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn pop_front(fifo: &mut Fifo<usize>) -> Option<usize> {
        let (mut asked, mut item) = (false, None);
        fifo.pop_while(|_| !std::mem::replace(&mut asked, true), |x| item = Some(x));
        item
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        #[test]
        fn behaves_like_a_vecdeque(ops in proptest::collection::vec(0u8..3, 0..6_000)) {
            let mut fifo = Fifo::new();
            let mut reference = VecDeque::new();
            for (i, op) in ops.into_iter().enumerate() {
                match op {
                    // Pushes outnumber pops, so the queue spans several blocks.
                    0 if i % 7 == 0 => {
                        fifo.extend(i..i + 2000);
                        reference.extend(i..i + 2000);
                    }
                    0 | 1 => {
                        fifo.push_back(i);
                        reference.push_back(i);
                    }
                    _ if i % 5 == 0 => {
                        // Pop a few at once, as a window does.
                        let mut left = 3;
                        let mut popped = Vec::new();
                        fifo.pop_while(|_| { left -= 1; left >= 0 }, |x| popped.push(x));
                        let expected: Vec<usize> =
                            (0..3).map_while(|_| reference.pop_front()).collect();
                        prop_assert_eq!(popped, expected);
                    }
                    _ => prop_assert_eq!(pop_front(&mut fifo), reference.pop_front()),
                }
                prop_assert_eq!(fifo.len(), reference.len());
            }
            fifo.clear();
            prop_assert_eq!(pop_front(&mut fifo), None);
            fifo.push_back(7);
            prop_assert_eq!(pop_front(&mut fifo), Some(7));
        }
    }
}
