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
//! The file is read by `hdf5-pure`, a Rust implementation of the format (no C library): the
//! HDF Group's libhdf5, which evtac used before, overflowed a heap buffer (SIGSEGV) and tried to
//! allocate 3.4 PB on damaged files our fuzzing found, and a C library's crash is no error a
//! user can read. `hdf5-pure` was chosen over the other Rust readers because it reads what h5py
//! writes for these files up to HDF5 1.14's format (contiguous and chunked, gzip and shuffle,
//! the bool enum, superblocks 0 and 3, `libver` v110 to v114), reads a window of rows without
//! reading the rest, parses with no `unsafe`, and is fuzzed and released often; `hdf5-reader`
//! also reads HDF5 2.0's new chunk layout (version 5) but copies chunks with `unsafe` pointer
//! arithmetic.
//! Files in HDF5 2.0's format (h5py built on HDF5 2.0 with `libver="latest"`) are refused with
//! the layout version named, as libhdf5 1.10 refused them.
//!
//! Data is read in slices of 65,536 events, so memory holds a slice whatever size a dataset
//! claims (a contiguous dataset's slice straight from its address in the file, `stored.rs`;
//! the usual type combinations decoded in one pass over the four columns, `fused.rs`). Before
//! reading, each event dataset must be one-dimensional with elements of at most 8 bytes, claim
//! no more data than the file can hold and store every chunk inside the file (see `column.rs`
//! for why), and an attribute is used only when it holds a handful of values.

mod column;
pub(crate) mod family;
mod fused;
mod stored;

use std::io::Cursor;
use std::path::Path;
use std::sync::Arc;

use hdf5_pure::{AttrValue, File, Group, ReadSeekSource};

use crate::check::{CheckError, EventCheck};
use crate::columns::{Field, Slots};
use crate::npy::polarity;
use crate::{Event, RangeIndex, Resolution};
use column::Column;
use stored::{FileBytes, Shared};

/// Events read per slice.
const CHUNK: usize = 1 << 16;
/// The most values an attribute may hold to be read (a size, a time, a count).
const SMALL_ATTRIBUTE: usize = 16;

/// What can go wrong reading an HDF5 event file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Hdf5Error {
    /// The HDF5 reader could not open or read an object (a damaged or unsupported file).
    #[error("{object}: {message}")]
    Library {
        /// The object (file, dataset or attribute path).
        object: String,
        /// The reader's message.
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

/// The error of a reader call on `object`.
fn library(object: &str) -> impl Fn(hdf5_pure::Error) -> Hdf5Error + '_ {
    move |e| Hdf5Error::Library {
        object: object.to_string(),
        message: e.to_string(),
    }
}

/// The numbers an attribute holds, or `None` for a text or compound one.
fn numbers(value: &AttrValue) -> Option<Vec<f64>> {
    if let Some(floats) = value.to_f64s() {
        return Some(floats);
    }
    macro_rules! widen {
        ($($one:ident, $many:ident);*) => {
            match value {
                $(AttrValue::$one(v) => vec![*v as f64],
                  AttrValue::$many(v) => v.iter().map(|&v| v as f64).collect(),)*
                _ => return None,
            }
        };
    }
    Some(
        widen!(I8, I8Array; I16, I16Array; I32, I32Array; I64, I64Array; U8, U8Array;
        U16, U16Array; U32, U32Array; U64, U64Array),
    )
}

/// A small numeric attribute of `group` (`at` names it in errors), if it has one named `name`.
fn small_attribute(group: &Group, at: &str, name: &str) -> Result<Option<Vec<f64>>, Hdf5Error> {
    let object = format!("{at}{name}");
    let attrs = group.attrs().map_err(library(&object))?;
    let Some(value) = attrs.get(name) else {
        return Ok(None);
    };
    let values = numbers(value).ok_or_else(|| Hdf5Error::Metadata {
        object: object.clone(),
        reason: format!("is {}, not numbers", value.type_name()),
    })?;
    if values.len() > SMALL_ATTRIBUTE {
        return Err(Hdf5Error::Metadata {
            object,
            reason: format!(
                "holds {} values; expected at most {SMALL_ATTRIBUTE}",
                values.len()
            ),
        });
    }
    Ok(Some(values))
}

/// The names of a group's datasets and groups.
fn members(group: &Group) -> Vec<String> {
    let mut names = group.datasets().unwrap_or_default();
    names.extend(group.groups().unwrap_or_default());
    names
}

/// A streaming reader of HDF5 event files (see the module docs).
#[derive(Debug)]
pub struct Hdf5Reader {
    /// `t, x, y, p`.
    columns: [Column; 4],
    /// Added to integer times (DSEC's `t_offset`).
    t_offset: i64,
    /// DSEC's millisecond index, when the file has one.
    ms_to_idx: Option<Column>,
    len: usize,
    next: usize,
    end: usize,
    /// The `sensor_resolution` attribute as stored.
    stated: Option<[u16; 2]>,
    check: EventCheck,
    /// The element the check's count starts at (where a range read starts).
    checked_from: usize,
    events: Vec<Event>,
    /// The file's bytes, for contiguous datasets' windows.
    bytes: FileBytes,
    /// Each column's stored bytes for the slice being decoded, reused from slice to slice.
    raw: [Vec<u8>; 4],
}

impl Hdf5Reader {
    /// Opens the file at `path` and finds its event datasets.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, Hdf5Error> {
        // Streaming: metadata and the chunks a slice needs are read on demand, not the file.
        // The caller names the path; the reader's message says what failed.
        let path = path.as_ref();
        let bytes = std::fs::File::open(path).map_err(|e| Hdf5Error::Library {
            object: "the file".into(),
            message: e.to_string(),
        })?;
        let file = File::open_streaming(path).map_err(library("the file"))?;
        Self::from_file(file, FileBytes::Disk(bytes))
    }

    /// Reads an HDF5 event file held in memory.
    pub fn from_bytes(bytes: Vec<u8>) -> Result<Self, Hdf5Error> {
        let shared = Shared(Arc::from(bytes));
        let source =
            ReadSeekSource::new(Cursor::new(shared.clone())).map_err(|e| Hdf5Error::Library {
                object: "the file".into(),
                message: e.to_string(),
            })?;
        let file = File::from_source(source).map_err(library("the file"))?;
        Self::from_file(file, FileBytes::Memory(shared))
    }

    fn from_file(file: File, bytes: FileBytes) -> Result<Self, Hdf5Error> {
        let root = file.root();
        let (group, prefix) = match file.group("events") {
            Ok(g) => (g, "events/"),
            Err(_) => (file.root(), ""),
        };
        let at = if prefix.is_empty() {
            "the root group"
        } else {
            "the group `events`"
        };
        let names = group.datasets().map_err(library(at))?;
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
            format!(
                "root {:?}, `{prefix}` {:?}",
                members(&root),
                members(&group)
            )
        };
        let [t, x, y, p] = slots
            .complete()
            .map_err(|_| Hdf5Error::NoEvents { found: found() })?;
        let file_len = file.file_size();
        let column = |name: &str, field| {
            let path = format!("{prefix}{name}");
            let dataset = group.dataset(name).map_err(library(&path))?;
            Column::new(path, dataset, field, file_len)
        };
        let columns = [
            column(t, Field::T)?,
            column(x, Field::X)?,
            column(y, Field::Y)?,
            column(p, Field::P)?,
        ];
        let len = columns[0].len;
        if columns.iter().any(|c| c.len != len || c.scalar) {
            let shapes = columns
                .iter()
                .map(|c| c.shape())
                .collect::<Vec<_>>()
                .join(", ");
            return Err(Hdf5Error::Shapes { shapes });
        }
        if let Some(n) = small_attribute(&root, "", "num_events")?
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
        let sizes = match small_attribute(&root, "", "sensor_resolution")? {
            Some(v) => Some(v),
            None => small_attribute(&group, prefix, "sensor_resolution")?,
        };
        let stated = sizes.as_deref().map(two_sizes).transpose()?;
        let at_root = root.datasets().map_err(library("the file's root"))?;
        let root_column = |name: &str| -> Result<Option<Column>, Hdf5Error> {
            if !at_root.iter().any(|n| n == name) {
                return Ok(None);
            }
            let dataset = file.dataset(name).map_err(library(name))?;
            Column::new(name.to_string(), dataset, Field::T, file_len).map(Some)
        };
        let t_offset = match root_column("t_offset")? {
            Some(c) if !columns[0].seconds() => {
                if c.len == 0 || c.seconds() {
                    return Err(Hdf5Error::Metadata {
                        object: "t_offset".into(),
                        reason: "is not an integer of microseconds".into(),
                    });
                }
                c.get(0)?
            }
            _ => 0,
        };
        let ms_to_idx = root_column("ms_to_idx")?;
        if let Some(index) = &ms_to_idx
            && (index.seconds() || index.scalar)
        {
            return Err(Hdf5Error::Metadata {
                object: "ms_to_idx".into(),
                reason: "holds floats, not event indices".into(),
            });
        }
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
            bytes,
            raw: Default::default(),
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
        let unit = if self.columns[0].seconds() {
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
        let bad = |reason: String| Hdf5Error::Metadata {
            object: "ms_to_idx".into(),
            reason,
        };
        let ms = index.len;
        if ms == 0 {
            return Err(bad("is empty".into()));
        }
        // ms_to_idx[k] is the first event with t >= k ms (after t_offset).
        let entry = |k: usize| -> Result<usize, Hdf5Error> {
            let v = usize::try_from(index.get(k)?).unwrap_or(usize::MAX);
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
            Ok(self.columns[0].get(i)?.saturating_add(self.t_offset))
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
        let start = self.next;
        let n = CHUNK.min(self.end - start);
        let [t, x, y, p] = &self.columns;
        let [rt, rx, ry, rp] = &mut self.raw;
        let file = &mut self.bytes;
        let raw = [
            t.raw_into(file, start, n, rt)?,
            x.raw_into(file, start, n, rx)?,
            y.raw_into(file, start, n, ry)?,
            p.raw_into(file, start, n, rp)?,
        ];
        let t_offset = self.t_offset;
        let kinds = [t, x, y, p].map(Column::fused_kind);
        let fused = match kinds {
            [Some(kt), Some(kx), Some(ky), Some(kp)] => fused::decode(
                [kt, kx, ky, kp],
                raw,
                t_offset,
                self.check.resolution(),
                &mut self.events,
            ),
            _ => None,
        };
        let base = self.checked_from as u64;
        let checked = match fused {
            Some(d) if d.valid => self.check.check_summarized(&self.events, d.summary),
            _ => {
                // The checked path: one pass per column, each value checked as it is decoded, so
                // the error names the first bad one.
                let ev = &mut self.events;
                ev.clear();
                ev.resize(n, Event::default());
                t.times(raw[0], start, ev, |e, t| {
                    e.t = t
                        .checked_add(t_offset)
                        .ok_or_else(|| format!("{t} + t_offset overflows"))?;
                    Ok(())
                })?;
                x.ints(raw[1], start, ev, |e, x| {
                    e.x = pixel("x", x)?;
                    Ok(())
                })?;
                y.ints(raw[2], start, ev, |e, y| {
                    e.y = pixel("y", y)?;
                    Ok(())
                })?;
                p.ints(raw[3], start, ev, |e, p| {
                    e.polarity = polarity(Some(p))?;
                    Ok(())
                })?;
                self.check.check(&self.events)
            }
        };
        checked.map_err(|error| Hdf5Error::Event {
            index: base + error.index(),
            error,
        })?;
        self.next = start + n;
        Ok(Some(&self.events))
    }
}

/// A pixel coordinate, `axis` naming it in the reason it is refused.
fn pixel(axis: &str, v: i64) -> Result<u16, String> {
    u16::try_from(v).map_err(|_| {
        if v < 0 {
            format!("negative coordinate ({axis}={v})")
        } else {
            format!("coordinate beyond 65535 ({axis}={v})")
        }
    })
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
/// error, never a panic.
pub fn fuzz_decode(bytes: &[u8]) -> Result<usize, Hdf5Error> {
    let mut reader = Hdf5Reader::from_bytes(bytes.to_vec())?;
    let mut n = 0;
    let _ = reader.select_range(0, 1_000_000);
    while let Some(chunk) = reader.next_chunk()? {
        n += chunk.len();
    }
    Ok(n)
}
