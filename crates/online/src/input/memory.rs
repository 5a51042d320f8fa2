//! Events already in memory, handed out in fixed-size chunks: for tests, benchmarks, and
//! replaying a recording that was read whole.

use super::{ChunkInfo, EventSource, Next};
use crate::Notice;
use evtac_events::Event;

/// Replays `events` (in time order) in chunks of `chunk_len` events.
#[derive(Debug, Clone)]
pub struct MemorySource {
    events: Vec<Event>,
    chunk_len: usize,
    pos: usize,
}

impl MemorySource {
    /// A source over `events` handing out `chunk_len` events at a time (at least one).
    pub fn new(events: Vec<Event>, chunk_len: usize) -> Self {
        Self {
            events,
            chunk_len: chunk_len.max(1),
            pos: 0,
        }
    }
}

impl EventSource for MemorySource {
    fn next_chunk(&mut self, out: &mut Vec<Event>, _notify: &mut dyn FnMut(Notice)) -> Next {
        out.clear();
        if self.pos >= self.events.len() {
            return Ok(None);
        }
        let end = self
            .pos
            .saturating_add(self.chunk_len)
            .min(self.events.len());
        out.extend_from_slice(&self.events[self.pos..end]);
        self.pos = end;
        Ok(Some(ChunkInfo::default()))
    }
}
