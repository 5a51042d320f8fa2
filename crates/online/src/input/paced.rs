//! Replay at recorded pace (`--realtime`): a source's events released in slices of event time,
//! each when the wall clock reaches the slice's end.
//!
//! A camera hands over events in packets shortly after they happen; a paced replay does the same
//! with a file, so that latency figures measured on a replay mean what they would mean live.
//! Because the replay reads ahead, each slice also tells the estimator that every event up to the
//! slice's end has been delivered (its *horizon*), so estimates in quiet stretches are not held
//! back waiting for the next event.

use super::{ChunkInfo, EventSource, InputError, Next};
use crate::Notice;
use evtac_events::Event;
use std::time::{Duration, Instant};

/// Paces another source: events with `t` in `(edge - slice, edge]` are released together at
/// `start + (edge - first_t)`, where `edge` runs over the multiples of the slice length.
#[derive(Debug)]
pub struct Paced<S> {
    inner: S,
    slice_us: i64,
    /// Events read from `inner` but not yet released, from `pos` on.
    pending: Vec<Event>,
    pos: usize,
    /// Chunk buffer for `inner`.
    scratch: Vec<Event>,
    inner_done: bool,
    /// All events with `t <= inner_horizon` have been read from `inner`.
    inner_horizon: i64,
    /// Event time and wall-clock instant of the first event.
    origin: Option<(i64, Instant)>,
    next_edge: i64,
}

impl<S: EventSource> Paced<S> {
    /// Paces `inner` in slices of `slice_us` microseconds of event time (at least 1).
    pub fn new(inner: S, slice_us: i64) -> Self {
        Self {
            inner,
            slice_us: slice_us.max(1),
            pending: Vec::new(),
            pos: 0,
            scratch: Vec::new(),
            inner_done: false,
            inner_horizon: i64::MIN,
            origin: None,
            next_edge: i64::MIN,
        }
    }

    /// Reads one chunk from `inner` into `pending`; returns `false` at the end of `inner`.
    fn read_more(&mut self, notify: &mut dyn FnMut(Notice)) -> Result<bool, InputError> {
        if self.inner_done {
            return Ok(false);
        }
        // Drop what was released already so `pending` stays the size of a chunk or two.
        if self.pos > 0 {
            self.pending.drain(..self.pos);
            self.pos = 0;
        }
        match self.inner.next_chunk(&mut self.scratch, notify)? {
            Some(info) => {
                self.pending.extend_from_slice(&self.scratch);
                if let Some(h) = info.horizon {
                    self.inner_horizon = self.inner_horizon.max(h);
                }
                Ok(true)
            }
            None => {
                self.inner_done = true;
                Ok(false)
            }
        }
    }

    /// Whether every event with `t <= edge` is in `pending` already.
    fn complete_up_to(&self, edge: i64) -> bool {
        self.inner_done
            || self.inner_horizon >= edge
            || self.pending.last().is_some_and(|e| e.t > edge)
    }
}

impl<S: EventSource> EventSource for Paced<S> {
    fn next_chunk(&mut self, out: &mut Vec<Event>, notify: &mut dyn FnMut(Notice)) -> Next {
        out.clear();
        let (first_t, start) = match self.origin {
            Some(origin) => origin,
            None => {
                while self.pending.len() == self.pos {
                    if !self.read_more(notify)? {
                        return Ok(None);
                    }
                }
                let first_t = self.pending[self.pos].t;
                let origin = (first_t, Instant::now());
                self.origin = Some(origin);
                self.next_edge = first_t
                    .div_euclid(self.slice_us)
                    .saturating_mul(self.slice_us)
                    .saturating_add(self.slice_us);
                origin
            }
        };
        // Find out whether anything is left before releasing another (possibly empty) slice.
        while self.pos == self.pending.len() {
            if !self.read_more(notify)? {
                return Ok(None);
            }
        }
        let edge = self.next_edge;
        while !self.complete_up_to(edge) {
            self.read_more(notify)?;
        }
        let start_idx = self.pos;
        let len = self.pending[start_idx..].partition_point(|e| e.t <= edge);
        self.pos = start_idx + len;
        self.next_edge = edge.saturating_add(self.slice_us);
        let offset = u64::try_from(edge.saturating_sub(first_t)).unwrap_or(0);
        let due = start + Duration::from_micros(offset);
        let now = Instant::now();
        if due > now {
            std::thread::sleep(due - now);
        }
        out.extend_from_slice(&self.pending[start_idx..self.pos]);
        Ok(Some(ChunkInfo {
            horizon: Some(edge),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::MemorySource;

    fn ev(t: i64) -> Event {
        Event {
            t,
            x: 0,
            y: 0,
            polarity: true,
        }
    }

    #[test]
    fn slices_at_multiples_keep_every_event_and_pace_the_clock() {
        let events: Vec<Event> = [100, 900, 1000, 1001, 2500, 2500, 6000]
            .into_iter()
            .map(ev)
            .collect();
        let mut paced = Paced::new(MemorySource::new(events.clone(), 2), 1000);
        let started = Instant::now();
        let mut slices = Vec::new();
        let mut notify = |_n: Notice| {};
        let mut out = Vec::new();
        while let Some(info) = paced.next_chunk(&mut out, &mut notify).unwrap() {
            slices.push((info.horizon, out.iter().map(|e| e.t).collect::<Vec<_>>()));
        }
        let elapsed = started.elapsed();
        assert_eq!(
            slices,
            vec![
                (Some(1000), vec![100, 900, 1000]),
                (Some(2000), vec![1001]),
                (Some(3000), vec![2500, 2500]),
                (Some(4000), vec![]),
                (Some(5000), vec![]),
                (Some(6000), vec![6000]),
            ]
        );
        // The last slice ends 5.9 ms of event time after the first event.
        assert!(elapsed >= Duration::from_micros(5900), "{elapsed:?}");
    }

    #[test]
    fn empty_source_ends_at_once() {
        let mut paced = Paced::new(MemorySource::new(Vec::new(), 4), 1000);
        assert!(
            paced
                .next_chunk(&mut Vec::new(), &mut |_| {})
                .unwrap()
                .is_none()
        );
    }
}
