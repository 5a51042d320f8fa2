//! Logging estimates to an MCAP file, the log format of ROS 2 (`rosbag2`'s default storage) and
//! Foxglove.
//!
//! A run's estimates are worth keeping beside the other signals of an experiment: the CSV output
//! holds them, but robotics tools want a log they can open, plot against time and replay. An
//! MCAP log ([`McapLog`], `evtac online --mcap FILE`) holds exactly what [`crate::ros2`]
//! publishes, so Foxglove plots it, `rosbags` (Python) reads it and `ros2 bag play` replays it
//! onto the topic as if evtac were running:
//!
//! - one channel, on the ROS 2 topic `/contact_angle` (or the one given), message encoding
//!   `cdr`;
//! - its schema is named `geometry_msgs/msg/Vector3Stamped` ([`MSG_TYPE`]), schema encoding
//!   `ros2msg`, the `.msg` text with its dependencies `std_msgs/Header`,
//!   `builtin_interfaces/Time` and `geometry_msgs/Vector3` ([`MSG_DEFINITION`]), as `rosbag2`
//!   writes it; the file's profile is `ros2`;
//! - each message is [`Vector3Stamped::from_estimate`] (`x` = pitch, `y` = roll in radians,
//!   `z` = 0, `header.stamp` = the estimate's `t_us`) serialized by the same CDR serializer the
//!   DDS publisher uses ([`Vector3Stamped::to_cdr`]: the encapsulation header `00 01 00 00`, then
//!   little-endian CDR);
//! - its log time and publish time are the estimate's `t_us` in nanoseconds: the event time, as
//!   the stamp (an MCAP time is unsigned, so an estimate before the clock's zero is an error);
//! - with [`McapLog::add_reference`], more channels of the same type beside it
//!   (`/contact_angle/label`, `/contact_angle/truth`: a replayed dataset trial's labels and the
//!   simulator's truth at each estimate's time), so Foxglove plots the estimate against them;
//! - with [`McapLog::write_frames`] (`--mcap-frames HZ`), the representation's binary frames
//!   ([`crate::frames`]) as `sensor_msgs/msg/Image` ([`crate::image_msg`], `mono8`, 0 and 255)
//!   on `<topic>/frames/static`, `/dynamic` and `/combined` (the parts the model has), stamped
//!   and logged at the estimate's time they were taken at;
//! - chunks are zstd-compressed on the calling thread (no compression threads), with the
//!   summary, chunk and message indexes readers seek with.
//!
//! The file is written as every evtac output: under a temporary name beside its final one,
//! renamed by [`McapLog::finish`] once complete ([`OutputFile`]), so a failed or killed run
//! leaves no truncated log under the final name; and never over one of the run's inputs
//! ([`refuse_input`]).

use crate::estimator::Estimate;
use crate::frames::{FrameSet, Part};
use crate::image_msg::{IMAGE_DEFINITION, IMAGE_TYPE, Image};
use crate::ros2::{MSG_DEFINITION, MSG_TYPE, Vector3, Vector3Stamped};
use evtac_events::output::{OutputFile, OutputIsInput, refuse_input};
use mcap::records::MessageHeader;
use mcap::{Compression, WriteOptions, Writer};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The channel's message encoding.
pub const MESSAGE_ENCODING: &str = "cdr";

/// The schema's encoding.
pub const SCHEMA_ENCODING: &str = "ros2msg";

/// The MCAP profile of ROS 2 logs (`rosbags` refuses a file without it).
pub const PROFILE: &str = "ros2";

/// The topic when none is given (the ROS 2 publisher's default).
pub const DEFAULT_TOPIC: &str = "/contact_angle";

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The log would overwrite an input.
    #[error(transparent)]
    OutputIsInput(#[from] OutputIsInput),
    /// The file could not be created, written or renamed.
    #[error("writing the MCAP log {}: {source}", path.display())]
    Io {
        /// The log's final path.
        path: PathBuf,
        /// What failed.
        #[source]
        source: std::io::Error,
    },
    /// The MCAP writer failed.
    #[error("writing the MCAP log {}: {source}", path.display())]
    Mcap {
        /// The log's final path.
        path: PathBuf,
        /// What the `mcap` crate said.
        #[source]
        source: mcap::McapError,
    },
    /// The message could not be serialized.
    #[error("serializing an estimate for the MCAP log: {0}")]
    Serialize(#[source] rustdds::serialization::Error),
    /// An estimate before the clock's zero has no MCAP time.
    #[error(
        "the estimate at t = {t_us} us is before the clock's zero: MCAP log times are unsigned"
    )]
    NegativeTime {
        /// The estimate's time.
        t_us: i64,
    },
}

/// What else is known of the angles at a time, logged beside each estimate: `(pitch_deg,
/// roll_deg)` at `t_us` (a replayed dataset trial's labels, or the simulator's truth).
pub type Reference = Box<dyn Fn(i64) -> (f64, f64) + Send>;

/// An MCAP log of estimates being written (see the module docs).
pub struct McapLog {
    writer: Writer<BufWriter<OutputFile>>,
    path: PathBuf,
    schema: u16,
    topic: String,
    channel: u16,
    /// The reference channels, each with its angles.
    references: Vec<(u16, Reference)>,
    /// The image schema and a channel per frame part, added with the first frames.
    image_schema: Option<u16>,
    frame_channels: BTreeMap<Part, u16>,
    frame_sets: u32,
    frame_id: String,
    sequence: u32,
    buf: Vec<u8>,
}

impl std::fmt::Debug for McapLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapLog")
            .field("path", &self.path)
            .field("frame_id", &self.frame_id)
            .field("written", &self.sequence)
            .finish_non_exhaustive()
    }
}

impl McapLog {
    /// Starts the log `path` with one channel on `topic` whose messages have `header.frame_id`
    /// `frame_id`; refuses a `path` that is one of `inputs`. Nothing appears under `path` before
    /// [`finish`](Self::finish).
    pub fn create<P: AsRef<Path>>(
        path: &Path,
        inputs: &[P],
        topic: &str,
        frame_id: &str,
    ) -> Result<Self, Error> {
        refuse_input(path, inputs)?;
        let io = |source| Error::Io {
            path: path.to_owned(),
            source,
        };
        let mcap = |source| Error::Mcap {
            path: path.to_owned(),
            source,
        };
        let file = OutputFile::buffered(path).map_err(io)?;
        let mut writer = WriteOptions::new()
            .profile(PROFILE)
            .library(format!("evtac {}", env!("CARGO_PKG_VERSION")))
            .compression(Some(Compression::Zstd))
            .compression_threads(0)
            .create(file)
            .map_err(mcap)?;
        let schema = writer
            .add_schema(MSG_TYPE, SCHEMA_ENCODING, MSG_DEFINITION.as_bytes())
            .map_err(mcap)?;
        let channel = writer
            .add_channel(schema, topic, MESSAGE_ENCODING, &BTreeMap::new())
            .map_err(mcap)?;
        Ok(Self {
            writer,
            path: path.to_owned(),
            schema,
            topic: topic.to_owned(),
            channel,
            references: Vec::new(),
            image_schema: None,
            frame_channels: BTreeMap::new(),
            frame_sets: 0,
            frame_id: frame_id.to_owned(),
            sequence: 0,
            buf: Vec::with_capacity(128),
        })
    }

    /// Adds a channel `<topic>/<name>` (e.g. `/contact_angle/label`) of the same message type,
    /// on which every estimate written from now on is accompanied by `reference`'s angles at its
    /// time, so that a plot shows the estimate against what it estimates.
    pub fn add_reference(&mut self, name: &str, reference: Reference) -> Result<(), Error> {
        let topic = format!("{}/{name}", self.topic.trim_end_matches('/'));
        let channel = self
            .writer
            .add_channel(self.schema, &topic, MESSAGE_ENCODING, &BTreeMap::new())
            .map_err(|source| Error::Mcap {
                path: self.path.clone(),
                source,
            })?;
        self.references.push((channel, reference));
        Ok(())
    }

    /// Appends `estimate` as a message (see the module docs), and each reference's angles at
    /// its time.
    pub fn write(&mut self, estimate: &Estimate) -> Result<(), Error> {
        let time_ns = log_time(estimate.t_us)?;
        self.sequence = self.sequence.wrapping_add(1);
        let message = Vector3Stamped::from_estimate(estimate, &self.frame_id);
        self.append(self.channel, &message, time_ns)?;
        for k in 0..self.references.len() {
            // The reference's own precision (f64), not the estimate's f32.
            let (pitch_deg, roll_deg) = (self.references[k].1)(estimate.t_us);
            let reference = Vector3Stamped {
                vector: Vector3 {
                    x: pitch_deg.to_radians(),
                    y: roll_deg.to_radians(),
                    z: 0.0,
                },
                ..message.clone()
            };
            self.append(self.references[k].0, &reference, time_ns)?;
        }
        Ok(())
    }

    /// Appends `frames` as one image per part, on `<topic>/frames/<part>` (see the module
    /// docs).
    pub fn write_frames(&mut self, frames: &FrameSet) -> Result<(), Error> {
        let time_ns = log_time(frames.t_us)?;
        let mcap = |path: &Path| {
            let path = path.to_owned();
            move |source| Error::Mcap { path, source }
        };
        let schema = match self.image_schema {
            Some(schema) => schema,
            None => {
                let schema = self
                    .writer
                    .add_schema(IMAGE_TYPE, SCHEMA_ENCODING, IMAGE_DEFINITION.as_bytes())
                    .map_err(mcap(&self.path))?;
                *self.image_schema.insert(schema)
            }
        };
        self.frame_sets = self.frame_sets.wrapping_add(1);
        for frame in &frames.frames {
            let channel = match self.frame_channels.get(&frame.part) {
                Some(&channel) => channel,
                None => {
                    let topic = format!(
                        "{}/frames/{}",
                        self.topic.trim_end_matches('/'),
                        frame.part.name()
                    );
                    let channel = self
                        .writer
                        .add_channel(schema, &topic, MESSAGE_ENCODING, &BTreeMap::new())
                        .map_err(mcap(&self.path))?;
                    self.frame_channels.insert(frame.part, channel);
                    channel
                }
            };
            let image = Image::from_frame(frame, frames.t_us, &self.frame_id);
            self.buf.clear();
            image.to_cdr(&mut self.buf).map_err(Error::Serialize)?;
            self.write_buf(channel, self.frame_sets, time_ns)?;
        }
        Ok(())
    }

    /// Appends `message` to `channel` at `time_ns`.
    fn append(
        &mut self,
        channel: u16,
        message: &Vector3Stamped,
        time_ns: u64,
    ) -> Result<(), Error> {
        self.buf.clear();
        message.to_cdr(&mut self.buf).map_err(Error::Serialize)?;
        self.write_buf(channel, self.sequence, time_ns)
    }

    /// Appends the serialized message in `buf` to `channel` at `time_ns`.
    fn write_buf(&mut self, channel: u16, sequence: u32, time_ns: u64) -> Result<(), Error> {
        let header = MessageHeader {
            channel_id: channel,
            sequence,
            log_time: time_ns,
            publish_time: time_ns,
        };
        self.writer
            .write_to_known_channel(&header, &self.buf)
            .map_err(|source| Error::Mcap {
                path: self.path.clone(),
                source,
            })
    }

    /// Frame sets written so far (modulo 2^32).
    pub fn frame_sets_written(&self) -> u32 {
        self.frame_sets
    }

    /// Messages written so far (modulo 2^32).
    pub fn written(&self) -> u32 {
        self.sequence
    }

    /// Writes the summary and footer and renames the file to its final name.
    pub fn finish(mut self) -> Result<(), Error> {
        self.writer.finish().map_err(|source| Error::Mcap {
            path: self.path.clone(),
            source,
        })?;
        OutputFile::commit_buffered(self.writer.into_inner()).map_err(|source| Error::Io {
            path: self.path,
            source,
        })
    }
}

/// The MCAP log time of `t_us`: nanoseconds, unsigned.
fn log_time(t_us: i64) -> Result<u64, Error> {
    u64::try_from(t_us)
        .ok()
        .and_then(|us| us.checked_mul(1000))
        .ok_or(Error::NegativeTime { t_us })
}
