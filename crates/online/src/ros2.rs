//! Publishing estimates on ROS 2, without a ROS installation: pure Rust over DDS.
//!
//! A robot's controller usually lives in ROS 2, and ROS 2 nodes talk DDS (RTPS over UDP) under
//! `rclcpp`/`rclpy`. So instead of linking ROS (a C/C++ install, a sourced workspace, a build
//! system of its own), evtac speaks DDS itself with the conventions ROS 2 puts on top of it, and
//! any ROS 2 node (`ros2 topic echo`, a controller, `rosbag2`) on the same domain receives the
//! estimates as if they came from a ROS node:
//!
//! - the ROS topic `/contact_angle` is the DDS topic `rt/contact_angle` ([`dds_topic_name`]);
//! - the message is `geometry_msgs/msg/Vector3Stamped`, whose DDS type name is
//!   `geometry_msgs::msg::dds_::Vector3Stamped_` ([`TYPE_NAME`]), serialized as ROS 2 does:
//!   plain CDR, little endian ([`Vector3Stamped`] mirrors the IDL field by field);
//! - `vector.x` is the pitch and `vector.y` the roll, in radians (REP 103), `vector.z` is 0;
//!   `header.stamp` is the estimate's event time `t_us` as seconds and nanoseconds (the sensor's
//!   clock, see `docs/online.md`), `header.frame_id` is configurable (`neurotac`);
//! - the QoS is the one a default `rclcpp`/`rclpy` subscription asks for: reliable, keep last
//!   ([`HISTORY_DEPTH`]), volatile;
//! - the domain is `ROS_DOMAIN_ID`'s, as ROS 2 reads it.
//!
//! # The DDS crate
//! [RustDDS](https://crates.io/crates/rustdds) (Atostek, 0.15): a maintained pure-Rust DDS
//! (regular releases, a company behind it that supports ROS 2 users), which exchanges data with
//! ROS 2, publishes interoperability results (the OMG `dds-rtps` tests) and lists Cyclone DDS
//! and Fast DDS interop fixes release after release; it serializes serde types to CDR. Its sister
//! crate `ros2-client` (same authors, built on it) adds ROS 2 nodes, services, actions and
//! parameters, but its `Node` wants a `Spinner` running on an async executor for its graph
//! bookkeeping, which would mean an executor and a thread for features evtac does not use; one
//! topic needs only the two naming conventions above, which this module spells out. The price:
//! `ros2 node list` shows no evtac node (`ros2 topic list/echo/info` work as usual).
//!
//! # Nothing blocks estimation
//! [`Ros2Publisher::publish`] never waits: on the caller's thread it serializes the estimate
//! and hands it to the DDS writer, whose own thread (RustDDS's event loop) puts it on the wire.
//! RustDDS's reliable writer keeps up to 8192 samples that a subscriber has not acknowledged;
//! the writer's QoS gives a write no time to wait for room ([`WRITE_BLOCKING`] is zero), so when
//! that window is full (a subscriber that stopped reading but did not leave) the estimate is
//! dropped for ROS at once and counted ([`PublishStats`]); the estimation and the CSV output go
//! on untouched. No subscriber at all is not a drop: with volatile durability nobody is owed
//! the message, and DDS discards it at once.
//!
//! An earlier version handed each estimate to a publishing thread of evtac's own through a
//! queue. That thread was one more wake-up between the estimate and the wire, and on a shared
//! core each wake-up is a scheduler's decision: the added latency's P99 was 143 us with it,
//! 108-114 us without (`benches/ros2_latency.rs`, idle).
//! What it protected against, a write that waits, the zero blocking time rules out. What a
//! write still shares with RustDDS's event loop is the send buffer's lock, held for the
//! moment of an insert or a send; the publish time in the summary is that write's duration.
//!
//! Messages published before a subscriber's discovery completes are not delivered to it
//! (volatile durability, as ROS 2's default). A run that must not miss its first estimates
//! (a replay recorded with `ros2 bag record`, the interop test) waits for its subscribers first:
//! [`Ros2Publisher::wait_for_subscribers`] (`evtac online --ros2-wait-subscribers N`).
//!
//! Discovery is two announcements crossing: the writer matches the reader when the reader's
//! announcement arrives, the reader matches the writer when ours does, and the two need not
//! happen together. A reliable, volatile reader (Cyclone's, as rclpy's) that matches the writer
//! late starts at the writer's next sequence number, so what was written in between is lost to
//! it (the likeliest cause of a CI run whose subscriber missed 7 of 401 estimates). RustDDS
//! says when *it* matched, not when the reader did, so the wait adds [`DISCOVERY_SETTLE`] after
//! the match.

use crate::estimator::Estimate;
use crate::latency::LatencyStats;
use rustdds::no_key::DataWriter;
use rustdds::policy::{Durability, History, Reliability};
use rustdds::{
    DataWriterStatus, DomainParticipantBuilder, QosPolicies, QosPolicyBuilder,
    RepresentationIdentifier, StatusEvented, TopicKind,
};
use serde::{Deserialize, Serialize};
use std::cell::{Cell, RefCell};
use std::net::IpAddr;
use std::time::{Duration, Instant};

/// The DDS type name of `geometry_msgs/msg/Vector3Stamped`.
pub const TYPE_NAME: &str = "geometry_msgs::msg::dds_::Vector3Stamped_";

/// History depth of the writer: a second of estimates at one per millisecond. A reliable writer
/// resends only what its history still holds, so ROS 2's default depth of 10
/// (`rmw_qos_profile_default`) gave a subscriber that fell 10 ms behind on a loaded machine
/// gaps (4 of 401 estimates in a CI run); a subscriber's own depth (10 by default) is its own.
/// Keep-last with any depth matches a default subscription.
pub const HISTORY_DEPTH: i32 = 1000;

/// Longest a write waits for room in the reliable writer's window before the estimate is
/// dropped: not at all, since the write runs on the caller's thread (see the module docs).
pub const WRITE_BLOCKING: Duration = Duration::ZERO;

/// How long [`Ros2Publisher::finish`] waits for subscribers to acknowledge what was published,
/// so that a run's last estimates are not lost by the participant leaving.
pub const LINGER: Duration = Duration::from_secs(2);

/// Largest domain id: RTPS's port mapping (7400 + 250 * domain + ...) leaves the 16-bit port
/// range above 232, and ROS 2 documents 0..=232 as well.
pub const MAX_DOMAIN_ID: u16 = 232;

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds (may be negative; the stamp is `sec + nanosec * 1e-9`).
    pub sec: i32,
    /// Nanoseconds, `0..1_000_000_000`.
    pub nanosec: u32,
}

impl Time {
    /// The time `t_us` microseconds after the clock's zero: whole seconds rounded down, the
    /// remainder as nanoseconds (so -1 us is `{sec: -1, nanosec: 999_999_000}`). Times beyond
    /// `i32` seconds (year 2038 for a Unix clock) saturate.
    pub fn from_micros(t_us: i64) -> Self {
        let sec = t_us.div_euclid(1_000_000);
        // 0..1e6 us, as nanoseconds below 1e9.
        let nanosec = (t_us.rem_euclid(1_000_000) * 1000) as u32;
        match i32::try_from(sec) {
            Ok(sec) => Self { sec, nanosec },
            Err(_) if sec < 0 => Self {
                sec: i32::MIN,
                nanosec: 0,
            },
            Err(_) => Self {
                sec: i32::MAX,
                nanosec: 999_999_999,
            },
        }
    }
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Header {
    /// When the data is for.
    pub stamp: Time,
    /// The coordinate frame the data is in.
    pub frame_id: String,
}

/// `geometry_msgs/msg/Vector3`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Vector3Stamped`, as evtac fills it from an [`Estimate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Vector3Stamped {
    /// `stamp` = the estimate's time, `frame_id` as configured.
    pub header: Header,
    /// `x` = pitch, `y` = roll, in radians; `z` = 0.
    pub vector: Vector3,
}

impl Vector3Stamped {
    /// The message for `estimate`: `x` and `y` are [`radians`] of its pitch and roll, the stamp
    /// is [`Time::from_micros`] of its `t_us`.
    pub fn from_estimate(estimate: &Estimate, frame_id: &str) -> Self {
        Self {
            header: Header {
                stamp: Time::from_micros(estimate.t_us),
                frame_id: frame_id.to_owned(),
            },
            vector: Vector3 {
                x: radians(estimate.pitch_deg),
                y: radians(estimate.roll_deg),
                z: 0.0,
            },
        }
    }
}

impl Vector3Stamped {
    /// Appends the message as a ROS 2 serialized message: the 4-byte encapsulation header of
    /// plain little-endian CDR (`00 01 00 00`) and the CDR body RustDDS's serializer makes (the
    /// bytes its data writer puts on the wire after the same header). This is what `rosbag2`
    /// stores and `rclpy.serialization.deserialize_message` reads.
    pub fn to_cdr(&self, out: &mut Vec<u8>) -> Result<(), rustdds::serialization::Error> {
        to_cdr(self, out)
    }
}

/// Appends `message`'s CDR encoding with its 4-byte encapsulation header (`00 01 00 00`:
/// little-endian CDR, no options), as a ROS 2 message is stored in a bag or sent over DDS.
pub(crate) fn to_cdr<T: Serialize>(
    message: &T,
    out: &mut Vec<u8>,
) -> Result<(), rustdds::serialization::Error> {
    out.extend_from_slice(&RepresentationIdentifier::CDR_LE.to_bytes());
    out.extend_from_slice(&[0, 0]);
    rustdds::serialization::to_writer_with_rep_id(out, message, RepresentationIdentifier::CDR_LE)
}

/// The `.msg` definitions of `std_msgs/Header` and `builtin_interfaces/Time` as they follow a
/// stamped message's own definition in an MCAP schema (each after a blank line, a line of 80 `=`
/// and its `MSG:` line): shared by [`MSG_DEFINITION`] and the image type's
/// (`crate::image_msg::IMAGE_DEFINITION`).
macro_rules! header_definitions {
    () => {
        concat!(
            "\n",
            "================================================================================\n",
            "MSG: std_msgs/Header\n",
            "builtin_interfaces/Time stamp\n",
            "string frame_id\n",
            "\n",
            "================================================================================\n",
            "MSG: builtin_interfaces/Time\n",
            "int32 sec\n",
            "uint32 nanosec\n",
        )
    };
}
pub(crate) use header_definitions;

/// The ROS 2 type name of the message ([`Vector3Stamped`]), as `rosbag2` and MCAP name it.
pub const MSG_TYPE: &str = "geometry_msgs/msg/Vector3Stamped";

/// The `.msg` definition of [`MSG_TYPE`] with its dependencies, as `rosbag2` stores it in an
/// MCAP schema (encoding `ros2msg`): the type's own definition, then each type it uses after a
/// line of 80 `=` and a `MSG: package/Type` line. Field for field the Rust types of this module.
pub const MSG_DEFINITION: &str = concat!(
    "std_msgs/Header header\n",
    "geometry_msgs/Vector3 vector\n",
    header_definitions!(),
    "\n",
    "================================================================================\n",
    "MSG: geometry_msgs/Vector3\n",
    "float64 x\n",
    "float64 y\n",
    "float64 z\n",
);

/// An estimate's angle in radians, as published: the `f32` degrees widened to `f64` exactly,
/// then multiplied by `PI / 180` in `f64` ([`f64::to_radians`], the same operation as Python's
/// `math.radians(float(numpy.float32(deg)))`).
pub fn radians(deg: f32) -> f64 {
    f64::from(deg).to_radians()
}

/// The DDS topic of the ROS 2 topic `topic`: `/contact_angle` and `contact_angle` (relative to
/// the root namespace) are `rt/contact_angle`, `/robot/contact_angle` is
/// `rt/robot/contact_angle`. A name ROS 2 would refuse is an error: empty tokens, a trailing
/// `/`, characters other than letters, digits and `_`, a token starting with a digit, `~`
/// substitutions.
pub fn dds_topic_name(topic: &str) -> Result<String, Error> {
    let bad = |why: &str| Error::TopicName {
        topic: topic.to_owned(),
        why: why.to_owned(),
    };
    let name = topic.strip_prefix('/').unwrap_or(topic);
    if name.is_empty() {
        return Err(bad("it is empty"));
    }
    for token in name.split('/') {
        if token.is_empty() {
            return Err(bad("it has an empty token (`//` or a trailing `/`)"));
        }
        if !token.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(bad(
                "only letters, digits, `_` and `/` are allowed (no `~` or `{}` substitutions)",
            ));
        }
        if token.starts_with(|c: char| c.is_ascii_digit()) {
            return Err(bad("a token starts with a digit"));
        }
    }
    Ok(format!("rt/{name}"))
}

/// The domain id in `ROS_DOMAIN_ID`, as ROS 2 reads it: `None` when unset or empty.
pub fn domain_from_env() -> Result<Option<u16>, Error> {
    match std::env::var("ROS_DOMAIN_ID") {
        Ok(v) if v.trim().is_empty() => Ok(None),
        Ok(v) => v
            .trim()
            .parse::<u16>()
            .ok()
            .filter(|&d| d <= MAX_DOMAIN_ID)
            .map(Some)
            .ok_or(Error::DomainFromEnv { value: v }),
        Err(std::env::VarError::NotPresent) => Ok(None),
        Err(std::env::VarError::NotUnicode(v)) => Err(Error::DomainFromEnv {
            value: v.to_string_lossy().into_owned(),
        }),
    }
}

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The ROS 2 topic name is invalid.
    #[error("invalid ROS 2 topic name {topic:?}: {why}")]
    TopicName {
        /// The name given.
        topic: String,
        /// What is wrong with it.
        why: String,
    },
    /// The domain id is out of range.
    #[error("invalid ROS 2 domain id {domain}: it must be from 0 to {MAX_DOMAIN_ID}")]
    Domain {
        /// The id given.
        domain: u32,
    },
    /// `ROS_DOMAIN_ID` does not hold a domain id.
    #[error("ROS_DOMAIN_ID={value:?} is not a domain id (0 to {MAX_DOMAIN_ID})")]
    DomainFromEnv {
        /// The variable's value.
        value: String,
    },
    /// A DDS entity could not be created.
    #[error(
        "cannot create the DDS {what} for publishing on ROS 2 topic {topic} \
         (DDS topic {dds_topic}) in domain {domain}: {source}"
    )]
    Create {
        /// Which entity (participant, topic, publisher, writer).
        what: &'static str,
        /// The ROS 2 topic.
        topic: String,
        /// The DDS topic.
        dds_topic: String,
        /// The domain id.
        domain: u16,
        /// What RustDDS said.
        #[source]
        source: rustdds::dds::CreateError,
    },
}

/// Where and how to publish.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ros2Options {
    /// The ROS 2 topic (`/contact_angle`).
    pub topic: String,
    /// `header.frame_id` of every message.
    pub frame_id: String,
    /// The DDS domain (ROS 2's `ROS_DOMAIN_ID`).
    pub domain: u16,
    /// Use only the network interfaces with these addresses for discovery and data (for
    /// example `127.0.0.1` to stay on this host); every interface when empty.
    pub interfaces: Vec<IpAddr>,
}

impl Ros2Options {
    /// `topic` in domain 0, frame `neurotac`, every interface.
    pub fn new(topic: impl Into<String>) -> Self {
        Self {
            topic: topic.into(),
            frame_id: "neurotac".to_owned(),
            domain: 0,
            interfaces: Vec::new(),
        }
    }
}

/// What the publisher did over a run, for the summary.
#[derive(Debug, Clone)]
pub struct PublishStats {
    /// The ROS 2 topic.
    pub topic: String,
    /// The DDS topic it maps to.
    pub dds_topic: String,
    /// The DDS domain.
    pub domain: u16,
    /// Estimates handed to the DDS writer.
    pub published: u64,
    /// Estimates dropped because the writer refused them: its reliable window was full (a
    /// subscriber that stopped acknowledging), or it failed.
    pub dropped_write: u64,
    /// Subscribers matched when the run ended.
    pub subscribers: usize,
    /// Whether every subscriber acknowledged every published estimate before the publisher
    /// left (waited for up to [`LINGER`]).
    pub acknowledged: bool,
    /// How long [`Ros2Publisher::publish`] took on the caller's thread (serializing, and the
    /// DDS writer taking the message into its send buffer; RustDDS's own thread puts it on the
    /// wire): median, P99, max.
    pub latency_median: Duration,
    /// P99 of the publish time.
    pub latency_p99: Duration,
    /// Longest publish time.
    pub latency_max: Duration,
}

impl PublishStats {
    /// Estimates not published, for any reason.
    pub fn dropped(&self) -> u64 {
        self.dropped_write
    }
}

impl std::fmt::Display for PublishStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let us = |d: Duration| d.as_secs_f64() * 1e6;
        writeln!(
            f,
            "ROS 2 {} (DDS {}, domain {}): {} published, {} dropped (writer's window full), \
             {} subscriber(s) at the end{}",
            self.topic,
            self.dds_topic,
            self.domain,
            self.published,
            self.dropped(),
            self.subscribers,
            if self.acknowledged {
                ""
            } else {
                ", not all acknowledged"
            },
        )?;
        write!(
            f,
            "ROS 2 publish time (the DDS write, on the thread that delivers estimates): median \
             {:.1} us, P99 {:.1} us, max {:.1} us",
            us(self.latency_median),
            us(self.latency_p99),
            us(self.latency_max)
        )
    }
}

type Writer = DataWriter<Vector3Stamped>;

/// Publishes estimates on a ROS 2 topic, writing on the caller's thread (see the module docs).
///
/// Not `Sync`: one thread publishes.
pub struct Ros2Publisher {
    options: Ros2Options,
    dds_topic: String,
    writer: Writer,
    /// Subscribers matched, as of the latest status RustDDS reported.
    subscribers: Cell<usize>,
    published: Cell<u64>,
    dropped_write: Cell<u64>,
    /// How long each write took.
    latency: RefCell<LatencyStats>,
    // Dropped last (fields drop in order): the writer belongs to it.
    _participant: rustdds::DomainParticipant,
}

impl std::fmt::Debug for Ros2Publisher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ros2Publisher")
            .field("options", &self.options)
            .field("dds_topic", &self.dds_topic)
            .finish_non_exhaustive()
    }
}

/// The QoS of a default `rclcpp`/`rclpy` publisher, with the writer's wait bounded.
fn qos() -> QosPolicies {
    QosPolicyBuilder::new()
        .reliability(Reliability::Reliable {
            max_blocking_time: rustdds::Duration::from_std(WRITE_BLOCKING),
        })
        .history(History::KeepLast {
            depth: HISTORY_DEPTH,
        })
        .durability(Durability::Volatile)
        .build()
}

impl Ros2Publisher {
    /// Joins the DDS domain, creates the topic and its writer, and starts the publishing
    /// thread.
    pub fn new(options: Ros2Options) -> Result<Self, Error> {
        if options.domain > MAX_DOMAIN_ID {
            return Err(Error::Domain {
                domain: options.domain.into(),
            });
        }
        let dds_topic = dds_topic_name(&options.topic)?;
        let create = |what: &'static str| {
            let (topic, dds_topic, domain) =
                (options.topic.clone(), dds_topic.clone(), options.domain);
            move |source| Error::Create {
                what,
                topic,
                dds_topic,
                domain,
                source,
            }
        };
        let mut builder = DomainParticipantBuilder::new(options.domain);
        if !options.interfaces.is_empty() {
            builder = builder.with_only_networks(options.interfaces.iter().copied());
        }
        let participant = builder.build().map_err(create("participant"))?;
        let qos = qos();
        let topic = participant
            .create_topic(
                dds_topic.clone(),
                TYPE_NAME.to_owned(),
                &qos,
                TopicKind::NoKey,
            )
            .map_err(create("topic"))?;
        let publisher = participant
            .create_publisher(&qos)
            .map_err(create("publisher"))?;
        let writer: Writer = publisher
            .create_datawriter_no_key_cdr::<Vector3Stamped>(&topic, None)
            .map_err(create("data writer"))?;
        Ok(Self {
            options,
            dds_topic,
            writer,
            subscribers: Cell::new(0),
            published: Cell::new(0),
            dropped_write: Cell::new(0),
            // The threshold of "late" is irrelevant here; only the quantiles are reported.
            latency: RefCell::new(LatencyStats::new(Duration::from_millis(1))),
            _participant: participant,
        })
    }

    /// The DDS topic the estimates go to.
    pub fn dds_topic(&self) -> &str {
        &self.dds_topic
    }

    /// Subscribers matched to the writer now.
    pub fn subscribers(&self) -> usize {
        // RustDDS reports matches as status events; the latest says how many are matched.
        while let Some(status) = self.writer.try_recv_status() {
            if let DataWriterStatus::PublicationMatched { current, .. } = status {
                self.subscribers
                    .set(usize::try_from(current.count()).unwrap_or(0));
            }
        }
        self.subscribers.get()
    }

    /// Waits until at least `count` subscribers are matched, or `timeout` passed, then
    /// [`DISCOVERY_SETTLE`] more for them to match the writer in turn; returns whether they are
    /// matched.
    pub fn wait_for_subscribers(&self, count: usize, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        loop {
            if self.subscribers() >= count {
                std::thread::sleep(DISCOVERY_SETTLE);
                return true;
            }
            if Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// Writes `estimate` on the topic, never waiting: when the reliable writer's window is full
    /// the estimate is dropped for ROS and counted.
    pub fn publish(&self, estimate: &Estimate) {
        let started = Instant::now();
        let message = Vector3Stamped::from_estimate(estimate, &self.options.frame_id);
        match self.writer.write(message, None) {
            Ok(()) => {
                self.latency.borrow_mut().record(started.elapsed());
                self.published.set(self.published.get() + 1);
            }
            Err(_) => self.dropped_write.set(self.dropped_write.get() + 1),
        }
    }

    /// Waits up to [`LINGER`] for the subscribers to acknowledge everything published, leaves
    /// the domain and returns the run's figures.
    pub fn finish(self) -> PublishStats {
        let acknowledged = self
            .writer
            .wait_for_acknowledgments(LINGER)
            .unwrap_or(false);
        let latency = self.latency.borrow();
        PublishStats {
            topic: self.options.topic.clone(),
            dds_topic: self.dds_topic.clone(),
            domain: self.options.domain,
            published: self.published.get(),
            dropped_write: self.dropped_write.get(),
            subscribers: self.subscribers(),
            acknowledged,
            latency_median: latency.quantile(0.5),
            latency_p99: latency.quantile(0.99),
            latency_max: latency.max(),
        }
    }
}

/// How long [`Ros2Publisher::wait_for_subscribers`] waits, once the writer has matched its
/// subscribers, for them to have matched the writer too. Both sides send their announcement
/// as soon as they discover each other's participant, so the gap is the other process's
/// handling of one message: well under a millisecond idle, a few milliseconds on a loaded
/// 2-core machine; 250 ms leaves room for a starved process and is paid once per run.
pub const DISCOVERY_SETTLE: Duration = Duration::from_millis(250);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_map_as_ros2_does() {
        assert_eq!(
            dds_topic_name("/contact_angle").unwrap(),
            "rt/contact_angle"
        );
        assert_eq!(dds_topic_name("contact_angle").unwrap(), "rt/contact_angle");
        assert_eq!(
            dds_topic_name("/robot1/contact_angle").unwrap(),
            "rt/robot1/contact_angle"
        );
        for bad in ["", "/", "/a//b", "/a/", "/a b", "/~/x", "/1abc", "/a-b"] {
            let e = dds_topic_name(bad).unwrap_err().to_string();
            assert!(e.contains("invalid ROS 2 topic name"), "{bad:?}: {e}");
        }
    }

    #[test]
    fn stamps_split_microseconds_into_seconds_and_nanoseconds() {
        assert_eq!(Time::from_micros(0), Time { sec: 0, nanosec: 0 });
        assert_eq!(
            Time::from_micros(1_234_567),
            Time {
                sec: 1,
                nanosec: 234_567_000
            }
        );
        assert_eq!(
            Time::from_micros(-1),
            Time {
                sec: -1,
                nanosec: 999_999_000
            }
        );
        // A DV camera's Unix-time microseconds.
        assert_eq!(
            Time::from_micros(1_700_000_000_000_001),
            Time {
                sec: 1_700_000_000,
                nanosec: 1000
            }
        );
        assert_eq!(Time::from_micros(i64::MAX).sec, i32::MAX);
        assert_eq!(Time::from_micros(i64::MIN).sec, i32::MIN);
    }

    #[test]
    fn messages_carry_radians_and_serialize_as_ros2_cdr() {
        let e = Estimate {
            t_us: 2_000_500,
            pitch_deg: 90.0,
            roll_deg: -0.1,
            latency: Duration::ZERO,
            processing: Duration::ZERO,
        };
        let m = Vector3Stamped::from_estimate(&e, "neurotac");
        assert_eq!(m.vector.x, std::f64::consts::FRAC_PI_2);
        assert_eq!(
            m.vector.y,
            f64::from(-0.1f32) * (std::f64::consts::PI / 180.0)
        );
        assert_eq!(m.vector.z, 0.0);
        assert_eq!(
            m.header.stamp,
            Time {
                sec: 2,
                nanosec: 500_000
            }
        );
        // CDR as rclcpp writes it: int32, uint32, string (u32 length with the NUL, bytes,
        // NUL), padding to 8, three float64.
        use rustdds::no_key::SerializerAdapter;
        let bytes = rustdds::CDRSerializerAdapter::<Vector3Stamped>::to_bytes(&m).unwrap();
        assert_eq!(
            <rustdds::CDRSerializerAdapter<Vector3Stamped>>::output_encoding(),
            rustdds::RepresentationIdentifier::CDR_LE
        );
        let mut expected = Vec::new();
        expected.extend(2i32.to_le_bytes());
        expected.extend(500_000u32.to_le_bytes());
        expected.extend(9u32.to_le_bytes());
        expected.extend(b"neurotac\0");
        expected.extend([0u8; 3]);
        for v in [m.vector.x, m.vector.y, 0.0] {
            expected.extend(v.to_le_bytes());
        }
        assert_eq!(&bytes[..], &expected[..]);
    }

    #[test]
    fn out_of_range_domains_are_refused_with_their_number() {
        let mut options = Ros2Options::new("/contact_angle");
        options.domain = 233;
        let e = Ros2Publisher::new(options).unwrap_err().to_string();
        assert!(e.contains("233"), "{e}");
    }
}
