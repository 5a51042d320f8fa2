//! The seams between the whole-file API and the formats: [`FormatReader`] and [`FormatWriter`],
//! which every format's reader and writer implement, and [`Family`], which says how a family's
//! files are recognised, opened and created.
//!
//! [`EventReader`](crate::EventReader) and [`EventWriter`](crate::EventWriter) hold a boxed
//! reader or writer and know no format by name: what a format does differently (its error
//! type, its chunk shape, how it finds a time range, how it reports progress) stays in its own
//! folder, in the one file that puts it behind these traits (`family.rs` there). The families
//! are listed, in the order their signatures are tried, in [`crate::registry`].

use std::io::BufWriter;
use std::path::{Path, PathBuf};

use evtac_events::output::OutputFile;

use crate::StreamSelection;
use crate::ros::TopicInfo;
use crate::{Chunk, Error, Event, Format, ImuSample, RangeIndex, Resolution, Trigger};

/// The buffered temporary file every writer writes to (renamed when the writer finishes).
pub(crate) type Sunk = BufWriter<OutputFile>;

/// One open file of some format, streamed chunk by chunk. Errors carry the file's path: the
/// reader is made for one path and knows it.
pub trait FormatReader: Send {
    /// The next chunk, `Ok(None)` at the end. Events are checked (inside the resolution, time
    /// never going backwards) before they are handed out.
    fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error>;

    /// The sensor size events are checked against, when the file states one or one was
    /// declared.
    fn resolution(&self) -> Option<Resolution>;

    /// Declares the sensor size for the events from now on. The caller has already refused a
    /// size other than the one the file states; a format with a subtler rule (HDF5) checks it
    /// here.
    fn set_resolution(&mut self, resolution: Resolution) -> Result<(), Error>;

    /// Bytes of the file consumed so far, for progress bars (formats that cannot count bytes
    /// scale their progress to the file's size).
    fn position(&self) -> u64;

    /// Restricts the reader to `[from, to)` when the format can find a range itself; the
    /// default, a format without an index, leaves the range to the caller, which reads from
    /// the start and stops past the range's end.
    fn select_range(&mut self, _from: i64, _to: i64) -> Result<Ranged, Error> {
        Ok(Ranged::Unindexed)
    }

    /// How far (us) IMU samples and triggers may come after events of a later time in the
    /// file's order: a range read keeps reading that far past its end (0: one time-ordered
    /// stream).
    fn stream_lag_us(&self) -> i64 {
        0
    }

    /// Hands out only the triggers from now on, where the format can pass the rest undecoded
    /// (the default decodes everything; callers look at the triggers only).
    fn triggers_only(&mut self) {}

    /// Hands out only the IMU samples from now on, where the format can pass the rest
    /// undecoded.
    fn imu_only(&mut self) {}
}

/// How a reader took a time range (see [`FormatReader::select_range`]).
#[derive(Debug)]
pub enum Ranged {
    /// The reader hands out exactly the range (AEDAT4, through its data table).
    Exact(RangeIndex),
    /// The reader skipped to near the range; the caller still trims each chunk (HDF5 with
    /// `ms_to_idx`, or without it).
    Narrowed(RangeIndex),
    /// The reader does nothing: the caller reads from the start and trims.
    Unindexed,
}

/// One file being written in some format; it is a temporary file until it finishes.
pub trait FormatWriter: Send {
    /// Appends events.
    fn write_events(&mut self, events: &[Event]) -> Result<(), Error>;

    /// Whether IMU samples and triggers are stored (the default: the format has no place for
    /// them, and the writes below ignore them).
    fn stores_imu_and_triggers(&self) -> bool {
        false
    }

    /// Appends IMU samples where the format stores them.
    fn write_imu(&mut self, _samples: &[ImuSample]) -> Result<(), Error> {
        Ok(())
    }

    /// Appends triggers where the format stores them.
    fn write_triggers(&mut self, _triggers: &[Trigger]) -> Result<(), Error> {
        Ok(())
    }

    /// Writes what is buffered (packets, data table, record count) and hands back the file,
    /// which the caller flushes and renames.
    fn finish(self: Box<Self>) -> Result<Sunk, Error>;
}

/// A format's own streaming reader, before the file's path is put on its errors: what the
/// simple formats' readers (AEDAT 3.1/2.0, EVT, CSV, NPY) share, so that one adapter,
/// [`Named`], puts each behind [`FormatReader`].
pub(crate) trait Decode: Send {
    /// The format's error.
    type Error;

    /// The next chunk, checked; `Ok(None)` at the end.
    fn decode(&mut self) -> Result<Option<Chunk<'_>>, Self::Error>;

    /// The sensor size events are checked against.
    fn sensor(&self) -> Option<Resolution>;

    /// Declares the sensor size.
    fn declare(&mut self, resolution: Resolution);

    /// Bytes consumed so far.
    fn consumed(&self) -> u64;

    /// See [`FormatReader::stream_lag_us`].
    fn lag_us(&self) -> i64 {
        0
    }
}

/// [`Decode::sensor`], [`Decode::declare`] and [`Decode::consumed`] for a reader whose own
/// `resolution`, `set_resolution` and `position` methods are them (the simple readers: CSV,
/// NPY, EVT, AEDAT 2.0/3.1), written once rather than in each of their `impl Decode`.
macro_rules! decode_by_inherent_methods {
    () => {
        fn sensor(&self) -> Option<Resolution> {
            self.resolution()
        }

        fn declare(&mut self, resolution: Resolution) {
            self.set_resolution(resolution);
        }

        fn consumed(&self) -> u64 {
            self.position()
        }
    };
}
pub(crate) use decode_by_inherent_methods;

/// A [`Decode`] reader of the file at `path`, its errors made the whole-file [`Error`] by
/// `wrap`.
pub(crate) struct Named<D: Decode> {
    pub path: PathBuf,
    pub inner: D,
    pub wrap: fn(PathBuf, D::Error) -> Error,
}

impl<D: Decode> FormatReader for Named<D> {
    fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error> {
        let (path, wrap) = (&self.path, self.wrap);
        self.inner
            .decode()
            .map_err(|error| wrap(path.clone(), error))
    }

    fn resolution(&self) -> Option<Resolution> {
        self.inner.sensor()
    }

    fn set_resolution(&mut self, resolution: Resolution) -> Result<(), Error> {
        self.inner.declare(resolution);
        Ok(())
    }

    fn position(&self) -> u64 {
        self.inner.consumed()
    }

    fn stream_lag_us(&self) -> i64 {
        self.inner.lag_us()
    }
}

/// A file of a family opened for reading, with what the whole-file API reports about it.
pub(crate) struct Opened {
    pub reader: Box<dyn FormatReader>,
    /// The camera that recorded it, when the file says.
    pub source: Option<String>,
    /// What a user should know that the counts do not say.
    pub note: Option<String>,
    /// A ROS bag's topics (empty for the other formats).
    pub topics: Vec<TopicInfo>,
}

impl Opened {
    /// A reader with nothing more to report.
    pub fn plain(reader: impl FormatReader + 'static) -> Self {
        Self {
            reader: Box::new(reader),
            source: None,
            note: None,
            topics: Vec::new(),
        }
    }
}

/// An extension a family's files carry, the format it names, and the signature a file with
/// that extension should start with (for the error when it does not; `None`: no such message).
pub(crate) struct Extension {
    pub extension: &'static str,
    pub format: Format,
    pub signature: Option<&'static str>,
}

/// A family of formats (AEDAT 3.1 and 2.0, say): how its files are recognised, opened and
/// created. One value of each family is listed in [`crate::registry`].
pub(crate) trait Family: Sync {
    /// The formats of the family.
    fn formats(&self) -> &'static [Format];

    /// The extensions of its files.
    fn extensions(&self) -> &'static [Extension];

    /// The format of the file at `path` whose first bytes (up to 4 KiB) are `head`, when it is
    /// this family's; an error when it is this family's but unreadable (an unknown version).
    fn sniff(&self, path: &Path, head: &[u8]) -> Option<Result<Format, Error>>;

    /// The format of the folder at `path`, when the family reads folders.
    fn sniff_folder(&self, _path: &Path) -> Option<Result<Format, Error>> {
        None
    }

    /// Whether a file of the family holds several streams a [`StreamSelection`] chooses from.
    fn has_streams(&self) -> bool {
        false
    }

    /// The size in bytes of what `path` names (a folder's files, for a folder).
    fn len(&self, path: &Path) -> Result<u64, Error> {
        std::fs::metadata(path)
            .map(|m| m.len())
            .map_err(|error| Error::Io {
                path: path.to_path_buf(),
                error,
            })
    }

    /// Opens the file [`Open`] names.
    fn open(&self, at: &Open<'_>) -> Result<Opened, Error>;

    /// Creates the writer [`Create`] asks for; `None` when the family does not write its
    /// format.
    fn create(&self, _to: Create<'_>) -> Option<Result<Box<dyn FormatWriter>, Error>> {
        None
    }

    /// Whether [`Self::create`] writes `format`.
    fn writes(&self, _format: Format) -> bool {
        false
    }
}

/// What [`Family::open`] opens: one struct rather than four arguments, so that a family's
/// `open` takes what it needs by name (and a new field does not touch every family).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Open<'a> {
    /// The file (or folder).
    pub path: &'a Path,
    /// Its format, one of the family's [`Family::formats`].
    pub format: Format,
    /// Which streams of a file with several to read.
    pub selection: &'a StreamSelection,
    /// Its size in bytes ([`Family::len`]).
    pub len: u64,
}

/// What [`Family::create`] writes: `format` into `file`, for the output `path`.
pub(crate) struct Create<'a> {
    /// The output's final name.
    pub path: &'a Path,
    /// Its format.
    pub format: Format,
    /// The temporary file it is written to ([`evtac_events::output::OutputFile`]).
    pub file: Sunk,
    /// The sensor's size, when known.
    pub resolution: Option<Resolution>,
    /// The camera's name, when known.
    pub source_name: Option<&'a str>,
}

/// A path's extension, lower case (empty when it has none).
pub(crate) fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}
