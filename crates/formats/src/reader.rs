//! The whole-file API for reading: open any supported event file by its path and stream it in
//! chunks ([`EventReader`]), or read it whole ([`read_recording`]) or a time range of it
//! ([`read_recording_range`]).
//!
//! The format is recognised by the registry ([`crate::registry`]): by the file's first bytes
//! (AEDAT4, NPY, HDF5 and MCAP magic, `#!AER-DAT2.0` / `#!AER-DAT3.1` header, EVT `%` header,
//! `#ROSBAG V2.0`, a NeuroTac pickle's opening; a folder is a rosbag2 bag) and otherwise by its
//! extension (`.csv`; `.npz` for a zip). Every reader validates what it decodes: events inside
//! the declared resolution and timestamps that never go backwards.
//!
//! [`EventReader::select_range`] (and [`read_recording_range`]) read a time range `[from, to)`:
//! AEDAT4 files through their data table, touching only the packets in the range; the other
//! formats, which have no index, by reading up to the range's end.

use std::path::{Path, PathBuf};

use crate::StreamSelection;
use crate::family::{FormatReader, Ranged};
use crate::range::{RangeIndex, ScanReason, within};
use crate::registry;
use crate::{Error, Event, Format, ImuSample, Resolution, Trigger};

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
    /// A chunk of events only (the formats that hold no IMU samples or triggers).
    pub(crate) fn of_events(events: &'a [Event]) -> Self {
        Self {
            events,
            ..Self::default()
        }
    }

    /// The part of the chunk with `from <= t < to`.
    fn within(self, from: i64, to: i64) -> Self {
        Self {
            events: &self.events[within(self.events, |e| e.t, from, to)],
            imu: &self.imu[within(self.imu, |s| s.t, from, to)],
            triggers: &self.triggers[within(self.triggers, |t| t.t, from, to)],
        }
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
    inner: Box<dyn FormatReader>,
    /// The selected time range, for the formats whose reader leaves the trimming to this one.
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
    open_as(path, registry::detect(path)?, selection)
}

/// Opens the file at `path` as [`open_with`] does, its format already recognised (so that a
/// caller which needed the format first detects it once).
pub(crate) fn open_as(
    path: &Path,
    format: Format,
    selection: &StreamSelection,
) -> Result<EventReader, Error> {
    let family = registry::family(format);
    let len = family.len(path)?;
    if !family.has_streams() && *selection != StreamSelection::default() {
        return Err(Error::UnknownFormat {
            path: path.to_path_buf(),
            reason: format!(
                "a stream was chosen, but only AEDAT4 files and ROS bags hold several streams \
                 and this is {}",
                format.name()
            ),
        });
    }
    let opened = family.open(&crate::family::Open {
        path,
        format,
        selection,
        len,
    })?;
    Ok(EventReader {
        path: path.to_path_buf(),
        format,
        source: opened.source,
        note: opened.note,
        topics: opened.topics,
        len,
        inner: opened.reader,
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
        self.inner.resolution()
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
        self.inner.set_resolution(resolution)
    }

    /// Size of the file in bytes.
    pub fn file_len(&self) -> u64 {
        self.len
    }

    /// Bytes of the file consumed so far (for progress bars).
    pub fn position(&self) -> u64 {
        self.inner.position()
    }

    /// Restricts the reader to the time range `[from, to)` (microseconds): from now on chunks
    /// hold exactly the events, IMU samples and triggers with `from <= t < to`. Call it before
    /// reading. An AEDAT4 file is read through its data table, touching only the packets in the
    /// range ([`AedatReader::select_range`](crate::aedat::AedatReader::select_range)); other
    /// formats have no index and are read from the start up to the range's end. The returned
    /// [`RangeIndex`] says which happened; [`RangeIndex::fallback`] gives the reason to warn
    /// about when an AEDAT4 file's data table is missing or unusable.
    pub fn select_range(&mut self, from: i64, to: i64) -> Result<RangeIndex, Error> {
        if from >= to {
            return Err(Error::EmptyRange {
                path: self.path.clone(),
                from,
                to,
            });
        }
        match self.inner.select_range(from, to)? {
            Ranged::Exact(index) => Ok(index),
            Ranged::Narrowed(index) => {
                self.range = Some((from, to));
                Ok(index)
            }
            Ranged::Unindexed => {
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
        self.inner.triggers_only();
    }

    /// Hands out only the IMU samples from now on, where the format lets the reader pass the
    /// rest undecoded, as [`Self::triggers_only`] does the triggers (a pass over a long
    /// session's IMU then costs a read of the file).
    pub fn imu_only(&mut self) {
        self.inner.imu_only();
    }

    /// The next chunk; `Ok(None)` at the end of the file (or, after
    /// [`select_range`](Self::select_range), of the range).
    pub fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error> {
        if self.past_range {
            return Ok(None);
        }
        let range = self.range;
        // How far the format's other streams may trail the events (read before the chunk
        // borrows the reader).
        let lag = self.inner.stream_lag_us();
        let chunk = self.inner.next_chunk()?;
        let (Some((from, to)), Some(chunk)) = (range, chunk) else {
            return Ok(chunk);
        };
        // Time never goes backwards within a stream: once an event reaches `to` (plus the lag),
        // the range is over.
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
