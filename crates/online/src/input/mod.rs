//! Inputs: anything that yields chunks of events in time order.
//!
//! [`EventSource`] is the one interface the ingestion thread pulls from. Implementations: a
//! recording on disk ([`FileSource`]), a live DV network stream with reconnection
//! ([`NetworkSource`]), a ROS 2 event topic over DDS ([`Ros2Source`]), standard input
//! ([`StdinSource`]), events in memory ([`MemorySource`]), and [`Paced`], which replays any of
//! them at recorded pace.

mod file;
mod memory;
mod network;
mod paced;
mod ros2;
mod spec;
mod stdin;

pub use file::FileSource;
pub use memory::MemorySource;
pub use network::{NetworkOptions, NetworkSource};
pub use paced::Paced;
pub use ros2::{Ros2InputOptions, Ros2InputReport, Ros2InputStats, Ros2Source};
pub use spec::{Error as SpecError, SourceSpec};
pub use stdin::StdinSource;

use crate::Notice;
use evtac_events::{Event, Resolution};

/// What a source says about the chunk it just delivered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ChunkInfo {
    /// When the source knows it: every event with `t <= horizon` has now been delivered
    /// (beyond what the events themselves show: an event at `t` proves all before `t`).
    pub horizon: Option<i64>,
}

/// What [`EventSource::next_chunk`] returns: the chunk's [`ChunkInfo`], `None` at the end of
/// the stream.
pub type Next = Result<Option<ChunkInfo>, InputError>;

/// A stream of event chunks.
///
/// The caller owns the buffer a chunk lands in (the pipeline recycles a pool of them), so a
/// source never allocates per chunk and never hands out a borrow of its own state.
pub trait EventSource: Send {
    /// Replaces the contents of `out` with the next chunk of events (full-sensor coordinates,
    /// time order; possibly empty); `Ok(None)` at the end of the stream. May block until data
    /// arrives. `notify` receives state changes worth telling the user (e.g. a reconnection).
    fn next_chunk(&mut self, out: &mut Vec<Event>, notify: &mut dyn FnMut(Notice)) -> Next;
}

impl<S: EventSource + ?Sized> EventSource for Box<S> {
    fn next_chunk(&mut self, out: &mut Vec<Event>, notify: &mut dyn FnMut(Notice)) -> Next {
        (**self).next_chunk(out, notify)
    }
}

/// Errors of the inputs.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputError {
    /// Reading or decoding a recording failed.
    #[error("reading {input}: {source}")]
    Events {
        /// The input.
        input: String,
        /// What failed.
        #[source]
        source: evtac_formats::Error,
    },
    /// An I/O error outside the event decoders (standard input, sockets).
    #[error("reading {input}: {source}")]
    Io {
        /// The input.
        input: String,
        /// What failed.
        #[source]
        source: std::io::Error,
    },
    /// A network input could not be reached at all.
    #[error("could not connect to {input}: {reason}")]
    Connect {
        /// The input.
        input: String,
        /// The last failure.
        reason: String,
    },
    /// The input's format could not be recognised.
    #[error("{input}: {reason}")]
    Format {
        /// The input.
        input: String,
        /// What was expected and found.
        reason: String,
    },
}

/// How an input named on the command line is opened.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct OpenOptions {
    /// Replay a file at recorded pace ([`Paced`]) instead of as fast as possible.
    pub realtime: bool,
    /// Slice length of a paced replay, in microseconds of event time (0: 1000).
    pub slice_us: i64,
    /// Sensor size for inputs that do not state it (CSV, NPY); checked against those that do.
    pub sensor: Option<Resolution>,
    /// Connection and reconnection of network inputs; for a ROS 2 topic, the stall timeout
    /// and the attempts to wait for it.
    pub network: NetworkOptions,
    /// Domain, interfaces and message type of a ROS 2 input.
    pub ros2: Ros2InputOptions,
    /// Which streams of an AEDAT4 file with several (two cameras) to replay.
    pub streams: evtac_formats::StreamSelection,
}

/// An opened input: the source and the sensor size it announced.
pub struct Opened {
    /// The stream of chunks.
    pub source: Box<dyn EventSource>,
    /// The sensor size (from the input, else the declared one), if known.
    pub resolution: Option<Resolution>,
    /// For a ROS 2 input, its samples, losses and skips, readable while and after it runs.
    pub ros2_input: Option<Ros2InputReport>,
}

impl std::fmt::Debug for Opened {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Opened")
            .field("resolution", &self.resolution)
            .finish_non_exhaustive()
    }
}

/// Opens `spec`: a file (paced when `options.realtime`), a network stream (connected, header
/// read, with retries), a ROS 2 topic (its publisher found and its first sample received, with
/// retries), or standard input. `notify` hears about connection attempts.
pub fn open(
    spec: &SourceSpec,
    options: &OpenOptions,
    notify: &mut dyn FnMut(Notice),
) -> Result<Opened, InputError> {
    let slice_us = if options.slice_us > 0 {
        options.slice_us
    } else {
        1000
    };
    let pace = |source: Box<dyn EventSource>| -> Box<dyn EventSource> {
        if options.realtime {
            Box::new(Paced::new(source, slice_us))
        } else {
            source
        }
    };
    Ok(match spec {
        SourceSpec::File(path) => {
            let source = FileSource::open(path, options.sensor, &options.streams)?;
            let resolution = source.resolution().or(options.sensor);
            Opened {
                source: pace(Box::new(source)),
                resolution,
                ros2_input: None,
            }
        }
        SourceSpec::Tcp { host, port } => {
            let source = NetworkSource::connect(host, *port, options.network, notify)?;
            let resolution = stated(source.name(), options.sensor, source.resolution())?;
            Opened {
                source: Box::new(source),
                resolution,
                ros2_input: None,
            }
        }
        SourceSpec::Ros2 { topic } => {
            let source = Ros2Source::open(topic, options.ros2.clone(), options.network, notify)?;
            let resolution = stated(source.name(), options.sensor, source.resolution())?;
            Opened {
                ros2_input: Some(source.report()),
                source: Box::new(source),
                resolution,
            }
        }
        SourceSpec::Stdin => {
            let source = StdinSource::open(options.sensor)?;
            let resolution = source.resolution();
            Opened {
                source: pace(Box::new(source)),
                resolution,
                ros2_input: None,
            }
        }
    })
}

/// The sensor size of a live input: the one it states, checked against a declared one, else the
/// declared one.
fn stated(
    input: &str,
    declared: Option<Resolution>,
    found: Option<Resolution>,
) -> Result<Option<Resolution>, InputError> {
    if let (Some(declared), Some(found)) = (declared, found)
        && declared != found
    {
        return Err(InputError::Format {
            input: input.to_string(),
            reason: format!("the stream says the sensor is {found}, but {declared} was given"),
        });
    }
    Ok(found.or(declared))
}
