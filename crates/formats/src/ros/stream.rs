//! A bag's event topic decoded a chunk at a time, as the recording's reader asks for chunks.
//!
//! Why not decode the topic whole and hand the result out in chunks, as the first reader did:
//! that wrote every event to one vector (48 MB for 3 M events, grown by doubling) and then read
//! it all again to check and hand it out, and the page faults of that fresh memory were a large
//! share of a bag's read. Here the messages, already kept by the scan, are decoded in receive-time
//! order into one reused chunk, checked while it is in the cache, and handed out; the IMU topic
//! (a sample per message) is still decoded whole, so that each chunk carries the samples up to
//! its last event. An `EventPacket`'s triggers are handed out with the events of their message.

use super::{Collector, EventMessage, Kind, MessageDecoder, MessageError, RosError};
use crate::check::EventCheck;
use crate::{Chunk, Event, ImuSample, Resolution, Trigger};

/// Events per chunk handed out (a chunk ends at a message boundary past this many).
const CHUNK: usize = 1 << 16;

/// The decoding state of one event topic: which message is next, the sensor size the first
/// message stated, the checks and the message decoder (whose EVT3 state carries across
/// packets; the same one a live ROS 2 input decodes its samples with).
#[derive(Debug)]
pub(super) struct Decoder {
    topic: usize,
    /// The topic's messages (indexes into its kept messages) in receive-time order.
    order: Vec<usize>,
    /// The next message, as an index into `order`.
    next: usize,
    /// The size the first message states.
    first: Option<Resolution>,
    check: EventCheck,
    messages: MessageDecoder,
}

impl Decoder {
    /// A decoder of the event topic `topic` of `c`; reads the first message's sensor size
    /// (known before any chunk, as a file header's would be).
    pub(super) fn new(c: &Collector, topic: usize) -> Result<Self, RosError> {
        let t = &c.topics[topic];
        let encoding = t.msg_encoding()?;
        let message = match t.kind {
            Kind::EventArray => EventMessage::EventArray,
            _ => EventMessage::EventPacket,
        };
        let messages = MessageDecoder::new(message, encoding);
        let order = t.in_order();
        let first = match order.first() {
            None => None,
            Some(&i) => {
                let kept = &t.messages[i];
                let size = messages.size(c.bytes(kept));
                Some(size.map_err(|e| t.message_error(0, kept.place, e))?)
            }
        };
        let stated = first.filter(|s| s.pixels() > 0);
        Ok(Self {
            topic,
            order,
            next: 0,
            first,
            check: EventCheck::new(stated),
            messages,
        })
    }

    /// The sensor size the messages state (`None`: they say 0x0, or there are none).
    pub(super) fn stated(&self) -> Option<Resolution> {
        self.first.filter(|s| s.pixels() > 0)
    }

    /// Whether every message has been decoded.
    pub(super) fn done(&self) -> bool {
        self.next >= self.order.len()
    }

    /// Decodes the next message into `events` and `triggers`, checking its events (inside the
    /// sensor, time never going backwards) so that an error names the message; `false` when
    /// none is left.
    pub(super) fn decode_next(
        &mut self,
        c: &Collector,
        events: &mut Vec<Event>,
        triggers: &mut Vec<Trigger>,
    ) -> Result<bool, RosError> {
        let Some(&i) = self.order.get(self.next) else {
            return Ok(false);
        };
        let index = self.next;
        self.next += 1;
        let topic = &c.topics[self.topic];
        let m = &topic.messages[i];
        let bytes = c.bytes(m);
        let fail = |what: &dyn std::fmt::Display| topic.message_error(index, m.place, what);
        let start = events.len();
        let size = self
            .messages
            .decode(bytes, events, triggers)
            .map_err(|e| match e {
                MessageError::Encoding { encoding } => RosError::Encoding {
                    topic: topic.info.name.clone(),
                    index,
                    place: m.place.to_string(),
                    encoding,
                },
                other => fail(&other),
            })?;
        if let Some(first) = self.first
            && first != size
        {
            return Err(RosError::Resolution {
                topic: topic.info.name.clone(),
                index,
                found: size,
                first,
            });
        }
        self.check
            .check(&events[start..])
            .map_err(|e| fail(&format_args!("{e} (counting the topic's events from 0)")))?;
        Ok(true)
    }
}

/// The chosen event topic of a bag (and its IMU samples), handed out in chunks.
#[derive(Debug)]
pub(crate) struct BagEvents {
    /// The scan, holding the messages' bytes.
    c: Collector,
    decoder: Decoder,
    /// The current chunk's events and triggers.
    events: Vec<Event>,
    triggers: Vec<Trigger>,
    /// Every IMU sample, in time order, and the next to hand out.
    imu: Vec<ImuSample>,
    next_imu: usize,
}

impl BagEvents {
    pub(super) fn new(c: Collector, decoder: Decoder, imu: Vec<ImuSample>) -> Self {
        Self {
            c,
            decoder,
            events: Vec::new(),
            triggers: Vec::new(),
            imu,
            next_imu: 0,
        }
    }

    /// The sensor size events are checked against: the messages' own, or a declared one.
    pub(crate) fn resolution(&self) -> Option<Resolution> {
        self.decoder.check.resolution()
    }

    /// Declares the sensor size (for messages that state none): events from now on must lie
    /// inside it.
    pub(crate) fn set_resolution(&mut self, resolution: Resolution) {
        self.decoder.check.set_resolution(Some(resolution));
    }

    /// The share of the event messages decoded so far, from 0 to 1 (for progress bars).
    pub(crate) fn progress(&self) -> f64 {
        self.decoder.next as f64 / self.decoder.order.len().max(1) as f64
    }

    /// The next chunk: the events (and triggers) of the next messages, at least [`CHUNK`]
    /// events unless the topic ends first, with the IMU samples up to the last of them (all
    /// that remain with the last events), so that a range read, which stops at the first chunk
    /// whose events pass the range's end, misses none.
    pub(crate) fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, RosError> {
        self.events.clear();
        self.triggers.clear();
        while self.events.len() < CHUNK
            && self
                .decoder
                .decode_next(&self.c, &mut self.events, &mut self.triggers)?
        {}
        let done = self.decoder.done();
        if done
            && self.events.is_empty()
            && self.triggers.is_empty()
            && self.next_imu >= self.imu.len()
        {
            return Ok(None);
        }
        let upto = match self.events.last() {
            Some(last) if !done => last.t,
            _ => i64::MAX,
        };
        let imu_end = self.next_imu + self.imu[self.next_imu..].partition_point(|s| s.t <= upto);
        let imu = &self.imu[self.next_imu..imu_end];
        self.next_imu = imu_end;
        Ok(Some(Chunk {
            events: &self.events,
            imu,
            triggers: &self.triggers,
        }))
    }
}
