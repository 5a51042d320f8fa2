//! ROS bags: the recordings event-camera drivers for ROS leave behind, read for their events and
//! IMU samples.
//!
//! Two containers:
//!
//! - **ROS 1 `.bag`** (`#ROSBAG V2.0`, [`Format::RosBag`]): records with `name=value` headers;
//!   messages sit in chunks, uncompressed, bz2 or lz4 (the `bag1` module explains why evtac
//!   parses the container itself rather than through the `rosbag` crate).
//! - **ROS 2 MCAP** (`\x89MCAP0\r\n`, [`Format::Mcap`]), rosbag2's default storage: a single
//!   `.mcap` file, or a rosbag2 folder (`metadata.yaml` beside one or more `.mcap` files), read
//!   with the `mcap` crate (module `mcap2`).
//!
//! In a bag, a stream *is* a topic: [`topics`] lists them (name, message type, message count),
//! and [`open_with`](crate::open_with) reads the event topic a [`StreamSelection`] names
//! (`--stream TOPIC`, `--imu-stream TOPIC`), else the only one, else it fails listing the
//! topics, as for an AEDAT4 file with two cameras. With several IMU topics, the one in the
//! event topic's namespace (`/cam0/imu` for `/cam0/events`) is the default.
//!
//! Messages understood (ROS 1 names; ROS 2's have `/msg/` in the middle, and an MCAP file may
//! hold either encoding: `cdr` or `ros1`):
//!
//! - `dvs_msgs/EventArray` (the rpg_dvs_ros drivers): `Header header; uint32 height; uint32
//!   width; Event[] events` with `Event = uint16 x, uint16 y, time ts, bool polarity`. An event's
//!   time is `ts.sec * 1_000_000 + ts.nsec / 1000` microseconds: integer arithmetic, the
//!   nanoseconds truncated (never rounded, so an event never moves into the next microsecond).
//! - `event_camera_msgs/EventPacket` (ros-event-camera's metavision and libcaer drivers): the
//!   camera's own encoding in `uint8[] events`. `evt3` packets are decoded with evtac's EVT 3.0
//!   decoder, one decoder per topic whose state (time high and low, row, vector base) carries
//!   from packet to packet, as ros-event-camera's `event_camera_codecs` does: the driver cuts
//!   the camera's word stream into packets anywhere. For `evt3` the `time_base` field is
//!   undefined (event_camera_msgs says so; the codecs' `setTimeBase` is a no-op for it), so the
//!   times are the camera's: microseconds from the sensor's counter, not ROS time. `mono`
//!   packets hold 64-bit words (`dt` in bits 0..32, `x` 32..48, `y` 48..63, polarity bit 63) and
//!   the time is `time_base + dt` nanoseconds, truncated to microseconds. Other encodings are an
//!   error naming the topic, the message and the encoding.
//! - `sensor_msgs/Imu`: the header stamp in microseconds (truncated as above), the linear
//!   acceleration divided by standard gravity (9.80665 m/s^2) into g, the angular velocity from
//!   rad/s into deg/s. The message has no temperature, so [`ImuSample::temperature`] is NaN (not
//!   a made-up 0 C that a statistic would average); [`EventReader::note`](crate::EventReader::note)
//!   says so.
//!
//! The sensor size is each event message's `width` x `height`; all messages of the topic must
//! state the same, else the error names the first message that differs. A topic whose messages
//! all say 0x0 states none (declare one with `set_resolution`). Messages are taken in the order
//! of their receive time (the bag's record time, MCAP's log time), ties in file order, as ROS's
//! own bag readers play them back; IMU samples are then ordered by their header stamps.
//!
//! The bag is read whole into memory (like the NeuroTac pickles): the topics are only known once
//! the file has been scanned, and both containers' indexes are optional. Nothing a header
//! claims is allocated before the bytes are there: lengths are checked against what is left,
//! and decompression grows with the data actually produced.

mod bag1;
pub(crate) mod family;
mod mcap2;
mod message;
mod msg;
mod stream;

use std::collections::HashMap;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::aedat::SelectionError;
use crate::{Error, Format, ImuSample, Resolution};
use crate::{StreamChoice, StreamSelection};
pub(crate) use stream::BagEvents;
use stream::Decoder;

pub use message::{EventMessage, MessageDecoder, MessageError};
pub use msg::STANDARD_GRAVITY;

/// The ROS 1 bag magic (version 2.0, the only one in use since ROS C Turtle).
pub const ROSBAG_MAGIC: &[u8] = b"#ROSBAG V2.0\n";
/// The MCAP magic.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// One topic of a bag (`evtac info` lists them).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TopicInfo {
    /// The topic name (`/dvs/events`).
    pub name: String,
    /// Its message type, as the bag spells it (`dvs_msgs/EventArray`,
    /// `event_camera_msgs/msg/EventPacket`).
    #[serde(rename = "type")]
    pub message_type: String,
    /// Messages recorded on it.
    pub messages: u64,
}

/// What is wrong with a bag (the crate's [`Error::Ros`] adds the file).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RosError {
    /// The container (records, chunks) is broken or cut off.
    #[error("{what} (at byte offset {offset})")]
    Container {
        /// Where the broken record starts.
        offset: u64,
        /// What is wrong.
        what: String,
    },
    /// The MCAP container is broken or cut off (the `mcap` crate's finding). Its reader reads
    /// records in order and does not say where a record starts: the place given is how far the
    /// file had been read when the problem was found.
    #[error("broken MCAP container, read up to byte {read_to}: {what}")]
    Mcap {
        /// The bytes of the file read when the problem was found.
        read_to: u64,
        /// What the reader found.
        what: String,
    },
    /// A message does not decode as its type.
    #[error("topic {topic}, message {index}{place}: {what}")]
    Message {
        /// The topic.
        topic: String,
        /// Zero-based index of the message in the topic (in receive-time order).
        index: usize,
        /// Where it is in the file, when known (` (record at byte offset N)`).
        place: String,
        /// What is wrong, naming the field.
        what: String,
    },
    /// An `EventPacket`'s encoding is not one evtac decodes.
    #[error(
        "topic {topic}, message {index}{place}: unknown EventPacket encoding `{encoding}` \
         (evtac decodes `evt3` and `mono`)"
    )]
    Encoding {
        /// The topic.
        topic: String,
        /// Zero-based index of the message in the topic.
        index: usize,
        /// Where it is in the file, when known.
        place: String,
        /// The packet's `encoding` field.
        encoding: String,
    },
    /// Event messages of one topic disagree on the sensor size.
    #[error(
        "topic {topic}, message {index}: the message says the sensor is {found}, but the topic's \
         first message says {first}"
    )]
    Resolution {
        /// The topic.
        topic: String,
        /// Zero-based index of the first message that differs.
        index: usize,
        /// Its size.
        found: Resolution,
        /// The first message's size.
        first: Resolution,
    },
    /// The topic's messages are serialized in an encoding evtac does not read.
    #[error(
        "topic {topic}: its messages are `{encoding}`-encoded; evtac reads `cdr` (ROS 2) and \
         `ros1`"
    )]
    MessageEncoding {
        /// The topic.
        topic: String,
        /// The channel's message encoding.
        encoding: String,
    },
    /// The folder is a rosbag2 bag in a storage other than MCAP, or holds no bag.
    #[error("{what}")]
    Folder {
        /// What was found.
        what: String,
    },
    /// A fuzzing run's cap on decompressed message bytes was reached.
    #[error("more than {limit} bytes of messages (the fuzzing cap)")]
    TooLarge {
        /// The cap.
        limit: u64,
    },
}

/// What a message type is to evtac.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    EventArray,
    EventPacket,
    Imu,
    Other,
}

impl Kind {
    /// The kind of `message_type` (ROS 1 `pkg/Type` or ROS 2 `pkg/msg/Type`).
    fn of(message_type: &str) -> Self {
        let canonical = message_type.replacen("/msg/", "/", 1);
        match canonical.as_str() {
            "dvs_msgs/EventArray" => Self::EventArray,
            "event_camera_msgs/EventPacket" => Self::EventPacket,
            "sensor_msgs/Imu" => Self::Imu,
            _ => Self::Other,
        }
    }

    fn is_events(self) -> bool {
        matches!(self, Self::EventArray | Self::EventPacket)
    }
}

/// Where a message is in the file, for errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Place {
    /// The message's record starts at this byte offset.
    Record(u64),
    /// It is inside the compressed chunk that starts at this byte offset.
    Chunk(u64),
    /// The container reader does not say.
    Unknown,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Record(offset) => write!(f, " (record at byte offset {offset})"),
            Self::Chunk(offset) => write!(f, " (in the compressed chunk at byte offset {offset})"),
            Self::Unknown => Ok(()),
        }
    }
}

/// One message kept by a scan, and where its bytes are.
#[derive(Debug, Clone)]
struct Kept {
    time_ns: u64,
    bytes: Bytes,
    place: Place,
}

/// Where a kept message's bytes are in the collector.
#[derive(Debug, Clone)]
enum Bytes {
    /// In a file of the bag read whole (a ROS 1 message outside compressed chunks).
    File(usize, Range<usize>),
    /// Copied into a block (a message from a compressed chunk, or from the MCAP reader, whose
    /// buffer is reused).
    Block(usize, Range<usize>),
}

/// A topic found by a scan, with the messages kept from it.
#[derive(Debug)]
struct Topic {
    info: TopicInfo,
    kind: Kind,
    /// The message encoding (`ros1`, `cdr`, ...).
    encoding: String,
    messages: Vec<Kept>,
}

impl Topic {
    fn msg_encoding(&self) -> Result<msg::Encoding, RosError> {
        match self.encoding.as_str() {
            "ros1" => Ok(msg::Encoding::Ros1),
            "cdr" => Ok(msg::Encoding::Cdr),
            other => Err(RosError::MessageEncoding {
                topic: self.info.name.clone(),
                encoding: other.to_string(),
            }),
        }
    }

    /// The indexes of the kept messages in receive-time order (ties in file order).
    fn in_order(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.messages.len()).collect();
        order.sort_by_key(|&i| self.messages[i].time_ns);
        order
    }

    fn message_error(&self, index: usize, place: Place, what: impl fmt::Display) -> RosError {
        RosError::Message {
            topic: self.info.name.clone(),
            index,
            place: place.to_string(),
            what: what.to_string(),
        }
    }
}

/// Gathers topics and messages while a container is scanned.
///
/// Message bytes are not gathered into one growing buffer per topic: its reallocations copied
/// every byte again and again, and with the page faults of the fresh memory they were most of
/// the time a bag took to read. A message inside a file read whole is kept as a range of that
/// file; the others are copied into blocks that are filled and never moved.
#[derive(Debug)]
pub(crate) struct Collector {
    topics: Vec<Topic>,
    by_name: HashMap<(String, String), usize>,
    /// Whether the bytes of event and IMU messages are kept (else only counted).
    keep: bool,
    /// Cap on the bytes kept (fuzzing), and the bytes kept so far.
    limit: u64,
    kept: u64,
    /// The files read whole so far, and the addresses of the one being scanned (a message
    /// whose bytes lie there is kept as a range of it).
    files: Vec<Vec<u8>>,
    scanning: Range<usize>,
    /// Copied message bytes.
    blocks: Vec<Vec<u8>>,
}

/// Bytes per block of copied messages (a longer message gets a block of its own size).
const BLOCK: usize = 1 << 20;

impl Collector {
    fn new(keep: bool, limit: u64) -> Self {
        Self {
            topics: Vec::new(),
            by_name: HashMap::new(),
            keep,
            limit,
            kept: 0,
            files: Vec::new(),
            scanning: 0..0,
            blocks: Vec::new(),
        }
    }

    /// Scans `file` (read whole) with `scan`, keeping messages that lie in it as ranges of it.
    fn scan_file(
        &mut self,
        file: Vec<u8>,
        scan: impl FnOnce(&[u8], &mut Self) -> Result<(), RosError>,
    ) -> Result<(), RosError> {
        let start = file.as_ptr() as usize;
        self.scanning = start..start + file.len();
        let scanned = scan(&file, self);
        self.scanning = 0..0;
        self.files.push(file);
        scanned
    }

    /// The bytes of a kept message.
    fn bytes(&self, kept: &Kept) -> &[u8] {
        match &kept.bytes {
            Bytes::File(i, range) => &self.files[*i][range.clone()],
            Bytes::Block(i, range) => &self.blocks[*i][range.clone()],
        }
    }

    /// Keeps `data`: as a range of the file being scanned when it lies there, else copied.
    fn keep_bytes(&mut self, data: &[u8]) -> Bytes {
        // Addresses compared as numbers only: the range found indexes the file's own bytes.
        let at = data.as_ptr() as usize;
        if self.scanning.start <= at && at + data.len() <= self.scanning.end {
            let start = at - self.scanning.start;
            return Bytes::File(self.files.len(), start..start + data.len());
        }
        let fits = self
            .blocks
            .last()
            .is_some_and(|b| b.capacity() - b.len() >= data.len());
        if !fits {
            // Sized by bytes already in memory, never by a length field.
            self.blocks.push(Vec::with_capacity(BLOCK.max(data.len())));
        }
        let i = self.blocks.len() - 1;
        let block = &mut self.blocks[i];
        let start = block.len();
        block.extend_from_slice(data);
        Bytes::Block(i, start..block.len())
    }

    /// The index of the topic `name` of `message_type` (added on first sight).
    pub(crate) fn topic(&mut self, name: &str, message_type: &str, encoding: &str) -> usize {
        let key = (name.to_string(), message_type.to_string());
        if let Some(&i) = self.by_name.get(&key) {
            return i;
        }
        self.topics.push(Topic {
            info: TopicInfo {
                name: name.to_string(),
                message_type: message_type.to_string(),
                messages: 0,
            },
            kind: Kind::of(message_type),
            encoding: encoding.to_string(),
            messages: Vec::new(),
        });
        self.by_name.insert(key, self.topics.len() - 1);
        self.topics.len() - 1
    }

    /// Counts a message of topic `topic`, keeping its bytes if the topic is one evtac reads.
    pub(crate) fn message(
        &mut self,
        topic: usize,
        time_ns: u64,
        data: &[u8],
        place: Place,
    ) -> Result<(), RosError> {
        self.topics[topic].info.messages += 1;
        if self.keep && self.topics[topic].kind != Kind::Other {
            self.kept += data.len() as u64;
            if self.kept > self.limit {
                return Err(RosError::TooLarge { limit: self.limit });
            }
            let bytes = self.keep_bytes(data);
            self.topics[topic].messages.push(Kept {
                time_ns,
                bytes,
                place,
            });
        }
        Ok(())
    }

    /// The cap on the bytes of messages kept (and of any chunk decompressed).
    pub(crate) fn limit(&self) -> u64 {
        self.limit
    }

    fn infos(&self) -> Vec<TopicInfo> {
        self.topics.iter().map(|t| t.info.clone()).collect()
    }
}

/// The files of the bag at `path`: the file itself, or a rosbag2 folder's `.mcap` files in the
/// order of their split number (`bag_0.mcap`, `bag_1.mcap`, ..., `bag_10.mcap`).
fn bag_files(path: &Path) -> Result<Vec<PathBuf>, Error> {
    if !path.is_dir() {
        return Ok(vec![path.to_path_buf()]);
    }
    let io = |error| Error::Io {
        path: path.to_path_buf(),
        error,
    };
    let mut mcap = Vec::new();
    let mut other = Vec::new();
    for entry in std::fs::read_dir(path).map_err(io)? {
        let file = entry.map_err(io)?.path();
        match file.extension().and_then(|e| e.to_str()) {
            Some("mcap") => mcap.push(file),
            Some("db3") => other.push(file),
            _ => {}
        }
    }
    if mcap.is_empty() {
        let what = if other.is_empty() {
            "a folder with no .mcap file: not a rosbag2 bag in MCAP storage".to_string()
        } else {
            format!(
                "a rosbag2 bag in SQLite storage ({}): evtac reads MCAP storage; convert it with \
                 `ros2 bag convert` (storage_id: mcap)",
                other[0].display()
            )
        };
        return Err(Error::Ros {
            path: path.to_path_buf(),
            error: Box::new(RosError::Folder { what }),
        });
    }
    // Split files end in `_N`: order by N, then by name.
    let split = |p: &PathBuf| {
        p.file_stem()
            .and_then(|s| s.to_str())
            .and_then(|s| s.rsplit_once('_'))
            .and_then(|(_, n)| n.parse::<u64>().ok())
    };
    mcap.sort_by(|a, b| split(a).cmp(&split(b)).then_with(|| a.cmp(b)));
    Ok(mcap)
}

/// Whether the folder at `path` is a rosbag2 bag evtac reads (MCAP storage): its format, or
/// the reason it is not.
pub(crate) fn detect_folder(path: &Path) -> Result<Format, Error> {
    bag_files(path).map(|_| Format::Mcap)
}

/// The total size of the bag's files, in bytes.
pub(crate) fn bag_len(path: &Path) -> Result<u64, Error> {
    let mut len = 0;
    for file in bag_files(path)? {
        len += std::fs::metadata(&file)
            .map_err(|error| Error::Io { path: file, error })?
            .len();
    }
    Ok(len)
}

/// Scans every file of the bag at `path` into one collector: a ROS 1 bag read whole (its
/// messages are kept as ranges of it), MCAP files streamed through their reader.
fn scan(path: &Path, format: Format, keep: bool) -> Result<Collector, Error> {
    let mut c = Collector::new(keep, u64::MAX);
    for file in bag_files(path)? {
        let io = |error| Error::Io {
            path: file.clone(),
            error,
        };
        let scanned = match format {
            Format::RosBag => {
                let bytes = std::fs::read(&file).map_err(io)?;
                c.scan_file(bytes, bag1::scan)
            }
            _ => {
                let f = std::fs::File::open(&file).map_err(io)?;
                let len = f.metadata().map_err(io)?.len();
                // Buffered: the reader asks for a record header, then its body, and so on.
                let source = std::io::BufReader::with_capacity(1 << 16, f);
                mcap2::scan(source, len, &mut c)
            }
        };
        scanned.map_err(|error| Error::Ros {
            path: file,
            error: Box::new(error),
        })?;
    }
    Ok(c)
}

/// The topics of the bag at `path` (a ROS 1 `.bag`, an `.mcap` file or a rosbag2 folder), in
/// the order they first appear, each with its message type and message count.
///
/// ```no_run
/// for t in evtac_formats::ros::topics("run.bag")? {
///     println!("{}: {}, {} messages", t.name, t.message_type, t.messages);
/// }
/// # Ok::<(), evtac_formats::Error>(())
/// ```
pub fn topics(path: impl AsRef<Path>) -> Result<Vec<TopicInfo>, Error> {
    let path = path.as_ref();
    let format = if path.is_dir() {
        detect_folder(path)?
    } else {
        Format::detect(path)?
    };
    if !matches!(format, Format::RosBag | Format::Mcap) {
        return Err(Error::UnknownFormat {
            path: path.to_path_buf(),
            reason: format!("{} is not a ROS bag, so it has no topics", format.name()),
        });
    }
    Ok(scan(path, format, false)?.infos())
}

/// One line per topic: name, type, messages.
fn listing(topics: &[Topic]) -> String {
    if topics.is_empty() {
        return "  (none: the bag holds no messages)".into();
    }
    topics
        .iter()
        .map(|t| {
            format!(
                "  {}: {}, {} messages",
                t.info.name, t.info.message_type, t.info.messages
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Whether `choice` names `topic` (with or without its leading `/`).
fn names(choice: &str, topic: &str) -> bool {
    topic == choice || topic.strip_prefix('/') == Some(choice)
}

/// The event and IMU topics `selection` picks (see the module docs).
fn choose(
    topics: &[Topic],
    selection: &StreamSelection,
) -> Result<(usize, Option<usize>), SelectionError> {
    let fail = |reason: String| SelectionError {
        reason,
        listing: listing(topics),
    };
    if let Some(c) = &selection.triggers {
        return Err(fail(format!(
            "--trigger-stream {c}: a bag has no trigger topic to choose; its triggers are the \
             EXT_TRIGGER words of the event topic's EVT3 packets"
        )));
    }
    let events = pick(
        topics,
        selection.events.as_ref(),
        Kind::is_events,
        "events (dvs_msgs/EventArray or event_camera_msgs/EventPacket)",
        "event",
        "--stream",
        None,
    )
    .map_err(fail)?
    .ok_or_else(|| {
        fail(
            "the bag has no event topic (dvs_msgs/EventArray or event_camera_msgs/EventPacket)"
                .into(),
        )
    })?;
    let namespace = topics[events].info.name.rsplit_once('/').map(|(ns, _)| ns);
    let imu = pick(
        topics,
        selection.imu.as_ref(),
        |k| k == Kind::Imu,
        "IMU samples (sensor_msgs/Imu)",
        "IMU",
        "--imu-stream",
        namespace,
    )
    .map_err(fail)?;
    Ok((events, imu))
}

/// The one topic `choice` names, of a kind `wanted` accepts; else the only such topic (of
/// `namespace`, when several); `None` when there is none and none was named.
fn pick(
    topics: &[Topic],
    choice: Option<&StreamChoice>,
    wanted: impl Fn(Kind) -> bool,
    holds: &str,
    what: &str,
    flag: &str,
    namespace: Option<&str>,
) -> Result<Option<usize>, String> {
    let of_kind: Vec<usize> = (0..topics.len())
        .filter(|&i| wanted(topics[i].kind))
        .collect();
    match choice {
        Some(StreamChoice::Id(id)) => Err(format!(
            "{flag} {id}: a bag's topics are chosen by name, not by number"
        )),
        Some(StreamChoice::Name(name)) => {
            let named: Vec<usize> = (0..topics.len())
                .filter(|&i| names(name, &topics[i].info.name))
                .collect();
            match named.iter().find(|&&i| wanted(topics[i].kind)) {
                Some(&i) => Ok(Some(i)),
                None => match named.first() {
                    Some(&i) => Err(format!(
                        "{flag} {name}: the topic holds {}, not {holds}",
                        topics[i].info.message_type
                    )),
                    None => Err(format!("{flag} {name}: the bag has no topic of that name")),
                },
            }
        }
        None => match of_kind.as_slice() {
            [] => Ok(None),
            [one] => Ok(Some(*one)),
            several => {
                let local: Vec<usize> = several
                    .iter()
                    .copied()
                    .filter(|&i| {
                        namespace.is_some_and(|ns| {
                            topics[i].info.name.rsplit_once('/').map(|(n, _)| n) == Some(ns)
                        })
                    })
                    .collect();
                match local.as_slice() {
                    [one] => Ok(Some(*one)),
                    _ => Err(format!(
                        "the bag has {} {what} topics: pick one with {flag} TOPIC",
                        several.len()
                    )),
                }
            }
        },
    }
}

/// A bag read for one event topic (and its IMU topic).
#[derive(Debug)]
pub(crate) struct BagRecording {
    /// The event topic, decoded as its chunks are asked for, with the IMU samples.
    pub events: BagEvents,
    pub topics: Vec<TopicInfo>,
    /// Which topics were read, and what their times are.
    pub note: String,
}

/// Reads the bag at `path` (of `format`): the event and IMU topics `selection` picks.
pub(crate) fn read(
    path: &Path,
    format: Format,
    selection: &StreamSelection,
) -> Result<BagRecording, Error> {
    let c = scan(path, format, true)?;
    let (event_topic, imu_topic) =
        choose(&c.topics, selection).map_err(|error| Error::Streams {
            path: path.to_path_buf(),
            error,
        })?;
    let ros = |error| Error::Ros {
        path: path.to_path_buf(),
        error: Box::new(error),
    };
    let decoder = Decoder::new(&c, event_topic).map_err(ros)?;
    let imu = match imu_topic {
        Some(i) => decode_imu(&c, i).map_err(ros)?,
        None => Vec::new(),
    };
    let describe = |t: &Topic| {
        format!(
            "{} ({}, {} messages)",
            t.info.name, t.info.message_type, t.info.messages
        )
    };
    let mut note = format!(
        "{}: events from {}",
        format.name(),
        describe(&c.topics[event_topic])
    );
    match imu_topic {
        Some(i) => {
            note += &format!(
                "; IMU from {} (sensor_msgs/Imu has no temperature: it reads NaN)",
                describe(&c.topics[i])
            );
        }
        None => note += "; no IMU topic",
    }
    if c.topics[event_topic].kind == Kind::EventPacket {
        note += "; EventPacket times are the camera's own clock (EVT3: its sensor counter), \
                 not ROS time";
        if imu_topic.is_some() {
            note += ", while IMU times are ROS header stamps";
        }
    }
    if decoder.stated().is_none() {
        note += "; the event messages state no sensor size (0x0)";
    }
    let topics = c.infos();
    Ok(BagRecording {
        events: BagEvents::new(c, decoder, imu),
        topics,
        note,
    })
}

/// Decodes the IMU topic `topic` of `c`: one sample per message, ordered by header stamp
/// (stable).
fn decode_imu(c: &Collector, topic: usize) -> Result<Vec<ImuSample>, RosError> {
    let topic = &c.topics[topic];
    let encoding = topic.msg_encoding()?;
    let mut samples = Vec::with_capacity(topic.messages.len());
    for (index, i) in topic.in_order().into_iter().enumerate() {
        let m = &topic.messages[i];
        let sample =
            msg::imu(c.bytes(m), encoding).map_err(|e| topic.message_error(index, m.place, e))?;
        samples.push(sample);
    }
    samples.sort_by_key(|s| s.t);
    Ok(samples)
}

/// Decodes every event topic of `c` a message at a time, as a reader would: the events and
/// triggers decoded, or 0 at the first error.
fn decode_all(c: &Collector, topic: usize) -> usize {
    let Ok(mut decoder) = Decoder::new(c, topic) else {
        return 0;
    };
    let (mut events, mut triggers) = (Vec::new(), Vec::new());
    let mut n = 0;
    loop {
        match decoder.decode_next(c, &mut events, &mut triggers) {
            Ok(true) => {
                n += events.len() + triggers.len();
                events.clear();
                triggers.clear();
            }
            Ok(false) => return n,
            Err(_) => return 0,
        }
    }
}

/// Decodes `data` as a bag of `format` in memory: every event topic and every IMU topic, with
/// at most a mebibyte of messages kept (so a small input cannot decompress into gigabytes).
fn fuzz(data: &[u8], format: Format) -> usize {
    let mut c = Collector::new(true, 1 << 20);
    let scanned = match format {
        Format::RosBag => c.scan_file(data.to_vec(), bag1::scan),
        _ => mcap2::scan(data, data.len() as u64, &mut c),
    };
    if scanned.is_err() {
        return 0;
    }
    let mut n = 0;
    for (i, topic) in c.topics.iter().enumerate() {
        n += match topic.kind {
            Kind::EventArray | Kind::EventPacket => decode_all(&c, i),
            Kind::Imu => decode_imu(&c, i).map_or(0, |s| s.len()),
            Kind::Other => 0,
        };
    }
    n
}

/// The fuzzing entry point for ROS 1 bags: scans `data` as a `.bag` and decodes every event
/// and IMU topic in it (nothing on disk). Returns the elements decoded.
pub fn fuzz_decode_rosbag(data: &[u8]) -> usize {
    fuzz(data, Format::RosBag)
}

/// The fuzzing entry point for MCAP: scans `data` as an `.mcap` file and decodes every event
/// and IMU topic in it (nothing on disk). Returns the elements decoded.
pub fn fuzz_decode_mcap(data: &[u8]) -> usize {
    fuzz(data, Format::Mcap)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn topic(name: &str, message_type: &str) -> Topic {
        Topic {
            info: TopicInfo {
                name: name.into(),
                message_type: message_type.into(),
                messages: 3,
            },
            kind: Kind::of(message_type),
            encoding: "cdr".into(),
            messages: Vec::new(),
        }
    }

    fn stereo() -> Vec<Topic> {
        vec![
            topic("/cam0/events", "event_camera_msgs/msg/EventPacket"),
            topic("/cam0/imu", "sensor_msgs/msg/Imu"),
            topic("/cam1/events", "dvs_msgs/msg/EventArray"),
            topic("/cam1/imu", "sensor_msgs/msg/Imu"),
            topic("/tf", "tf2_msgs/msg/TFMessage"),
        ]
    }

    #[test]
    fn the_event_topic_is_named_or_the_only_one() {
        let topics = stereo();
        let err = choose(&topics, &StreamSelection::default()).unwrap_err();
        assert!(err.reason.contains("2 event topics"), "{err}");
        assert!(
            err.to_string()
                .contains("/cam1/events: dvs_msgs/msg/EventArray, 3 messages"),
            "{err}"
        );
        for (name, want) in [
            ("/cam1/events", (2, Some(3))),
            ("cam0/events", (0, Some(1))),
        ] {
            let sel = StreamSelection {
                events: Some(name.parse().unwrap()),
                ..Default::default()
            };
            assert_eq!(choose(&topics, &sel).unwrap(), want, "{name}");
        }
        let sel = StreamSelection {
            events: Some("/cam1/events".parse().unwrap()),
            imu: Some("/cam0/imu".parse().unwrap()),
            ..Default::default()
        };
        assert_eq!(choose(&topics, &sel).unwrap(), (2, Some(1)));
    }

    #[test]
    fn a_wrong_or_missing_topic_is_an_error_naming_it() {
        let topics = stereo();
        let sel = |events: &str, imu: Option<&str>| StreamSelection {
            events: Some(events.parse().unwrap()),
            imu: imu.map(|i| i.parse().unwrap()),
            ..Default::default()
        };
        let err = choose(&topics, &sel("/cam0/imu", None)).unwrap_err();
        assert!(
            err.reason
                .contains("--stream /cam0/imu: the topic holds sensor_msgs/msg/Imu, not events"),
            "{err}"
        );
        let err = choose(&topics, &sel("/nope", None)).unwrap_err();
        assert!(err.reason.contains("no topic of that name"), "{err}");
        let err = choose(&topics, &sel("/cam0/events", Some("/tf"))).unwrap_err();
        assert!(err.reason.contains("--imu-stream /tf"), "{err}");
        let err = choose(&topics, &sel("1", None)).unwrap_err();
        assert!(err.reason.contains("by name"), "{err}");
        let err = choose(&topics[4..], &StreamSelection::default()).unwrap_err();
        assert!(err.reason.contains("no event topic"), "{err}");
    }

    #[test]
    fn message_types_of_both_ros_versions_are_known() {
        assert_eq!(Kind::of("dvs_msgs/EventArray"), Kind::EventArray);
        assert_eq!(Kind::of("dvs_msgs/msg/EventArray"), Kind::EventArray);
        assert_eq!(
            Kind::of("event_camera_msgs/msg/EventPacket"),
            Kind::EventPacket
        );
        assert_eq!(Kind::of("sensor_msgs/Imu"), Kind::Imu);
        assert_eq!(Kind::of("sensor_msgs/msg/Image"), Kind::Other);
    }
}
