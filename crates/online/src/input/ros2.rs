//! Events in from ROS 2 (`ros2:///event_camera/events`): a DDS subscription, in pure Rust, to a
//! camera driver's event topic, with no ROS installation.
//!
//! Like the publisher ([`crate::ros2`], which says why RustDDS), it speaks DDS with ROS 2's
//! conventions: the topic `/event_camera/events` is the DDS topic `rt/event_camera/events`, and
//! the message types are ROS 2's, named as `rmw` names them for DDS. Two types are read:
//!
//! - `event_camera_msgs/msg/EventPacket` (ros-event-camera's metavision and libcaer drivers;
//!   `evt3` and `mono` packets), and
//! - `dvs_msgs/msg/EventArray` (rpg_dvs_ros and its ROS 2 ports).
//!
//! # Which type
//! DDS discovery announces each writer with its topic and type name, so the source waits for a
//! writer of the topic to be discovered and subscribes with that writer's type
//! (`event_camera_msgs::msg::dds_::EventPacket_`, `dvs_msgs::msg::dds_::EventArray_`). A topic
//! published with any other type, or with both, is an error naming the topic and the types.
//! [`Ros2InputOptions::message`] (`--ros-event-type`) fixes the type instead, for a publisher
//! whose discovery data evtac cannot see in time; the reader is then created at once.
//!
//! # Decoding
//! Each sample's bytes (CDR, with its encapsulation header, as rosbag2 would store them) go
//! through [`evtac_formats::ros::MessageDecoder`], the decoder the bag readers use for each
//! message, with one decoder for the topic whose EVT 3.0 state carries from packet to packet.
//! So the events of a live stream are those of a bag of the same messages, bit for bit, times
//! included. One sample is one chunk for the pipeline, stamped on arrival when it is taken.
//!
//! # QoS
//! The reader is volatile (what a late subscriber of a sensor stream wants, and it matches
//! every writer's durability) and keep-last ([`HISTORY_DEPTH`] samples). Its reliability is
//! chosen as `rosbag2` and `ros2 topic echo` choose theirs: reliable when every discovered
//! writer of the topic offers reliable (a default `rclpy`/`rclcpp` publisher: lost datagrams
//! are resent), else best effort, which matches both kinds of writer (a reliable reader does
//! not match a best-effort writer, and camera drivers often publish best effort). With the
//! type fixed by option, nothing is known of the writers, so the reader is best effort.
//!
//! # Failures
//! As for the DV network stream ([`super::NetworkSource`]), with DDS's words:
//! - No sample for the stall timeout: the input is reported lost ([`Notice::Lost`], saying
//!   whether the publisher left), then waited for with the backoff policy: attempt `n` waits
//!   up to the backoff's `n`-th delay for a sample ([`Notice::Waiting`]); the first sample ends
//!   the wait at once ([`Notice::Connected`], a reconnection in the summary). After the last
//!   attempt the stream ends normally and every event received is estimated.
//! - A publisher that never comes: opening waits the connect timeout (discovery takes a moment
//!   more than a TCP connection), then the backoff's attempts, then fails naming the topic and
//!   the domain.
//! - Lost samples: DDS numbers each writer's samples; a jump in the numbers of one writer is
//!   samples lost (best effort, or a reliable writer's history overwritten before they were
//!   resent, or this reader's own history overflowing while estimation was behind), counted
//!   in the summary. Their events never arrive; for `evt3` the decoder goes on from its state
//!   (as ros-event-camera's decoders do), which the next time-high word corrects.
//! - A sample that does not decode (cut short, a field out of range, a sensor size other than
//!   the first sample's, not plain CDR) is skipped, counted and reported ([`Notice::Skipped`],
//!   at most once a second, naming the field); estimation goes on. An `EventPacket` encoding
//!   evtac does not decode is an error naming the topic and the encoding: every sample would
//!   be skipped.

use super::{ChunkInfo, EventSource, InputError, NetworkOptions, Next};
use crate::Notice;
use crate::ros2::{MAX_DOMAIN_ID, dds_topic_name};
use evtac_events::{Event, Resolution, Trigger};
use evtac_formats::ros::{EventMessage, MessageDecoder, MessageError};
use rustdds::mio1::{Events, Interest, Poll, Token};
use rustdds::no_key::{DataReader, Decode, DefaultDecoder, DeserializerAdapter};
use rustdds::policy::{Durability, History, Reliability};
use rustdds::{
    DataReaderStatus, DomainParticipant, DomainParticipantBuilder, GUID, QosPolicies,
    QosPolicyBuilder, RepresentationIdentifier, StatusEvented, Subscriber, TopicKind,
};
use std::collections::HashMap;
use std::net::IpAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

/// Samples the reader keeps until they are taken: about a second of a driver's packets at one
/// per millisecond. The ingestion thread takes them as they come; only while estimation is
/// behind (the pipeline's queue full) do they wait here, and beyond this many the oldest are
/// overwritten, which shows as lost samples.
const HISTORY_DEPTH: i32 = 1000;

/// Longest sleep between looks at the discovered writers while no reader exists yet.
const DISCOVERY_POLL: Duration = Duration::from_millis(10);

/// Longest single wait for the reader's readiness: a bound on how long a missed wake-up could
/// delay a sample (none is expected; the reader signals every arrival).
const POLL_CAP: Duration = Duration::from_millis(20);

/// Shortest time between two [`Notice::Skipped`].
const SKIPPED_NOTICE_EVERY: Duration = Duration::from_secs(1);

/// How a ROS 2 input subscribes.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Ros2InputOptions {
    /// The DDS domain (ROS 2's `ROS_DOMAIN_ID`).
    pub domain: u16,
    /// Use only the network interfaces with these addresses for discovery and data; every
    /// interface when empty.
    pub interfaces: Vec<IpAddr>,
    /// The message type, when not to be taken from the discovered publisher.
    pub message: Option<EventMessage>,
}

/// A sample as delivered: its CDR bytes with the 4-byte encapsulation header put back in front,
/// as rosbag2 stores a message (the decoder reads the representation from it).
#[derive(Debug, Clone)]
struct RawSample(Vec<u8>);

/// RustDDS's deserializer hook for [`RawSample`]: copies the bytes, decodes nothing (that is
/// [`MessageDecoder`]'s job, with errors naming the field).
#[derive(Debug, Clone, Copy)]
struct RawAdapter;

/// Every representation RustDDS knows is accepted here, so that a sample in one evtac does not
/// read (XCDR2, say) reaches the decoder and is reported by it, rather than failing inside
/// RustDDS with a generic error.
const REPRESENTATIONS: [RepresentationIdentifier; 10] = [
    RepresentationIdentifier::CDR_LE,
    RepresentationIdentifier::CDR_BE,
    RepresentationIdentifier::PL_CDR_LE,
    RepresentationIdentifier::PL_CDR_BE,
    RepresentationIdentifier::CDR2_LE,
    RepresentationIdentifier::CDR2_BE,
    RepresentationIdentifier::PL_CDR2_LE,
    RepresentationIdentifier::PL_CDR2_BE,
    RepresentationIdentifier::D_CDR_LE,
    RepresentationIdentifier::D_CDR_BE,
];

impl DeserializerAdapter<RawSample> for RawAdapter {
    type Error = std::convert::Infallible;
    type Decoded = RawSample;

    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &REPRESENTATIONS
    }

    fn transform_decoded(decoded: RawSample) -> RawSample {
        decoded
    }
}

impl DefaultDecoder<RawSample> for RawAdapter {
    type Decoder = RawAdapter;
    const DECODER: RawAdapter = RawAdapter;
}

impl Decode<'_, RawSample> for RawAdapter {
    type Error = std::convert::Infallible;

    fn decode_bytes(
        self,
        input_bytes: &[u8],
        encoding: RepresentationIdentifier,
    ) -> Result<RawSample, Self::Error> {
        let mut bytes = Vec::with_capacity(input_bytes.len() + 4);
        bytes.extend_from_slice(&encoding.to_bytes());
        // The options bytes (padding at the end, XCDR2 only) are not passed on; plain CDR
        // has them 0, and the decoder accepts up to 7 bytes of padding anyway.
        bytes.extend_from_slice(&[0, 0]);
        bytes.extend_from_slice(input_bytes);
        Ok(RawSample(bytes))
    }
}

type Reader = DataReader<RawSample, RawAdapter>;

/// What the input did, for the summary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ros2InputStats {
    /// The ROS 2 topic.
    pub topic: String,
    /// Its DDS topic.
    pub dds_topic: String,
    /// The domain.
    pub domain: u16,
    /// The message type subscribed with, once known.
    pub message: Option<EventMessage>,
    /// Whether the reader asked for reliable delivery (else best effort).
    pub reliable: bool,
    /// Samples taken (decoded or not).
    pub samples: u64,
    /// Events decoded from them.
    pub events: u64,
    /// Samples lost: jumps in the writers' sequence numbers.
    pub lost: u64,
    /// Samples skipped because they did not decode.
    pub malformed: u64,
    /// Publishers matched at the last look.
    pub publishers: u64,
}

impl std::fmt::Display for Ros2InputStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let message = self.message.map_or("type unknown", EventMessage::ros2_name);
        let reliability = if self.reliable {
            "reliable"
        } else {
            "best effort"
        };
        write!(
            f,
            "ROS 2 input {} (DDS {}, {message}, {reliability}, domain {}): {} samples, {} events, \
             {} lost (sequence gaps), {} malformed (skipped), {} publisher(s) at the end",
            self.topic,
            self.dds_topic,
            self.domain,
            self.samples,
            self.events,
            self.lost,
            self.malformed,
            self.publishers
        )
    }
}

/// Counters the source updates and the caller reads, from any thread.
#[derive(Debug, Default)]
struct Counters {
    message: OnceLock<EventMessage>,
    reliable: AtomicBool,
    samples: AtomicU64,
    events: AtomicU64,
    lost: AtomicU64,
    malformed: AtomicU64,
    publishers: AtomicU64,
}

/// A handle on a [`Ros2Source`]'s counters that outlives handing the source to the pipeline.
#[derive(Debug, Clone)]
pub struct Ros2InputReport {
    topic: String,
    dds_topic: String,
    domain: u16,
    counters: Arc<Counters>,
}

impl Ros2InputReport {
    /// The figures so far.
    pub fn stats(&self) -> Ros2InputStats {
        let c = &self.counters;
        let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
        Ros2InputStats {
            topic: self.topic.clone(),
            dds_topic: self.dds_topic.clone(),
            domain: self.domain,
            message: c.message.get().copied(),
            reliable: c.reliable.load(Ordering::Relaxed),
            samples: get(&c.samples),
            events: get(&c.events),
            lost: get(&c.lost),
            malformed: get(&c.malformed),
            publishers: get(&c.publishers),
        }
    }
}

/// The reader, once the type is known, and what waits on it.
struct Subscription {
    reader: Reader,
    poll: Poll,
    events: Events,
    decoder: MessageDecoder,
    /// Writers matched, from the reader's status events.
    matched: u64,
}

/// A ROS 2 event topic as an [`EventSource`] (see the module docs).
pub struct Ros2Source {
    topic: String,
    dds_topic: String,
    name: String,
    options: Ros2InputOptions,
    network: NetworkOptions,
    subscription: Option<Subscription>,
    /// The sensor size the first decoded sample stated (0x0 when it states none).
    first_size: Option<Resolution>,
    /// The first sample's events, read by [`Ros2Source::open`], handed out first.
    first: Option<Vec<Event>>,
    /// Triggers of `evt3` packets: decoded, not used (as the network input skips them).
    triggers: Vec<Trigger>,
    /// The highest sequence number seen per writer.
    last_seq: HashMap<GUID, i64>,
    counters: Arc<Counters>,
    last_skipped_notice: Option<Instant>,
    ended: bool,
    // Dropped last (fields drop in order): the reader and subscriber belong to it.
    subscriber: Subscriber,
    participant: DomainParticipant,
}

impl std::fmt::Debug for Ros2Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ros2Source")
            .field("input", &self.name)
            .field("options", &self.options)
            .field("subscribed", &self.subscription.is_some())
            .finish_non_exhaustive()
    }
}

/// The reader's QoS: volatile, keep last, reliable or best effort (see the module docs).
fn qos(reliable: bool) -> QosPolicies {
    let reliability = if reliable {
        Reliability::Reliable {
            max_blocking_time: rustdds::Duration::from_millis(100),
        }
    } else {
        Reliability::BestEffort
    };
    QosPolicyBuilder::new()
        .reliability(reliability)
        .history(History::KeepLast {
            depth: HISTORY_DEPTH,
        })
        .durability(Durability::Volatile)
        .build()
}

impl Ros2Source {
    /// Joins the domain, waits for the topic's publisher and its first sample (the connect
    /// timeout, then the backoff's attempts), and returns the source with that sample's events
    /// to hand out first; fails naming the topic and domain when no sample ever comes.
    pub fn open(
        topic: &str,
        options: Ros2InputOptions,
        network: NetworkOptions,
        notify: &mut dyn FnMut(Notice),
    ) -> Result<Self, InputError> {
        let name = format!("ros2://{topic}");
        let dds_topic = dds_topic_name(topic).map_err(|e| InputError::Format {
            input: name.clone(),
            reason: e.to_string(),
        })?;
        if options.domain > MAX_DOMAIN_ID {
            return Err(InputError::Format {
                input: name,
                reason: format!(
                    "invalid ROS 2 domain id {}: it must be from 0 to {MAX_DOMAIN_ID}",
                    options.domain
                ),
            });
        }
        let dds_error = |what: &str, e: &dyn std::fmt::Display| InputError::Connect {
            input: name.clone(),
            reason: format!(
                "cannot create the DDS {what} for {dds_topic} in domain {}: {e}",
                options.domain
            ),
        };
        let mut builder = DomainParticipantBuilder::new(options.domain);
        if !options.interfaces.is_empty() {
            builder = builder.with_only_networks(options.interfaces.iter().copied());
        }
        let participant = builder.build().map_err(|e| dds_error("participant", &e))?;
        let subscriber = participant
            .create_subscriber(&qos(false))
            .map_err(|e| dds_error("subscriber", &e))?;
        let counters = Arc::new(Counters::default());
        let mut source = Self {
            topic: topic.to_owned(),
            dds_topic,
            name,
            options,
            network,
            subscription: None,
            first_size: None,
            first: None,
            triggers: Vec::new(),
            last_seq: HashMap::new(),
            counters,
            last_skipped_notice: None,
            ended: false,
            subscriber,
            participant,
        };
        let mut first = Vec::new();
        let deadline = Instant::now() + network.connect_timeout;
        let came = if source.wait_sample(&mut first, deadline, notify)? {
            true
        } else {
            notify(Notice::AttemptFailed {
                input: source.name.clone(),
                attempt: 0,
                reason: source.silence(network.connect_timeout),
            });
            source.wait_with_backoff(&mut first, notify)?
        };
        if !came {
            return Err(InputError::Connect {
                input: source.name.clone(),
                reason: format!(
                    "no sample on ROS 2 topic {} (DDS {}) in domain {} after {} attempts (is the \
                     driver publishing in this domain, and does discovery reach it? see \
                     docs/online.md, ROS 2)",
                    source.topic,
                    source.dds_topic,
                    source.options.domain,
                    network.backoff.attempts + 1
                ),
            });
        }
        notify(Notice::Connected {
            input: source.name.clone(),
        });
        source.first = Some(first);
        Ok(source)
    }

    /// The sensor size the first sample stated, unless it stated 0x0.
    pub fn resolution(&self) -> Option<Resolution> {
        self.first_size.filter(|s| s.pixels() > 0)
    }

    /// The input as `ros2://TOPIC`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A handle on the counters, to read after the source has gone to the pipeline.
    pub fn report(&self) -> Ros2InputReport {
        Ros2InputReport {
            topic: self.topic.clone(),
            dds_topic: self.dds_topic.clone(),
            domain: self.options.domain,
            counters: Arc::clone(&self.counters),
        }
    }

    /// The type to subscribe with and whether to ask for reliability: from the option, or from
    /// the writers of the topic discovered so far (`None`: none yet).
    fn choose_type(&self) -> Result<Option<(EventMessage, bool)>, InputError> {
        if let Some(message) = self.options.message {
            return Ok(Some((message, false)));
        }
        let writers: Vec<_> = self
            .participant
            .discovered_writers()
            .into_iter()
            .map(|w| w.publication_topic_data)
            .filter(|p| p.topic_name == self.dds_topic)
            .collect();
        let Some(first) = writers.first() else {
            return Ok(None);
        };
        let refuse = |reason: String| InputError::Format {
            input: self.name.clone(),
            reason,
        };
        let message = EventMessage::of(&first.type_name).ok_or_else(|| {
            refuse(format!(
                "ROS 2 topic {} is published as {}, not as an event message \
                 ({} or {})",
                self.topic,
                first.type_name,
                EventMessage::EventPacket.dds_type_name(),
                EventMessage::EventArray.dds_type_name()
            ))
        })?;
        if let Some(other) = writers.iter().find(|w| w.type_name != first.type_name) {
            return Err(refuse(format!(
                "ROS 2 topic {} is published with two types, {} and {}: evtac reads one",
                self.topic, first.type_name, other.type_name
            )));
        }
        // A writer that does not state its reliability is taken as best effort: the reader
        // then matches it whatever it does.
        let reliable = writers
            .iter()
            .all(|w| matches!(w.reliability, Some(Reliability::Reliable { .. })));
        Ok(Some((message, reliable)))
    }

    /// Creates the reader once the type is known; `Ok(false)` while it is not.
    fn subscribe(&mut self) -> Result<bool, InputError> {
        let Some((message, reliable)) = self.choose_type()? else {
            return Ok(false);
        };
        let dds_error = |what: &str, e: &dyn std::fmt::Display| InputError::Connect {
            input: self.name.clone(),
            reason: format!(
                "cannot create the DDS {what} for {} in domain {}: {e}",
                self.dds_topic, self.options.domain
            ),
        };
        let qos = qos(reliable);
        let topic = self
            .participant
            .create_topic(
                self.dds_topic.clone(),
                message.dds_type_name().to_owned(),
                &qos,
                TopicKind::NoKey,
            )
            .map_err(|e| dds_error("topic", &e))?;
        let mut reader: Reader = self
            .subscriber
            .create_datareader_no_key::<RawSample, RawAdapter>(&topic, Some(qos))
            .map_err(|e| dds_error("data reader", &e))?;
        let poll = Poll::new().map_err(|e| dds_error("poll", &e))?;
        poll.registry()
            .register(&mut reader, Token(0), Interest::READABLE)
            .map_err(|e| dds_error("poll registration", &e))?;
        let _ = self.counters.message.set(message);
        self.counters.reliable.store(reliable, Ordering::Relaxed);
        self.subscription = Some(Subscription {
            reader,
            poll,
            events: Events::with_capacity(4),
            decoder: MessageDecoder::cdr(message),
            matched: 0,
        });
        Ok(true)
    }

    /// Takes samples until one decodes into `out` (replacing its contents): `Ok(true)`, or
    /// `Ok(false)` when the reader holds no more. Samples that do not decode are skipped and
    /// counted.
    fn take(
        &mut self,
        out: &mut Vec<Event>,
        notify: &mut dyn FnMut(Notice),
    ) -> Result<bool, InputError> {
        let Some(sub) = self.subscription.as_mut() else {
            return Ok(false);
        };
        while let Some(status) = sub.reader.try_recv_status() {
            if let DataReaderStatus::SubscriptionMatched { current, .. } = status {
                sub.matched = u64::try_from(current.count()).unwrap_or(0);
                self.counters
                    .publishers
                    .store(sub.matched, Ordering::Relaxed);
            }
        }
        loop {
            let sample = match sub.reader.take_next_sample() {
                Ok(Some(sample)) => sample,
                Ok(None) => return Ok(false),
                Err(e) => {
                    return Err(InputError::Format {
                        input: self.name.clone(),
                        reason: format!("reading a sample of DDS topic {}: {e}", self.dds_topic),
                    });
                }
            };
            let identity = sample.sample_info().sample_identity();
            let seq = i64::from(identity.sequence_number);
            let last = self.last_seq.entry(identity.writer_guid).or_insert(seq);
            if seq > *last {
                // Gaps only: a sample older than the latest (best effort reorders nothing,
                // but a reliable resend could arrive late) is not a loss.
                let lost = u64::try_from(seq - *last - 1).unwrap_or(0);
                self.counters.lost.fetch_add(lost, Ordering::Relaxed);
                *last = seq;
            }
            self.counters.samples.fetch_add(1, Ordering::Relaxed);
            let RawSample(bytes) = sample.into_value();
            out.clear();
            self.triggers.clear();
            let decoded = sub
                .decoder
                .decode(&bytes, out, &mut self.triggers)
                .and_then(|size| match self.first_size {
                    Some(first) if first != size => Err(MessageError::Malformed(format!(
                        "the sample says the sensor is {size}, but the topic's first sample \
                         said {first}"
                    ))),
                    _ => Ok(size),
                });
            match decoded {
                Ok(size) => {
                    self.first_size.get_or_insert(size);
                    self.counters
                        .events
                        .fetch_add(out.len() as u64, Ordering::Relaxed);
                    return Ok(true);
                }
                Err(MessageError::Encoding { encoding }) => {
                    return Err(InputError::Format {
                        input: self.name.clone(),
                        reason: format!(
                            "ROS 2 topic {}: unknown EventPacket encoding `{encoding}` (evtac \
                             decodes `evt3` and `mono`)",
                            self.topic
                        ),
                    });
                }
                Err(e) => {
                    out.clear();
                    let skipped = self.counters.malformed.fetch_add(1, Ordering::Relaxed) + 1;
                    if self
                        .last_skipped_notice
                        .is_none_or(|t| t.elapsed() >= SKIPPED_NOTICE_EVERY)
                    {
                        self.last_skipped_notice = Some(Instant::now());
                        notify(Notice::Skipped {
                            input: self.name.clone(),
                            reason: format!(
                                "a sample of {} (DDS sequence number {seq}) that does not \
                                 decode: {e} ({skipped} skipped so far)",
                                sub.decoder.message()
                            ),
                        });
                    }
                }
            }
        }
    }

    /// Waits until `deadline` for a sample that decodes, into `out`; `Ok(false)` when none came.
    fn wait_sample(
        &mut self,
        out: &mut Vec<Event>,
        deadline: Instant,
        notify: &mut dyn FnMut(Notice),
    ) -> Result<bool, InputError> {
        loop {
            if self.subscription.is_none() && !self.subscribe()? {
                let now = Instant::now();
                if now >= deadline {
                    return Ok(false);
                }
                std::thread::sleep((deadline - now).min(DISCOVERY_POLL));
                continue;
            }
            if self.take(out, notify)? {
                return Ok(true);
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(false);
            }
            let Some(sub) = self.subscription.as_mut() else {
                continue;
            };
            // Woken by an arrival; an error (a signal) just means looking again.
            let _ = sub
                .poll
                .poll(&mut sub.events, Some((deadline - now).min(POLL_CAP)));
        }
    }

    /// Why no sample came in the last `waited`, for notices.
    fn silence(&self, waited: Duration) -> String {
        let s = waited.as_secs_f64();
        match &self.subscription {
            None => format!(
                "no publisher of {} (DDS {}) discovered in domain {} within {s:.1} s",
                self.topic, self.dds_topic, self.options.domain
            ),
            Some(sub) if sub.matched == 0 && self.first_size.is_some() => {
                format!("no sample for {s:.1} s: the publisher left")
            }
            Some(sub) if sub.matched == 0 => {
                format!("no sample for {s:.1} s and no publisher matched")
            }
            Some(sub) => format!(
                "no sample for {s:.1} s from {} matched publisher(s) (stalled)",
                sub.matched
            ),
        }
    }

    /// After a silence: waits for a sample through the backoff's attempts, into `out`;
    /// `Ok(false)` when every attempt passed without one (reported as given up).
    fn wait_with_backoff(
        &mut self,
        out: &mut Vec<Event>,
        notify: &mut dyn FnMut(Notice),
    ) -> Result<bool, InputError> {
        let backoff = self.network.backoff;
        let mut attempt = 0;
        while let Some(wait) = backoff.delay(attempt) {
            attempt += 1;
            notify(Notice::Waiting {
                input: self.name.clone(),
                attempt,
                attempts: backoff.attempts,
                wait,
            });
            if self.wait_sample(out, Instant::now() + wait, notify)? {
                return Ok(true);
            }
            notify(Notice::AttemptFailed {
                input: self.name.clone(),
                attempt,
                reason: self.silence(wait),
            });
        }
        notify(Notice::GaveUp {
            input: self.name.clone(),
            attempts: attempt,
        });
        Ok(false)
    }
}

impl EventSource for Ros2Source {
    fn next_chunk(&mut self, out: &mut Vec<Event>, notify: &mut dyn FnMut(Notice)) -> Next {
        if let Some(first) = self.first.take() {
            out.clear();
            out.extend_from_slice(&first);
            return Ok(Some(ChunkInfo::default()));
        }
        if self.ended {
            out.clear();
            return Ok(None);
        }
        let stall = self.network.stall_timeout;
        if self.wait_sample(out, Instant::now() + stall, notify)? {
            return Ok(Some(ChunkInfo::default()));
        }
        notify(Notice::Lost {
            input: self.name.clone(),
            reason: self.silence(stall),
        });
        if self.wait_with_backoff(out, notify)? {
            notify(Notice::Connected {
                input: self.name.clone(),
            });
            return Ok(Some(ChunkInfo::default()));
        }
        self.ended = true;
        out.clear();
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_samples_get_their_encapsulation_header_back() {
        let RawSample(bytes) = RawAdapter
            .decode_bytes(&[7, 8, 9], RepresentationIdentifier::CDR_LE)
            .unwrap();
        assert_eq!(bytes, [0, 1, 0, 0, 7, 8, 9]);
        let RawSample(bytes) = RawAdapter
            .decode_bytes(&[], RepresentationIdentifier::CDR2_LE)
            .unwrap();
        assert_eq!(&bytes[..2], &RepresentationIdentifier::CDR2_LE.to_bytes());
    }

    #[test]
    fn the_summary_line_names_topic_type_and_losses() {
        let stats = Ros2InputStats {
            topic: "/event_camera/events".into(),
            dds_topic: "rt/event_camera/events".into(),
            domain: 7,
            message: Some(EventMessage::EventPacket),
            reliable: false,
            samples: 12,
            events: 3456,
            lost: 2,
            malformed: 1,
            publishers: 0,
        };
        assert_eq!(
            stats.to_string(),
            "ROS 2 input /event_camera/events (DDS rt/event_camera/events, \
             event_camera_msgs/msg/EventPacket, best effort, domain 7): 12 samples, 3456 events, \
             2 lost (sequence gaps), 1 malformed (skipped), 0 publisher(s) at the end"
        );
    }
}
