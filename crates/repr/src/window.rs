//! [`SlidingWindow`]: per-pixel event counts over `(t_k - window, t_k]`, kept incrementally.
//!
//! Every event enters once (count + 1) and expires once (count - 1) when the window's start passes
//! it, from a FIFO of `(t, pixel)`: the window is never recounted, so a sample costs only the
//! events that entered or left since the previous one.

use crate::fifo::Fifo;
use evtac_events::Event;
use evtac_events::Resolution;

/// Sliding-window event counter over one frame (both polarities).
///
/// ```
/// use evtac_events::Resolution;
/// use evtac_repr::SlidingWindow;
///
/// let mut w = SlidingWindow::new(Resolution::new(2, 2), 10);
/// w.add(0, 3);
/// w.add(5, 3);
/// w.expire_through(10, |_, _| {}); // window (0, 10]: the event at t = 0 leaves
/// assert_eq!(w.counts()[3], 1);
/// ```
#[derive(Debug, Clone)]
pub struct SlidingWindow {
    window_us: i64,
    counts: Vec<u32>,
    /// Every event in the window, oldest first (in blocks: a window of millions of events
    /// grows without copying, see [`crate::fifo`]).
    queue: Fifo<Entry>,
}

/// One event in the window. The polarity takes no extra space (the entry is padded to 16
/// bytes anyway) and lets an accumulator take the event when it leaves (see
/// [`SlidingWindow::expire_batches_through`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Entry {
    pub(crate) t: i64,
    pub(crate) pixel: u32,
    pub(crate) polarity: bool,
}

/// An event that left the window, with its pixel's count after it left.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Expired {
    pub(crate) entry: Entry,
    pub(crate) count: u32,
}

impl SlidingWindow {
    /// An empty window of `window_us` microseconds over a `resolution` frame.
    pub fn new(resolution: Resolution, window_us: i64) -> Self {
        Self {
            window_us,
            counts: vec![0; resolution.pixels()],
            queue: Fifo::new(),
        }
    }

    /// The window length in microseconds.
    pub fn window_us(&self) -> i64 {
        self.window_us
    }

    /// Adds an event at time `t` on pixel `pixel` (`y * width + x`); returns the pixel's new
    /// count. Times must be non-decreasing (the caller checks).
    ///
    /// # Panics
    /// When `pixel` is outside the frame.
    #[inline]
    pub fn add(&mut self, t: i64, pixel: u32) -> u32 {
        let c = &mut self.counts[pixel as usize];
        *c += 1;
        // The polarity is only read by an accumulator fed from the window, which the
        // extractor sets up through `add_batch`.
        self.queue.push_back(Entry {
            t,
            pixel,
            polarity: true,
        });
        *c
    }

    /// Adds a batch of events (time order; event `i` on pixel `pixels[i]`) and writes each
    /// one's new count into `counts`: [`Self::add`] for each, with the queue extended once.
    ///
    /// # Panics
    /// When a pixel is outside the frame, or `counts` or `pixels` is shorter than `events`.
    #[inline]
    pub(crate) fn add_batch(&mut self, events: &[Event], pixels: &[u32], counts: &mut [u32]) {
        for (&p, out) in pixels[..events.len()].iter().zip(counts.iter_mut()) {
            let c = &mut self.counts[p as usize];
            *c += 1;
            *out = *c;
        }
        self.queue
            .extend(events.iter().zip(pixels).map(|(e, &pixel)| Entry {
                t: e.t,
                pixel,
                polarity: e.polarity,
            }));
    }

    /// Hints the cache to load pixel `pixel`'s count (an event for it is coming).
    #[inline(always)]
    pub(crate) fn prefetch(&self, pixel: usize) {
        crate::prefetch::prefetch(&self.counts, pixel);
    }

    /// Moves the window's end to `t_k`: removes every event with `t <= t_k - window`, calling
    /// `on_expire(pixel, new_count)` for each.
    #[inline]
    pub fn expire_through(&mut self, t_k: i64, mut on_expire: impl FnMut(u32, u32)) {
        let start = t_k.saturating_sub(self.window_us);
        let counts = &mut self.counts;
        self.queue.pop_while(
            |e| e.t <= start,
            |e| {
                let c = &mut counts[e.pixel as usize];
                *c -= 1;
                on_expire(e.pixel, *c);
            },
        );
    }

    /// [`Self::expire_through`] in batches of at most `BATCH`: each batch of events that left,
    /// oldest first, is handed to `on_batch` after their counts have been decremented.
    #[inline]
    pub(crate) fn expire_batches_through<const BATCH: usize>(
        &mut self,
        t_k: i64,
        mut on_batch: impl FnMut(&[Expired]),
    ) {
        let start = t_k.saturating_sub(self.window_us);
        let counts = &mut self.counts;
        let mut batch = [Expired::default(); BATCH];
        let mut n = 0;
        self.queue.pop_while(
            |e| e.t <= start,
            |entry| {
                let c = &mut counts[entry.pixel as usize];
                *c -= 1;
                batch[n] = Expired { entry, count: *c };
                n += 1;
                if n == BATCH {
                    on_batch(&batch);
                    n = 0;
                }
            },
        );
        if n > 0 {
            on_batch(&batch[..n]);
        }
    }

    /// The per-pixel counts, row-major.
    pub fn counts(&self) -> &[u32] {
        &self.counts
    }

    /// Number of events in the window.
    pub fn len(&self) -> usize {
        self.queue.len()
    }

    /// Whether the window holds no event.
    pub fn is_empty(&self) -> bool {
        self.queue.is_empty()
    }

    /// Empties the window.
    pub fn clear(&mut self) {
        self.counts.fill(0);
        self.queue.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batched_expiry_hands_over_what_single_expiry_reports() {
        let (mut one, mut batched) = (
            SlidingWindow::new(Resolution::new(4, 1), 10),
            SlidingWindow::new(Resolution::new(4, 1), 10),
        );
        let events: Vec<Event> = (0..20)
            .map(|i| Event {
                t: i,
                x: (i * 7 % 4) as u16,
                y: 0,
                polarity: i % 3 == 0,
            })
            .collect();
        let pixels: Vec<u32> = events.iter().map(|e| u32::from(e.x)).collect();
        for w in [&mut one, &mut batched] {
            w.add_batch(&events, &pixels, &mut [0; 20]);
        }
        let mut expected = Vec::new();
        one.expire_through(25, |p, c| expected.push((p, c)));
        let (mut got, mut sizes) = (Vec::new(), Vec::new());
        batched.expire_batches_through::<4>(25, |batch| {
            sizes.push(batch.len());
            for (x, e) in batch.iter().zip(&events[got.len()..]) {
                assert_eq!((x.entry.t, x.entry.polarity), (e.t, e.polarity));
                got.push((x.entry.pixel, x.count));
            }
        });
        assert_eq!(got, expected);
        assert_eq!(sizes, [4, 4, 4, 4]);
        assert_eq!(batched.counts(), one.counts());
    }

    #[test]
    fn window_is_half_open_on_the_left() {
        let mut w = SlidingWindow::new(Resolution::new(1, 1), 100);
        w.add(0, 0);
        w.add(100, 0);
        w.expire_through(99, |_, _| {
            panic!("nothing leaves before t_k - window reaches 0")
        });
        assert_eq!(w.counts()[0], 2);
        let mut left = Vec::new();
        w.expire_through(100, |p, c| left.push((p, c)));
        assert_eq!(left, [(0, 1)]);
        w.expire_through(200, |_, _| {});
        assert!(w.is_empty());
        assert_eq!(w.counts()[0], 0);
    }
}
