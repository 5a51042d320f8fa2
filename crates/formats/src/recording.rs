//! The whole-file API: open any supported event file by its path, stream it in chunks
//! ([`EventReader`]) or read it whole ([`read_recording`]), and write events to any writable
//! format ([`EventWriter`]).
//!
//! The format is recognised by the file's first bytes (AEDAT4, NPY, HDF5 and MCAP magic,
//! `#!AER-DAT2.0` / `#!AER-DAT3.1` header, EVT `%` header, `#ROSBAG V2.0`, a NeuroTac pickle's
//! opening; a folder is a rosbag2 bag) and otherwise by its extension (`.csv`; `.npz` for a zip). Every reader validates what it decodes: events
//! inside the declared resolution and timestamps that never go backwards.
//!
//! [`EventReader::select_range`] (and [`read_recording_range`]) read a time range `[from, to)`:
//! AEDAT4 files through their data table, touching only the packets in the range; the other
//! formats, which have no index, by reading up to the range's end.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read};
use std::path::{Path, PathBuf};

use crate::aedat::{AedatReader, AedatWriter, StreamSelection, WriterConfig};
use crate::aedat_legacy::{self, LegacyReader};
use crate::check::EventCheck;
use crate::csv::{CsvReader, CsvWriter};
use crate::evt::{EvtReader, EvtVersion};
use crate::hdf5::Hdf5Reader;
use crate::npy::npz::{NpzError, NpzReader};
use crate::npy::{NpyReader, NpyWriter};
use crate::range::{RangeIndex, ScanReason, within};
use crate::ros::BagEvents;
use crate::{Error, Event, ImuSample, Resolution, Trigger};
use evtac_events::output::OutputFile;

/// The event file formats evtac knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Format {
    /// iniVation AEDAT 4.0 (`.aedat4`): events, IMU and triggers.
    Aedat4,
    /// jAER AEDAT 2.0 (`.aedat`) from a DAVIS240 or DAVIS346: polarity events, read only.
    Aedat2,
    /// cAER AEDAT 3.1 (`.aedat`): polarity events, IMU6 and triggers, read only.
    Aedat31,
    /// Prophesee EVT 2.0 raw (`.raw`), read only.
    Evt2,
    /// Prophesee EVT 2.1 raw (`.raw`), read only.
    Evt21,
    /// Prophesee EVT 3.0 raw (`.raw`), read only.
    Evt3,
    /// `t,x,y,p` CSV (`.csv`).
    Csv,
    /// NPY with an event record dtype, `t <i8, x <i2, y <i2, p u1` as evtac writes it (`.npy`;
    /// other names and integer types read, see [`crate::npy`]).
    Npy,
    /// NPZ: numpy's zip of NPY arrays, one event record array or one array per field
    /// (`.npz`), read only (see [`crate::npy::npz`]).
    Npz,
    /// HDF5 with one dataset per event field (event_utils' and the NeuroTac code's layout, and
    /// DSEC's), read only (see [`crate::hdf5`]).
    Hdf5,
    /// The NeuroTac lab's per-pixel event times (a pickle, or an NPY of Python objects), read
    /// only (see [`crate::neurotac`]).
    Neurotac,
    /// A ROS 1 bag (`.bag`): `dvs_msgs/EventArray` or `event_camera_msgs/EventPacket` events and
    /// `sensor_msgs/Imu`, read only (see [`crate::ros`]).
    RosBag,
    /// A ROS 2 bag in MCAP storage (an `.mcap` file or a rosbag2 folder), with the same messages
    /// as [`Format::RosBag`], read only (see [`crate::ros`]).
    Mcap,
}

impl Format {
    /// The short name shown to users (`AEDAT4`, `AEDAT2`, `AEDAT3.1`, `EVT2`, `EVT21`, `EVT3`,
    /// `CSV`, `NPY`, `NPZ`, `HDF5`, `NeuroTac pickle`, `ROS 1 bag`, `ROS 2 MCAP`).
    pub const fn name(self) -> &'static str {
        match self {
            Self::Aedat4 => "AEDAT4",
            Self::Aedat2 => "AEDAT2",
            Self::Aedat31 => "AEDAT3.1",
            Self::Evt2 => "EVT2",
            Self::Evt21 => "EVT21",
            Self::Evt3 => "EVT3",
            Self::Csv => "CSV",
            Self::Npy => "NPY",
            Self::Npz => "NPZ",
            Self::Hdf5 => "HDF5",
            Self::Neurotac => "NeuroTac pickle",
            Self::RosBag => "ROS 1 bag",
            Self::Mcap => "ROS 2 MCAP",
        }
    }

    /// Whether the format carries the sensor resolution itself (CSV, NPY and NPZ do not; HDF5
    /// does when it has a `sensor_resolution` attribute, which DSEC's files do not).
    pub const fn has_resolution(self) -> bool {
        !matches!(self, Self::Csv | Self::Npy | Self::Npz | Self::Hdf5)
    }

    /// The format an output path's extension asks for: `.aedat4`, `.csv` or `.npy`.
    pub fn for_writing(path: &Path) -> Result<Self, Error> {
        let extension = extension(path);
        match extension.as_str() {
            "aedat4" | "aedat" => Ok(Self::Aedat4),
            "csv" => Ok(Self::Csv),
            "npy" => Ok(Self::Npy),
            "raw" => Err(Error::NotWritable {
                path: path.to_path_buf(),
                format: Self::Evt3,
            }),
            "pickle" | "pkl" => Err(Error::NotWritable {
                path: path.to_path_buf(),
                format: Self::Neurotac,
            }),
            "npz" => Err(Error::NotWritable {
                path: path.to_path_buf(),
                format: Self::Npz,
            }),
            "h5" | "hdf5" => Err(Error::NotWritable {
                path: path.to_path_buf(),
                format: Self::Hdf5,
            }),
            "bag" => Err(Error::NotWritable {
                path: path.to_path_buf(),
                format: Self::RosBag,
            }),
            "mcap" => Err(Error::NotWritable {
                path: path.to_path_buf(),
                format: Self::Mcap,
            }),
            _ => Err(Error::UnknownFormat {
                path: path.to_path_buf(),
                reason: format!("the extension `{extension}` is not .aedat4, .csv or .npy"),
            }),
        }
    }

    /// Recognises the format of the file at `path`: by its first bytes, else by its extension.
    /// A folder is read as a rosbag2 bag (its `.mcap` files).
    pub fn detect(path: &Path) -> Result<Self, Error> {
        let io = |error| Error::Io {
            path: path.to_path_buf(),
            error,
        };
        if path.is_dir() {
            return crate::ros::detect_folder(path);
        }
        let mut head = Vec::with_capacity(64);
        File::open(path)
            .map_err(io)?
            .take(4096)
            .read_to_end(&mut head)
            .map_err(io)?;
        if head.starts_with(crate::aedat::MAGIC) {
            return Ok(Self::Aedat4);
        }
        if head.starts_with(b"\x89HDF\r\n\x1a\n") {
            return Ok(Self::Hdf5);
        }
        // Any `#ROSBAG V` line: the reader names a version other than 2.0.
        if head.starts_with(b"#ROSBAG V") {
            return Ok(Self::RosBag);
        }
        if head.starts_with(crate::ros::MCAP_MAGIC) {
            return Ok(Self::Mcap);
        }
        if crate::neurotac::sniff(&head) {
            return Ok(Self::Neurotac);
        }
        if head.starts_with(crate::npy::MAGIC) {
            return Ok(Self::Npy);
        }
        if let Some(version) = aedat_legacy::sniff(&head) {
            return match version {
                Ok(aedat_legacy::Version::Aedat2) => Ok(Self::Aedat2),
                Ok(aedat_legacy::Version::Aedat31) => Ok(Self::Aedat31),
                Err(version) => Err(Error::AedatLegacy {
                    path: path.to_path_buf(),
                    error: aedat_legacy::LegacyError::UnsupportedVersion { version },
                }),
            };
        }
        if head.starts_with(b"%") {
            // The version needs the whole header, which the EVT reader parses.
            return match EvtReader::new(File::open(path).map_err(io)?) {
                Ok(r) => Ok(match r.header().version {
                    EvtVersion::Evt2 => Self::Evt2,
                    EvtVersion::Evt21 => Self::Evt21,
                    EvtVersion::Evt3 => Self::Evt3,
                }),
                Err(error) => Err(Error::Evt {
                    path: path.to_path_buf(),
                    error,
                }),
            };
        }
        let extension = extension(path);
        // A zip archive is an NPZ when its name says so (a zip may hold anything else).
        if extension == "npz"
            && (head.starts_with(b"PK\x03\x04") || head.starts_with(b"PK\x05\x06"))
        {
            return Ok(Self::Npz);
        }
        match extension.as_str() {
            "csv" => Ok(Self::Csv),
            _ if head.is_empty() => Err(Error::UnknownFormat {
                path: path.to_path_buf(),
                reason: "the file is empty".into(),
            }),
            "aedat4" | "aedat" | "npy" | "npz" | "h5" | "hdf5" | "raw" | "bag" | "mcap" => {
                let signature = match extension.as_str() {
                    "h5" | "hdf5" => "the HDF5 signature `\\x89HDF\\r\\n\\x1a\\n`",
                    "npy" => "the NPY magic `\\x93NUMPY`",
                    "npz" => "the zip magic `PK\\x03\\x04`",
                    "raw" => "a `%` EVT text header line",
                    "bag" => "the ROS 1 bag line `#ROSBAG V2.0`",
                    "mcap" => "the MCAP magic `\\x89MCAP0\\r\\n`",
                    _ => "the AEDAT 4.0 magic `#!AER-DAT4.0\\r\\n`",
                };
                let first = String::from_utf8_lossy(&head[..head.len().min(14)]).into_owned();
                Err(Error::UnknownFormat {
                    path: path.to_path_buf(),
                    reason: format!(
                        "the extension says `.{extension}` but the first bytes (at byte offset \
                         0) are {first:?}, not {signature}"
                    ),
                })
            }
            _ => Err(Error::UnknownFormat {
                path: path.to_path_buf(),
                reason:
                    "no AEDAT4, NPY, HDF5, EVT, ROS bag or MCAP signature, and the extension is \
                         not .csv (nor .npz for a zip)"
                        .into(),
            }),
        }
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// One chunk of a recording: views into the reader's reused buffers, valid until the next call.
/// A chunk may be empty.
#[derive(Debug, Clone, Copy, Default)]
pub struct Chunk<'a> {
    /// Events, in time order.
    pub events: &'a [Event],
    /// IMU samples (AEDAT4, AEDAT 3.1, ROS bags).
    pub imu: &'a [ImuSample],
    /// Triggers (AEDAT4, AEDAT 3.1, EVT, ROS bags' EVT3 packets).
    pub triggers: &'a [Trigger],
}

impl<'a> Chunk<'a> {
    /// The part of the chunk with `from <= t < to`.
    fn within(self, from: i64, to: i64) -> Self {
        Self {
            events: &self.events[within(self.events, |e| e.t, from, to)],
            imu: &self.imu[within(self.imu, |s| s.t, from, to)],
            triggers: &self.triggers[within(self.triggers, |t| t.t, from, to)],
        }
    }
}

enum Inner {
    Aedat(Box<AedatReader<BufReader<File>>>),
    Legacy(Box<LegacyReader<File>>),
    Evt(Box<EvtReader<File>>),
    Csv(Box<CsvReader<BufReader<File>>>),
    Npy(Box<NpyReader<File>>),
    Hdf5(Box<Hdf5Reader>),
    Npz(Box<NpzReader<File>>),
    Bag(Box<BagEvents>),
    Memory(Box<MemoryEvents>),
}

/// A recording read whole (NeuroTac pickles, which must be parsed whole), handed out in chunks
/// like the streaming readers'.
struct MemoryEvents {
    events: Vec<Event>,
    /// IMU samples, in time order.
    imu: Vec<ImuSample>,
    /// Triggers, in time order.
    triggers: Vec<Trigger>,
    /// The next event, IMU sample and trigger to hand out.
    next: usize,
    next_imu: usize,
    next_trigger: usize,
    /// Checks events against the file's sensor size (or a declared one).
    check: EventCheck,
    /// Bytes of the files, for positions: all read at once.
    len: u64,
}

impl MemoryEvents {
    /// Events per chunk, as the file readers hand them out.
    const CHUNK: usize = 1 << 16;

    fn new(events: Vec<Event>, resolution: Option<Resolution>, len: u64) -> Self {
        Self {
            events,
            imu: Vec::new(),
            triggers: Vec::new(),
            next: 0,
            next_imu: 0,
            next_trigger: 0,
            check: EventCheck::new(resolution),
            len,
        }
    }

    /// The next chunk: up to [`Self::CHUNK`] events, with the IMU samples and triggers up to
    /// the last of them (all that remain with the last events), so that a range read, which
    /// stops at the first chunk whose events pass the range's end, misses none.
    fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, crate::check::CheckError> {
        let done = self.next >= self.events.len();
        if done && self.next_imu >= self.imu.len() && self.next_trigger >= self.triggers.len() {
            return Ok(None);
        }
        let end = (self.next + Self::CHUNK).min(self.events.len());
        let events = &self.events[self.next..end];
        self.check.check(events)?;
        self.next = end;
        let upto = match events.last() {
            Some(last) if end < self.events.len() => last.t,
            _ => i64::MAX,
        };
        let imu_end = self.next_imu + self.imu[self.next_imu..].partition_point(|s| s.t <= upto);
        let trigger_end =
            self.next_trigger + self.triggers[self.next_trigger..].partition_point(|t| t.t <= upto);
        let chunk = Chunk {
            events,
            imu: &self.imu[self.next_imu..imu_end],
            triggers: &self.triggers[self.next_trigger..trigger_end],
        };
        self.next_imu = imu_end;
        self.next_trigger = trigger_end;
        Ok(Some(chunk))
    }
}

/// A streaming reader of any supported event file (see [`open`]).
pub struct EventReader {
    path: PathBuf,
    format: Format,
    source: Option<String>,
    /// What a user should know about the file that its counts do not say (a NeuroTac pickle's
    /// millisecond times and missing polarity, a CSV file's missing header line, the members an
    /// NPZ archive's events came from, a bag's topics read).
    note: Option<String>,
    /// A ROS bag's topics (empty for the other formats).
    topics: Vec<crate::ros::TopicInfo>,
    len: u64,
    inner: Inner,
    /// Validation of AEDAT4 events (the other readers validate their own).
    aedat_check: EventCheck,
    /// The selected time range, for the formats the reader filters itself (not AEDAT4, whose
    /// reader does).
    range: Option<(i64, i64)>,
    /// Set once a range read of an unindexed format has passed the range's end.
    past_range: bool,
}

impl std::fmt::Debug for EventReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EventReader")
            .field("path", &self.path)
            .field("format", &self.format)
            .field("resolution", &self.resolution())
            .finish_non_exhaustive()
    }
}

/// Opens the event file at `path`, recognising its format (see [`Format::detect`]).
///
/// ```no_run
/// let mut reader = evtac_formats::open("recording.aedat4")?;
/// let mut on = 0;
/// while let Some(chunk) = reader.next_chunk()? {
///     on += chunk.events.iter().filter(|e| e.polarity).count();
/// }
/// println!("{on} ON events from {:?}", reader.source());
/// # Ok::<(), evtac_formats::Error>(())
/// ```
pub fn open(path: impl AsRef<Path>) -> Result<EventReader, Error> {
    open_with(path, &StreamSelection::default())
}

/// Opens the event file at `path` as [`open`] does, reading the streams `selection` picks from
/// an AEDAT4 file with several (two cameras, say; see [`StreamSelection`]), or the topics it
/// names in a ROS bag (`selection.events` the event topic, `selection.imu` the IMU topic; see
/// [`crate::ros`]). A selection naming a stream is an error for the other formats, which hold
/// one stream of each kind.
pub fn open_with(
    path: impl AsRef<Path>,
    selection: &StreamSelection,
) -> Result<EventReader, Error> {
    let path = path.as_ref();
    let format = Format::detect(path)?;
    let io = |error| Error::Io {
        path: path.to_path_buf(),
        error,
    };
    let len = if format == Format::Mcap {
        // A rosbag2 folder: its files' sizes.
        crate::ros::bag_len(path)?
    } else {
        std::fs::metadata(path).map_err(io)?.len()
    };
    let streams = matches!(format, Format::Aedat4 | Format::RosBag | Format::Mcap);
    if !streams && *selection != StreamSelection::default() {
        return Err(Error::UnknownFormat {
            path: path.to_path_buf(),
            reason: format!(
                "a stream was chosen, but only AEDAT4 files and ROS bags hold several streams \
                 and this is {}",
                format.name()
            ),
        });
    }
    // The AEDAT4 event stream's size, which the reader checks events against.
    let mut resolution = None;
    let mut note = None;
    let mut topics = Vec::new();
    let (inner, source) = match format {
        Format::Aedat4 => {
            let mut r = AedatReader::open(path).map_err(|error| Error::Aedat {
                path: path.to_path_buf(),
                error,
            })?;
            let chosen = selection
                .resolve(r.header())
                .map_err(|error| Error::Streams {
                    path: path.to_path_buf(),
                    error,
                })?;
            r.select_streams(&chosen);
            let header = r.header();
            let event_stream = chosen.events.and_then(|id| header.stream(id));
            let name = match event_stream {
                Some(s) => s.source.clone(),
                None => r.source().map(str::to_string),
            };
            resolution = event_stream.and_then(|s| s.resolution);
            (Inner::Aedat(Box::new(r)), name)
        }
        Format::Aedat2 | Format::Aedat31 => {
            let r = LegacyReader::from_path(path).map_err(|error| Error::AedatLegacy {
                path: path.to_path_buf(),
                error,
            })?;
            let name = r.header().camera.clone();
            (Inner::Legacy(Box::new(r)), name)
        }
        Format::Evt2 | Format::Evt21 | Format::Evt3 => {
            let r = EvtReader::from_path(path).map_err(|error| Error::Evt {
                path: path.to_path_buf(),
                error,
            })?;
            let name = r.header().source();
            (Inner::Evt(Box::new(r)), name)
        }
        Format::Csv => {
            let r = CsvReader::from_path(path).map_err(|error| Error::Csv {
                path: path.to_path_buf(),
                error,
            })?;
            if r.headerless() {
                note = Some(
                    "no header line: the columns were read as t,x,y,p (microseconds, column, \
                     row, polarity)"
                        .to_string(),
                );
            }
            (Inner::Csv(Box::new(r)), None)
        }
        Format::Npy => {
            let r = NpyReader::from_path(path).map_err(|error| Error::Npy {
                path: path.to_path_buf(),
                error,
            })?;
            (Inner::Npy(Box::new(r)), None)
        }
        Format::Neurotac => {
            let file = crate::neurotac::read_pair(path).map_err(|error| Error::Neurotac {
                path: path.to_path_buf(),
                error: Box::new(error),
            })?;
            note = Some(file.note());
            let r = MemoryEvents::new(file.events, Some(file.resolution), len);
            (Inner::Memory(Box::new(r)), None)
        }
        Format::Hdf5 => {
            let r = Hdf5Reader::open(path).map_err(|error| Error::Hdf5 {
                path: path.to_path_buf(),
                error: Box::new(error),
            })?;
            note = Some(r.note());
            (Inner::Hdf5(Box::new(r)), None)
        }
        Format::Npz => {
            let r = NpzReader::from_path(path).map_err(|error| Error::Npz {
                path: path.to_path_buf(),
                error: Box::new(error),
            })?;
            note = Some(r.note());
            (Inner::Npz(Box::new(r)), None)
        }
        Format::RosBag | Format::Mcap => {
            let bag = crate::ros::read(path, format, selection)?;
            note = Some(bag.note);
            topics = bag.topics;
            (Inner::Bag(Box::new(bag.events)), None)
        }
    };
    let aedat_check = EventCheck::new(resolution);
    Ok(EventReader {
        path: path.to_path_buf(),
        format,
        source,
        note,
        topics,
        len,
        inner,
        aedat_check,
        range: None,
        past_range: false,
    })
}

impl EventReader {
    /// The file being read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Its format.
    pub fn format(&self) -> Format {
        self.format
    }

    /// The camera that recorded it, when the file says (AEDAT4 source name; EVT plugin and
    /// serial number).
    pub fn source(&self) -> Option<&str> {
        self.source.as_deref()
    }

    /// The sensor size events are checked against: the file's own, or the one declared with
    /// [`set_resolution`](Self::set_resolution).
    pub fn resolution(&self) -> Option<Resolution> {
        match &self.inner {
            Inner::Aedat(_) => self.aedat_check.resolution(),
            Inner::Legacy(r) => r.resolution(),
            Inner::Evt(r) => r.resolution(),
            Inner::Csv(r) => r.resolution(),
            Inner::Npy(r) => r.resolution(),
            Inner::Hdf5(r) => r.resolution(),
            Inner::Npz(r) => r.resolution(),
            Inner::Bag(r) => r.resolution(),
            Inner::Memory(r) => r.check.resolution(),
        }
    }

    /// What a user should know about the file that its counts do not say (for a NeuroTac
    /// pickle: its index order, ON-only, and that its times are milliseconds; for a ROS bag:
    /// the topics read, and the clocks their times come from).
    pub fn note(&self) -> Option<&str> {
        self.note.as_deref()
    }

    /// A ROS bag's topics, each with its message type and count (empty for the other formats;
    /// see [`crate::ros::topics`]).
    pub fn topics(&self) -> &[crate::ros::TopicInfo] {
        &self.topics
    }

    /// Declares the sensor size (needed for CSV and NPY, which do not store it): events from now
    /// on must lie inside it. For a file that states its own size, a different one is an error.
    pub fn set_resolution(&mut self, resolution: Resolution) -> Result<(), Error> {
        if self.format.has_resolution()
            && let Some(found) = self.resolution()
            && found != resolution
        {
            return Err(Error::ResolutionMismatch {
                path: self.path.clone(),
                declared: resolution,
                found,
            });
        }
        if let Inner::Hdf5(r) = &self.inner
            && !r.accepts(resolution)
            && let Some(found) = r.resolution()
        {
            return Err(Error::ResolutionMismatch {
                path: self.path.clone(),
                declared: resolution,
                found,
            });
        }
        match &mut self.inner {
            Inner::Aedat(_) => self.aedat_check.set_resolution(Some(resolution)),
            Inner::Hdf5(r) => r.set_resolution(resolution),
            Inner::Legacy(r) => r.set_resolution(resolution),
            Inner::Evt(r) => r.set_resolution(resolution),
            Inner::Csv(r) => r.set_resolution(resolution),
            Inner::Npy(r) => r.set_resolution(resolution),
            Inner::Npz(r) => r.set_resolution(resolution),
            // A bag whose messages state a size was checked above; one that states none
            // takes this one.
            Inner::Bag(r) => r.set_resolution(resolution),
            // A pickle's own size was checked above.
            Inner::Memory(r) => r.check.set_resolution(Some(resolution)),
        }
        Ok(())
    }

    /// Size of the file in bytes.
    pub fn file_len(&self) -> u64 {
        self.len
    }

    /// Bytes of the file consumed so far (for progress bars).
    pub fn position(&self) -> u64 {
        match &self.inner {
            Inner::Aedat(r) => r.offset(),
            Inner::Legacy(r) => r.position(),
            Inner::Evt(r) => r.position(),
            Inner::Csv(r) => r.position(),
            Inner::Npy(r) => r.position(),
            // Elements, not bytes (chunks and filters hide the bytes): scaled to the file.
            Inner::Hdf5(r) => {
                (self.len as f64 * r.position() as f64 / r.len().max(1) as f64) as u64
            }
            Inner::Npz(r) => (self.len as f64 * r.progress()) as u64,
            Inner::Bag(r) => (self.len as f64 * r.progress()) as u64,
            Inner::Memory(r) => {
                if r.next > 0 {
                    r.len
                } else {
                    0
                }
            }
        }
    }

    /// Restricts the reader to the time range `[from, to)` (microseconds): from now on chunks
    /// hold exactly the events, IMU samples and triggers with `from <= t < to`. Call it before
    /// reading. An AEDAT4 file is read through its data table, touching only the packets in the
    /// range ([`AedatReader::select_range`]); other formats have no index and are read from the
    /// start up to the range's end. The returned [`RangeIndex`] says which happened;
    /// [`RangeIndex::fallback`] gives the reason to warn about when an AEDAT4 file's data table
    /// is missing or unusable.
    pub fn select_range(&mut self, from: i64, to: i64) -> Result<RangeIndex, Error> {
        if from >= to {
            return Err(Error::EmptyRange {
                path: self.path.clone(),
                from,
                to,
            });
        }
        match &mut self.inner {
            Inner::Aedat(r) => {
                self.aedat_check = EventCheck::new(self.aedat_check.resolution());
                r.select_range(from, to).map_err(|error| Error::Aedat {
                    path: self.path.clone(),
                    error,
                })
            }
            Inner::Hdf5(r) => {
                self.range = Some((from, to));
                let index = r.select_range(from, to).map_err(|error| Error::Hdf5 {
                    path: self.path.clone(),
                    error: Box::new(error),
                })?;
                Ok(index.unwrap_or(RangeIndex::Scan(ScanReason::NotIndexed {
                    format: "HDF5 (without ms_to_idx)",
                })))
            }
            _ => {
                self.range = Some((from, to));
                Ok(RangeIndex::Scan(ScanReason::NotIndexed {
                    format: self.format.name(),
                }))
            }
        }
    }

    /// Hands out only the triggers from now on, where the format lets the reader pass the
    /// rest undecoded (AEDAT4: event and IMU packets are read past, not decompressed): a pass
    /// for the triggers of a long session then costs a read of the file. Other formats still
    /// decode everything and hand it out; callers look at the triggers only.
    pub fn triggers_only(&mut self) {
        if let Inner::Aedat(r) = &mut self.inner {
            r.triggers_only();
        }
    }

    /// Hands out only the IMU samples from now on, where the format lets the reader pass the
    /// rest undecoded, as [`Self::triggers_only`] does the triggers (a pass over a long
    /// session's IMU then costs a read of the file).
    pub fn imu_only(&mut self) {
        if let Inner::Aedat(r) = &mut self.inner {
            r.imu_only();
        }
    }

    /// The next chunk; `Ok(None)` at the end of the file (or, after
    /// [`select_range`](Self::select_range), of the range).
    pub fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error> {
        if self.past_range {
            return Ok(None);
        }
        let range = self.range;
        let chunk = next_unfiltered(&self.path, &mut self.inner, &mut self.aedat_check)?;
        let (Some((from, to)), Some(chunk)) = (range, chunk) else {
            return Ok(chunk);
        };
        // Time never goes backwards within a stream: once an event reaches `to` (plus the lag
        // by which the format's other streams may trail the events), the range is over.
        let lag = stream_lag_us(self.format);
        self.past_range = chunk
            .events
            .last()
            .is_some_and(|e| e.t >= to.saturating_add(lag));
        Ok(Some(chunk.within(from, to)))
    }

    /// An iterator over the remaining events, one at a time (IMU samples and triggers are
    /// skipped); it yields the first error and then ends.
    pub fn into_events(self) -> Events {
        Events {
            reader: self,
            buf: Vec::new(),
            next: 0,
            failed: false,
        }
    }

    /// Reads the rest of the file into a [`Recording`].
    pub fn into_recording(mut self) -> Result<Recording, Error> {
        let (mut events, mut imu, mut triggers) = (Vec::new(), Vec::new(), Vec::new());
        while let Some(chunk) = self.next_chunk()? {
            events.extend_from_slice(chunk.events);
            imu.extend_from_slice(chunk.imu);
            triggers.extend_from_slice(chunk.triggers);
        }
        Ok(Recording {
            format: self.format,
            resolution: self.resolution(),
            source: self.source,
            events,
            imu,
            triggers,
        })
    }
}

/// How far (us) IMU samples and triggers may come after events of a later time, in the file
/// order of `format`: a range read keeps reading that far past its end.
///
/// EVT, CSV and NPY hold one time-ordered stream, and AEDAT 2.0 only events. AEDAT 3.1 stores
/// one packet per event type: cAER writes the polarity, IMU and special packets of a *packet
/// container* one after another, each spanning the container's interval (libcaer's
/// `PacketContainerInterval`, 10 ms by default, at most a few hundred ms in any setup seen),
/// so an IMU packet may follow a polarity packet that already ends past the range. One second
/// covers that with a wide margin and costs one second of decoding per range read. (AEDAT4 is
/// read through its own range logic, stream by stream.)
fn stream_lag_us(format: Format) -> i64 {
    match format {
        Format::Aedat31 => 1_000_000,
        _ => 0,
    }
}

/// The next chunk of `inner`, before any range filtering (AEDAT4 events checked with
/// `aedat_check`).
fn next_unfiltered<'a>(
    path: &Path,
    inner: &'a mut Inner,
    aedat_check: &mut EventCheck,
) -> Result<Option<Chunk<'a>>, Error> {
    match inner {
        Inner::Aedat(r) => {
            let chunk = r.next_chunk().map_err(|error| Error::Aedat {
                path: path.to_path_buf(),
                error,
            })?;
            let Some(chunk) = chunk else { return Ok(None) };
            aedat_check
                .check(chunk.events)
                .map_err(|error| Error::Event {
                    path: path.to_path_buf(),
                    error,
                })?;
            Ok(Some(Chunk {
                events: chunk.events,
                imu: chunk.imu,
                triggers: chunk.triggers,
            }))
        }
        Inner::Legacy(r) => r
            .next_chunk()
            .map(|c| {
                c.map(|c| Chunk {
                    events: c.events,
                    imu: c.imu,
                    triggers: c.triggers,
                })
            })
            .map_err(|error| Error::AedatLegacy {
                path: path.to_path_buf(),
                error,
            }),
        Inner::Evt(r) => r
            .next_chunk()
            .map(|c| {
                c.map(|c| Chunk {
                    events: c.events,
                    imu: &[],
                    triggers: c.triggers,
                })
            })
            .map_err(|error| Error::Evt {
                path: path.to_path_buf(),
                error,
            }),
        Inner::Csv(r) => r
            .next_chunk()
            .map(|c| {
                c.map(|events| Chunk {
                    events,
                    ..Chunk::default()
                })
            })
            .map_err(|error| Error::Csv {
                path: path.to_path_buf(),
                error,
            }),
        Inner::Npy(r) => r
            .next_chunk()
            .map(|c| {
                c.map(|events| Chunk {
                    events,
                    ..Chunk::default()
                })
            })
            .map_err(|error| Error::Npy {
                path: path.to_path_buf(),
                error,
            }),
        Inner::Hdf5(r) => r
            .next_chunk()
            .map(|c| {
                c.map(|events| Chunk {
                    events,
                    ..Chunk::default()
                })
            })
            .map_err(|error| Error::Hdf5 {
                path: path.to_path_buf(),
                error: Box::new(error),
            }),
        Inner::Npz(r) => r
            .next_chunk()
            .map(|c| {
                c.map(|events| Chunk {
                    events,
                    ..Chunk::default()
                })
            })
            .map_err(|error| match error {
                // A check failure reads as it does for every other format.
                NpzError::Event(error) => Error::Event {
                    path: path.to_path_buf(),
                    error,
                },
                error => Error::Npz {
                    path: path.to_path_buf(),
                    error: Box::new(error),
                },
            }),
        Inner::Bag(r) => r.next_chunk().map_err(|error| Error::Ros {
            path: path.to_path_buf(),
            error: Box::new(error),
        }),
        Inner::Memory(r) => r.next_chunk().map_err(|error| Error::Event {
            path: path.to_path_buf(),
            error,
        }),
    }
}

/// Iterator over the events of an [`EventReader`] (see [`EventReader::into_events`]).
#[derive(Debug)]
pub struct Events {
    reader: EventReader,
    buf: Vec<Event>,
    next: usize,
    failed: bool,
}

impl Iterator for Events {
    type Item = Result<Event, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        while self.next == self.buf.len() {
            if self.failed {
                return None;
            }
            match self.reader.next_chunk() {
                Ok(Some(chunk)) => {
                    self.buf.clear();
                    self.buf.extend_from_slice(chunk.events);
                    self.next = 0;
                }
                Ok(None) => return None,
                Err(e) => {
                    self.failed = true;
                    return Some(Err(e));
                }
            }
        }
        let event = self.buf[self.next];
        self.next += 1;
        Some(Ok(event))
    }
}

/// A whole recording in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// The format it was read from.
    pub format: Format,
    /// The camera that recorded it, when the file says.
    pub source: Option<String>,
    /// The sensor size, when the file states it.
    pub resolution: Option<Resolution>,
    /// Events, in time order.
    pub events: Vec<Event>,
    /// IMU samples, in time order.
    pub imu: Vec<ImuSample>,
    /// Triggers.
    pub triggers: Vec<Trigger>,
}

/// Reads the whole event file at `path` (any supported format).
///
/// ```no_run
/// let rec = evtac_formats::read_recording("recording.aedat4")?;
/// println!("{} events, {} IMU samples, {:?}", rec.events.len(), rec.imu.len(), rec.resolution);
/// # Ok::<(), evtac_formats::Error>(())
/// ```
pub fn read_recording(path: impl AsRef<Path>) -> Result<Recording, Error> {
    open(path)?.into_recording()
}

/// Reads the part `[from, to)` (microseconds) of the event file at `path`: the events, IMU
/// samples and triggers with `from <= t < to`, and how they were found (see
/// [`EventReader::select_range`]). Memory holds the range, not the file.
///
/// ```no_run
/// let (trial, how) = evtac_formats::read_recording_range("session.aedat4", 5_000_000, 9_000_000)?;
/// if let Some(reason) = how.fallback() {
///     eprintln!("warning: {reason}; scanned the whole file");
/// }
/// println!("{} events, {} triggers", trial.events.len(), trial.triggers.len());
/// # Ok::<(), evtac_formats::Error>(())
/// ```
pub fn read_recording_range(
    path: impl AsRef<Path>,
    from: i64,
    to: i64,
) -> Result<(Recording, RangeIndex), Error> {
    let mut reader = open(path)?;
    let index = reader.select_range(from, to)?;
    Ok((reader.into_recording()?, index))
}

/// The buffered temporary file every [`EventWriter`] sink writes to.
type Sunk = BufWriter<OutputFile>;

enum Sink {
    Aedat(Box<AedatWriter<Sunk>>),
    Csv(CsvWriter<Sunk>),
    Npy(NpyWriter<Sunk>),
}

/// Writes events (and, for AEDAT4, IMU samples and triggers) to a file whose extension picks the
/// format: `.aedat4`, `.csv` or `.npy`.
///
/// The file is written under a temporary name beside `path` and appears under `path` only when
/// [`finish`](Self::finish) succeeds ([`OutputFile`]); a writer dropped before, or a failed
/// finish, leaves no output (and an earlier file of that name untouched).
pub struct EventWriter {
    path: PathBuf,
    format: Format,
    sink: Sink,
}

impl std::fmt::Debug for EventWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EventWriter")
            .field("path", &self.path)
            .field("format", &self.format)
            .finish_non_exhaustive()
    }
}

impl EventWriter {
    /// Creates the file at `path`. AEDAT4 needs the sensor `resolution` and stores
    /// `source_name` (default `evtac`) with LZ4 compression; CSV and NPY store neither.
    pub fn create(
        path: impl AsRef<Path>,
        resolution: Option<Resolution>,
        source_name: Option<&str>,
    ) -> Result<Self, Error> {
        let path = path.as_ref().to_path_buf();
        let format = Format::for_writing(&path)?;
        let resolution = match (format, resolution) {
            (Format::Aedat4, None) => return Err(Error::MissingResolution { path }),
            (_, r) => r,
        };
        let file = OutputFile::buffered(&path).map_err(|error| Error::Io {
            path: path.clone(),
            error,
        })?;
        let sink = match (format, resolution) {
            (Format::Aedat4, Some(resolution)) => {
                let config = WriterConfig::new(resolution, source_name.unwrap_or("evtac"));
                let w = AedatWriter::new_seekable(file, config).map_err(|error| Error::Aedat {
                    path: path.clone(),
                    error,
                })?;
                Sink::Aedat(Box::new(w))
            }
            (Format::Csv, _) => Sink::Csv(CsvWriter::new(file).map_err(|error| Error::Csv {
                path: path.clone(),
                error,
            })?),
            (Format::Npy, _) => Sink::Npy(NpyWriter::new(file).map_err(|error| Error::Npy {
                path: path.clone(),
                error,
            })?),
            (format, _) => return Err(Error::NotWritable { path, format }),
        };
        Ok(Self { path, format, sink })
    }

    /// The format being written.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Whether IMU samples are stored (AEDAT4 only).
    pub fn stores_imu(&self) -> bool {
        matches!(self.sink, Sink::Aedat(_))
    }

    /// Whether triggers are stored (AEDAT4 only).
    pub fn stores_triggers(&self) -> bool {
        matches!(self.sink, Sink::Aedat(_))
    }

    /// Appends events.
    pub fn write_events(&mut self, events: &[Event]) -> Result<(), Error> {
        let path = &self.path;
        match &mut self.sink {
            Sink::Aedat(w) => w.write_events(events).map_err(|error| Error::Aedat {
                path: path.clone(),
                error,
            }),
            Sink::Csv(w) => w.write_events(events).map_err(|error| Error::Csv {
                path: path.clone(),
                error,
            }),
            Sink::Npy(w) => w.write_events(events).map_err(|error| Error::Npy {
                path: path.clone(),
                error,
            }),
        }
    }

    /// Appends IMU samples when the format stores them ([`stores_imu`](Self::stores_imu));
    /// CSV and NPY event files have no place for them and ignore them.
    pub fn write_imu(&mut self, samples: &[ImuSample]) -> Result<(), Error> {
        match &mut self.sink {
            Sink::Aedat(w) => w.write_imu(samples).map_err(|error| Error::Aedat {
                path: self.path.clone(),
                error,
            }),
            Sink::Csv(_) | Sink::Npy(_) => Ok(()),
        }
    }

    /// Appends triggers when the format stores them ([`stores_triggers`](Self::stores_triggers));
    /// CSV and NPY event files have no place for them and ignore them.
    pub fn write_triggers(&mut self, triggers: &[Trigger]) -> Result<(), Error> {
        match &mut self.sink {
            Sink::Aedat(w) => w.write_triggers(triggers).map_err(|error| Error::Aedat {
                path: self.path.clone(),
                error,
            }),
            Sink::Csv(_) | Sink::Npy(_) => Ok(()),
        }
    }

    /// Finishes the file (buffered packets, data table, NPY record count), flushes it and
    /// renames it to its final name.
    pub fn finish(self) -> Result<(), Error> {
        let path = self.path;
        let sunk = match self.sink {
            Sink::Aedat(w) => w.finish().map_err(|error| Error::Aedat {
                path: path.clone(),
                error,
            }),
            Sink::Csv(w) => w.finish().map_err(|error| Error::Csv {
                path: path.clone(),
                error,
            }),
            Sink::Npy(w) => w.finish().map_err(|error| Error::Npy {
                path: path.clone(),
                error,
            }),
        }?;
        OutputFile::commit_buffered(sunk).map_err(|error| Error::Io { path, error })
    }
}
