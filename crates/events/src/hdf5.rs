//! HDF5 event files, in the two layouts labs have on disk, streamed in chunks.
//!
//! - **event_utils** (and the NeuroTac lab's collection code, which writes the same layout): a
//!   group `events` with one dataset per field, `xs`, `ys` (int16), `ts` (float seconds) and
//!   `ps` (bool), and attributes `t0`, `tk`, `num_events` and `sensor_resolution` on the file.
//! - **DSEC**: `events/x`, `events/y` (uint16), `events/t` (uint32 microseconds after the root
//!   dataset `t_offset`), `events/p` (uint8), and `ms_to_idx`, the index of the first event of
//!   each millisecond, through which a time range is read without reading what comes before.
//!
//! Any dataset names [`Field`] accepts are read, in the group `events` or at the root. Times are
//! integer microseconds, or float seconds rounded to the nearest microsecond (exact for times
//! that were whole microseconds: a float64 of a Unix time in seconds is within 0.25 us of it).
//!
//! `sensor_resolution` is written `[height, width]` by event_utils and `[width, height]` by
//! the NeuroTac code (dv-processing's `getEventResolution`); the file does not say which, so the
//! larger value is taken as the width (every event camera evtac knows is wider than tall) and
//! the note says so. A sensor size declared by the user must be the same two numbers.
//!
//! The HDF5 library itself is the HDF Group's (`libhdf5`, through the `hdf5-metno` bindings):
//! the format's B-trees, chunking and filters are too large to rewrite. Data is read in slices of
//! 65,536 events, so memory holds a slice whatever size a dataset claims; attributes are read
//! only when they hold a handful of values.

use std::ops::Range;
use std::path::Path;

use hdf5_metno::types::{IntSize, TypeDescriptor};
use hdf5_metno::{Dataset, File, Group, Location};

use crate::check::{CheckError, EventCheck};
use crate::columns::{Field, Slots};
use crate::npy::{coordinates, polarity};
use crate::{Event, RangeIndex, Resolution};

/// Events read per slice.
const CHUNK: usize = 1 << 16;
/// The most values an attribute may hold to be read (a size, a time, a count).
const SMALL_ATTRIBUTE: usize = 16;

/// What can go wrong reading an HDF5 event file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Hdf5Error {
    /// The HDF5 library could not open or read an object.
    #[error("{object}: {message}")]
    Library {
        /// The object (file, dataset or attribute path).
        object: String,
        /// The library's message.
        message: String,
    },
    /// No group holds the four event datasets.
    #[error(
        "no event datasets: expected a group `events` (or the file's root) with one dataset per \
         field, named {accepted}; found {found}",
        accepted = Field::accepted()
    )]
    NoEvents {
        /// What the file's root and `events` group hold.
        found: String,
    },
    /// A dataset's element type cannot hold its field.
    #[error("dataset `{dataset}` has type {found}: {expected}")]
    Type {
        /// The dataset's path.
        dataset: String,
        /// Its type.
        found: String,
        /// What the field needs.
        expected: &'static str,
    },
    /// The datasets differ in length, or are not one-dimensional.
    #[error("the event datasets must be one-dimensional and of one length: {shapes}")]
    Shapes {
        /// Each dataset with its shape.
        shapes: String,
    },
    /// An attribute or index dataset is malformed, or disagrees with the data.
    #[error("`{object}`: {reason}")]
    Metadata {
        /// The attribute or dataset.
        object: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A value is not an event field.
    #[error("dataset `{dataset}`, element {index}: {reason}")]
    Value {
        /// The dataset's path.
        dataset: String,
        /// Zero-based element index.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A decoded event is invalid (outside the sensor, or earlier than its predecessor).
    #[error("{error} (element {index} of the event datasets)")]
    Event {
        /// What is wrong with it.
        error: CheckError,
        /// Zero-based element index.
        index: u64,
    },
}

/// How a dataset's elements are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// Integers that fit `i64`, read in their own type and widened here (HDF5's own
    /// conversion is several times slower than a widening loop).
    Int(IntSize, bool),
    /// Unsigned 64-bit integers, checked against `i64::MAX` here (HDF5 would clip them).
    U64,
    /// Float seconds (timestamps only).
    Seconds,
    /// HDF5's bool enum, as h5py writes numpy's bool.
    Bool,
}

/// One event field's dataset.
#[derive(Debug)]
struct Column {
    path: String,
    dataset: Dataset,
    kind: Kind,
}

impl Column {
    fn new(group: &Group, prefix: &str, name: &str, field: Field) -> Result<Self, Hdf5Error> {
        let path = format!("{prefix}{name}");
        let dataset = group.dataset(name).map_err(library(&path))?;
        let descriptor = dataset
            .dtype()
            .and_then(|t| t.to_descriptor())
            .map_err(library(&path))?;
        let kind = match (&descriptor, field) {
            (TypeDescriptor::Unsigned(IntSize::U8), _) => Kind::U64,
            (TypeDescriptor::Integer(size), _) => Kind::Int(*size, true),
            (TypeDescriptor::Unsigned(size), _) => Kind::Int(*size, false),
            (TypeDescriptor::Boolean, _) => Kind::Bool,
            (TypeDescriptor::Float(_), Field::T) => Kind::Seconds,
            (found, _) => {
                return Err(Hdf5Error::Type {
                    dataset: path,
                    found: format!("{found:?}"),
                    expected: if field == Field::T {
                        "times are integer microseconds or float seconds"
                    } else {
                        "pixels and polarities are integers (or bool)"
                    },
                });
            }
        };
        Ok(Self {
            path,
            dataset,
            kind,
        })
    }

    /// The elements `range` as integers (microseconds for times in seconds).
    fn read(&self, range: Range<usize>) -> Result<Vec<i64>, Hdf5Error> {
        let start = range.start;
        let lib = library(&self.path);
        let value_error = |i: usize, reason: String| Hdf5Error::Value {
            dataset: self.path.clone(),
            index: start + i,
            reason,
        };
        match self.kind {
            Kind::Int(size, signed) => {
                let d = &self.dataset;
                macro_rules! widened {
                    ($t:ty) => {
                        d.read_slice_1d::<$t, _>(range)
                            .map_err(lib)?
                            .iter()
                            .map(|&v| i64::from(v))
                            .collect()
                    };
                }
                Ok(match (size, signed) {
                    (IntSize::U1, true) => widened!(i8),
                    (IntSize::U2, true) => widened!(i16),
                    (IntSize::U4, true) => widened!(i32),
                    (IntSize::U8, true) => widened!(i64),
                    (IntSize::U1, false) => widened!(u8),
                    (IntSize::U2, false) => widened!(u16),
                    // Unsigned 64-bit integers are `Kind::U64`.
                    (_, false) => widened!(u32),
                })
            }
            Kind::U64 => self
                .dataset
                .read_slice_1d::<u64, _>(range)
                .map_err(lib)?
                .iter()
                .enumerate()
                .map(|(i, &v)| {
                    i64::try_from(v).map_err(|_| value_error(i, format!("{v} is above 2^63 - 1")))
                })
                .collect(),
            Kind::Bool => Ok(self
                .dataset
                .read_slice_1d::<bool, _>(range)
                .map_err(lib)?
                .iter()
                .map(|&b| i64::from(b))
                .collect()),
            Kind::Seconds => self
                .dataset
                .read_slice_1d::<f64, _>(range)
                .map_err(lib)?
                .iter()
                .enumerate()
                .map(|(i, &s)| {
                    let us = s * 1e6;
                    // i64::MAX as f64 rounds up to 2^63, so `<` keeps the cast in range.
                    if us.is_finite() && us > i64::MIN as f64 && us < i64::MAX as f64 - 1.0 {
                        // Rounded half away from zero by a truncating cast (`f64::round` is a
                        // library call here, a fifth of the read's time).
                        Ok((us + 0.5f64.copysign(us)) as i64)
                    } else {
                        Err(value_error(
                            i,
                            format!("{s} s is not a time in microseconds"),
                        ))
                    }
                })
                .collect(),
        }
    }
}

/// The error of a library call on `object`.
fn library(object: &str) -> impl Fn(hdf5_metno::Error) -> Hdf5Error + '_ {
    move |e| Hdf5Error::Library {
        object: object.to_string(),
        message: e.to_string(),
    }
}

/// A small numeric attribute of `location`, if it has one named `name`.
fn small_attribute(location: &Location, name: &str) -> Result<Option<Vec<f64>>, Hdf5Error> {
    if !location
        .attr_names()
        .is_ok_and(|n| n.iter().any(|a| a == name))
    {
        return Ok(None);
    }
    let attr = location.attr(name).map_err(library(name))?;
    let size = attr.size();
    if size > SMALL_ATTRIBUTE {
        return Err(Hdf5Error::Metadata {
            object: name.to_string(),
            reason: format!("holds {size} values; expected at most {SMALL_ATTRIBUTE}"),
        });
    }
    attr.read_raw::<f64>().map(Some).map_err(library(name))
}

/// A streaming reader of HDF5 event files (see the module docs).
#[derive(Debug)]
pub struct Hdf5Reader {
    /// `t, x, y, p`.
    columns: [Column; 4],
    /// Added to integer times (DSEC's `t_offset`).
    t_offset: i64,
    /// DSEC's millisecond index, when the file has one.
    ms_to_idx: Option<Dataset>,
    len: usize,
    next: usize,
    end: usize,
    /// The `sensor_resolution` attribute as stored.
    stated: Option<[u16; 2]>,
    check: EventCheck,
    /// The element the check's count starts at (where a range read starts).
    checked_from: usize,
    events: Vec<Event>,
    /// Keeps the file open while its datasets are read.
    _file: File,
}

impl Hdf5Reader {
    /// Opens the file at `path` and finds its event datasets.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, Hdf5Error> {
        let path = path.as_ref();
        // The caller names the path; the library's message says what failed.
        let file = File::open(path).map_err(library("the file"))?;
        let (group, prefix) = match file.group("events") {
            Ok(g) => (g, "events/"),
            Err(_) => ((*file).clone(), ""),
        };
        let names = group.member_names().map_err(library(prefix))?;
        let mut slots = Slots::default();
        for name in &names {
            if let Some(field) = Field::of(name) {
                slots
                    .set(field, name.as_str(), name)
                    .map_err(|reason| Hdf5Error::Metadata {
                        object: format!("{prefix}{name}"),
                        reason,
                    })?;
            }
        }
        let found = || {
            let root = file.member_names().unwrap_or_default();
            format!("root {root:?}, `{prefix}` {names:?}")
        };
        let [t, x, y, p] = slots
            .complete()
            .map_err(|_| Hdf5Error::NoEvents { found: found() })?;
        let columns = [
            Column::new(&group, prefix, t, Field::T)?,
            Column::new(&group, prefix, x, Field::X)?,
            Column::new(&group, prefix, y, Field::Y)?,
            Column::new(&group, prefix, p, Field::P)?,
        ];
        let shapes: Vec<Vec<usize>> = columns.iter().map(|c| c.dataset.shape()).collect();
        let len = shapes[0].first().copied().unwrap_or(0);
        if shapes.iter().any(|s| s.as_slice() != [len]) {
            let shapes = columns
                .iter()
                .zip(&shapes)
                .map(|(c, s)| format!("{} {s:?}", c.path))
                .collect::<Vec<_>>()
                .join(", ");
            return Err(Hdf5Error::Shapes { shapes });
        }
        let root: &Location = &file;
        if let Some(n) = small_attribute(root, "num_events")?
            && n.first().is_none_or(|&n| n != len as f64)
        {
            return Err(Hdf5Error::Metadata {
                object: "num_events".into(),
                reason: format!(
                    "says {n:?} events, but the event datasets hold {len} (a file cut short?)"
                ),
            });
        }
        // On the file (event_utils, the NeuroTac code), else on the `events` group.
        let sizes = match small_attribute(root, "sensor_resolution")? {
            Some(v) => Some(v),
            None => small_attribute(&group, "sensor_resolution")?,
        };
        let stated = sizes.as_deref().map(two_sizes).transpose()?;
        let t_offset = if columns[0].kind != Kind::Seconds && file.link_exists("t_offset") {
            file.dataset("t_offset")
                .and_then(|d| d.read_scalar::<i64>())
                .map_err(library("t_offset"))?
        } else {
            0
        };
        let ms_to_idx = if file.link_exists("ms_to_idx") {
            Some(file.dataset("ms_to_idx").map_err(library("ms_to_idx"))?)
        } else {
            None
        };
        let resolution = stated.map(|[a, b]| Resolution::new(a.max(b), a.min(b)));
        Ok(Self {
            columns,
            t_offset,
            ms_to_idx,
            len,
            next: 0,
            end: len,
            stated,
            check: EventCheck::new(resolution),
            checked_from: 0,
            events: Vec::new(),
            _file: file,
        })
    }

    /// Number of events in the file.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the file holds no events.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The sensor size events are checked against: the file's (see the module docs), or the one
    /// declared.
    pub fn resolution(&self) -> Option<Resolution> {
        self.check.resolution()
    }

    /// Whether `declared` is the file's `sensor_resolution` (in either order), or the file states
    /// none.
    pub fn accepts(&self, declared: Resolution) -> bool {
        self.stated.is_none_or(|[a, b]| {
            [declared.width, declared.height] == [a, b]
                || [declared.width, declared.height] == [b, a]
        })
    }

    /// Declares the sensor size (see [`Self::accepts`]).
    pub fn set_resolution(&mut self, resolution: Resolution) {
        self.check.set_resolution(Some(resolution));
    }

    /// What `evtac info` says about the file: the datasets read, the time unit, and how the
    /// sensor size was read.
    pub fn note(&self) -> String {
        let [t, x, y, p] = self.columns.each_ref().map(|c| c.path.as_str());
        let unit = if self.columns[0].kind == Kind::Seconds {
            "float seconds, rounded to microseconds".to_string()
        } else if self.t_offset != 0 {
            format!("microseconds after t_offset = {} us", self.t_offset)
        } else {
            "microseconds".to_string()
        };
        let mut note = format!("events from {t}, {x}, {y}, {p}; times in {unit}");
        if let Some([a, b]) = self.stated
            && a != b
        {
            note += &format!(
                "; sensor_resolution = [{a}, {b}] read as {}x{} (the larger as the width: \
                 event_utils writes [height, width], dv-processing [width, height])",
                a.max(b),
                a.min(b)
            );
        }
        if self.ms_to_idx.is_some() {
            note += "; time ranges are read through ms_to_idx";
        }
        note
    }

    /// Elements read so far (for progress).
    pub fn position(&self) -> usize {
        self.next
    }

    /// Narrows the read to the events that can lie in `[from, to)` through `ms_to_idx`, when the
    /// file has one (the caller still cuts the chunks to the range exactly). `None` when it has
    /// none.
    pub fn select_range(&mut self, from: i64, to: i64) -> Result<Option<RangeIndex>, Hdf5Error> {
        let Some(index) = &self.ms_to_idx else {
            return Ok(None);
        };
        let path = "ms_to_idx";
        let bad = |reason: String| Hdf5Error::Metadata {
            object: path.into(),
            reason,
        };
        let ms = index.shape().first().copied().unwrap_or(0);
        if ms == 0 {
            return Err(bad("is empty".into()));
        }
        // ms_to_idx[k] is the first event with t >= k ms (after t_offset).
        let entry = |k: usize| -> Result<usize, Hdf5Error> {
            let v = index
                .read_slice_1d::<u64, _>(k..k + 1)
                .map_err(library(path))?;
            let v = usize::try_from(v[0]).unwrap_or(usize::MAX);
            if v > self.len {
                return Err(bad(format!(
                    "entry {k} is {v}, past the {} events",
                    self.len
                )));
            }
            Ok(v)
        };
        let millis = |t: i64| t.saturating_sub(self.t_offset).div_euclid(1000);
        let first_ms = millis(from).clamp(0, ms as i64 - 1) as usize;
        // The millisecond holding `to - 1`, plus one: its first event is at or past `to`.
        let last_ms = millis(to.saturating_sub(1)).saturating_add(1);
        let start = if millis(from) < 0 {
            0
        } else {
            entry(first_ms)?
        };
        let end = if last_ms < 0 {
            0
        } else if last_ms as usize >= ms {
            self.len
        } else {
            entry(last_ms as usize)?
        };
        let end = end.max(start);
        // A wrong index would silently drop events: check it against the times at both edges.
        let t_at = |i: usize| -> Result<i64, Hdf5Error> {
            Ok(self.columns[0].read(i..i + 1)?[0].saturating_add(self.t_offset))
        };
        if start > 0 && t_at(start - 1)? >= from {
            return Err(bad(format!(
                "entry {first_ms} says events start at {start}, but event {} is at or after \
                 {from} us",
                start - 1
            )));
        }
        if end < self.len && t_at(end)? < to {
            return Err(bad(format!(
                "entry {last_ms} says events end at {end}, but event {end} is before {to} us"
            )));
        }
        self.next = start;
        self.end = end;
        self.check = EventCheck::new(self.check.resolution());
        self.checked_from = start;
        Ok(Some(RangeIndex::EventIndex {
            events: (end - start) as u64,
            total: self.len as u64,
        }))
    }

    /// The next chunk of events; `Ok(None)` at the end.
    pub fn next_chunk(&mut self) -> Result<Option<&[Event]>, Hdf5Error> {
        if self.next >= self.end {
            return Ok(None);
        }
        let range = self.next..(self.next + CHUNK).min(self.end);
        let [t, x, y, p] = [0, 1, 2, 3].map(|i| self.columns[i].read(range.clone()));
        let (t, x, y, p) = (t?, x?, y?, p?);
        self.events.clear();
        let value = |column: usize, i: usize, reason: String| Hdf5Error::Value {
            dataset: self.columns[column].path.clone(),
            index: range.start + i,
            reason,
        };
        for i in 0..range.len() {
            let (ex, ey) = coordinates(Some(x[i]), Some(y[i])).map_err(|r| value(1, i, r))?;
            let t = t[i]
                .checked_add(self.t_offset)
                .ok_or_else(|| value(0, i, format!("{} + t_offset overflows", t[i])))?;
            let polarity = polarity(Some(p[i])).map_err(|r| value(3, i, r))?;
            self.events.push(Event {
                t,
                x: ex,
                y: ey,
                polarity,
            });
        }
        let base = self.checked_from as u64;
        self.check
            .check(&self.events)
            .map_err(|error| Hdf5Error::Event {
                index: base + error.index(),
                error,
            })?;
        self.next = range.end;
        Ok(Some(&self.events))
    }
}

/// Two sizes from a `sensor_resolution` attribute.
fn two_sizes(values: &[f64]) -> Result<[u16; 2], Hdf5Error> {
    let size = |v: f64| ((1.0..=65535.0).contains(&v) && v.fract() == 0.0).then_some(v as u16);
    match values {
        [a, b, ..] => match (size(*a), size(*b)) {
            (Some(a), Some(b)) => Ok([a, b]),
            _ => Err(Hdf5Error::Metadata {
                object: "sensor_resolution".into(),
                reason: format!("{values:?} are not two pixel counts"),
            }),
        },
        _ => Err(Hdf5Error::Metadata {
            object: "sensor_resolution".into(),
            reason: format!("{values:?} is not [height, width] or [width, height]"),
        }),
    }
}

/// Reads `bytes` as an HDF5 event file, for the fuzz target: any input gives events or an
/// error, never a panic. The HDF5 library reads files, so the bytes go to a temporary one.
pub fn fuzz_decode(bytes: &[u8]) -> Result<usize, Hdf5Error> {
    let file = tempfile::NamedTempFile::new().map_err(|e| Hdf5Error::Library {
        object: "temporary file".into(),
        message: e.to_string(),
    })?;
    std::fs::write(file.path(), bytes).map_err(|e| Hdf5Error::Library {
        object: "temporary file".into(),
        message: e.to_string(),
    })?;
    let mut reader = Hdf5Reader::open(file.path())?;
    let mut n = 0;
    let _ = reader.select_range(0, 1_000_000);
    while let Some(chunk) = reader.next_chunk()? {
        n += chunk.len();
    }
    Ok(n)
}
