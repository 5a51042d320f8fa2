//! NPZ event archives: what `np.savez` and `np.savez_compressed` write, a zip file of NPY
//! arrays, read whole.
//!
//! Two layouts are in use, and both are read:
//! - **one record array** (`np.savez(f, events=a)` with `a` an event record array, as
//!   [`crate::npy`] reads it), found as the archive's only member, or as its only member whose
//!   dtype is an event record;
//! - **one array per field** (`np.savez(f, t=t, x=x, y=y, p=p)`), the members named as
//!   [`Field`] accepts (`timestamp`, `polarity`, `xs`, ...), integer or bool, all of one length.
//!
//! The zip container's directory is the `zip` crate's (stored and deflate members, as numpy
//! writes); the NPY members are parsed by [`crate::npy`]. The archive is streamed, not read
//! whole: [`NpzReader`] hands out chunks of events as the NPY reader does, reading every member
//! it needs side by side from its own offset (the `member` module says why not through the
//! crate), so an archive of 5 M events costs buffers of one chunk rather than the columns and
//! the events in memory. Each member's size and CRC-32 are checked when it ends; a declared size
//! never decides an allocation.

mod fields;
mod member;

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use crate::check::CheckError;
use crate::columns::{Field, Slots};
use crate::npy::{self, NpyError, NpyReader};
use crate::{Event, Resolution};
use member::{Entry, Member, Shared};

/// What can go wrong reading an NPZ archive.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NpzError {
    /// The file is not a readable zip archive.
    #[error("not a readable NPZ (zip) archive: {0}")]
    Zip(String),
    /// A member could not be read as NPY.
    #[error("member `{member}`: {error}")]
    Member {
        /// The member's name in the archive.
        member: String,
        /// What is wrong with it.
        error: NpyError,
    },
    /// No member holds events.
    #[error(
        "no member holds events: the archive has {members:?}; expected one event record array, \
         or one array per field named {accepted}",
        accepted = Field::accepted()
    )]
    NoEvents {
        /// The members found.
        members: Vec<String>,
    },
    /// Several members are event record arrays and none was chosen.
    #[error("several members are event record arrays ({members:?}); keep one per archive")]
    Several {
        /// The candidate members.
        members: Vec<String>,
    },
    /// The per-field arrays differ in length.
    #[error("the field arrays differ in length: {lengths}")]
    Lengths {
        /// Each member with its length.
        lengths: String,
    },
    /// A value of a per-field array is not an event field.
    #[error("member `{member}`, element {index}: {reason}")]
    BadValue {
        /// The member's name.
        member: String,
        /// Zero-based element index.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A per-field event is invalid (outside the sensor, or earlier than its predecessor).
    #[error("{0}")]
    Event(CheckError),
}

/// The events of an NPZ archive, and which members held them.
#[derive(Debug, Clone, PartialEq)]
pub struct NpzEvents {
    /// The events, in the archive's order.
    pub events: Vec<Event>,
    /// The members read, `t, x, y, p` order for per-field arrays.
    pub members: Vec<String>,
}

impl NpzEvents {
    /// A line for `evtac info`: where the events came from.
    pub fn note(&self) -> String {
        note(&self.members)
    }
}

/// Reads the NPZ archive at `path` whole.
pub fn read(path: impl AsRef<Path>) -> Result<NpzEvents, NpzError> {
    NpzReader::from_path(path)?.read_to_end()
}

/// Reads a whole NPZ archive from any seekable source.
pub fn read_from<R: Read + Seek>(source: R) -> Result<NpzEvents, NpzError> {
    NpzReader::new(source)?.read_to_end()
}

/// A streaming reader of NPZ event archives: chunks of checked events, as [`NpyReader`] hands
/// them out.
#[derive(Debug)]
pub struct NpzReader<R> {
    inner: Inner<R>,
}

/// Where the events come from.
#[derive(Debug)]
enum Inner<R> {
    /// One event record array: the member's name and size, and an NPY reader of it.
    Records(String, u64, Box<NpyReader<Member<R>>>),
    /// One array per field.
    Fields(Box<fields::Fields<R>>),
}

impl NpzReader<File> {
    /// Opens the archive at `path`.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, NpzError> {
        let file = File::open(path).map_err(|e| NpzError::Zip(e.to_string()))?;
        Self::new(file)
    }
}

impl<R: Read + Seek> NpzReader<R> {
    /// Reads the archive's directory from `source` and the NPY headers of the members holding
    /// the events (see the module docs for which).
    pub fn new(mut source: R) -> Result<Self, NpzError> {
        let end = end_record(&mut source).map_err(|e| NpzError::Zip(e.to_string()))?;
        let mut archive =
            zip::ZipArchive::new(source).map_err(|e| NpzError::Zip(end.explain(e)))?;
        let members: Vec<String> = archive.file_names().map(str::to_string).collect();
        let stem = |m: &str| m.strip_suffix(".npy").unwrap_or(m).to_string();
        // One array per field, when the members' names say so.
        let mut slots = Slots::default();
        let mut named = true;
        for m in &members {
            if let Some(field) = Field::of(&stem(m)) {
                named &= slots.set(field, m.as_str(), m).is_ok();
            }
        }
        if named && let Ok(columns) = slots.complete() {
            let entries = columns.map(|name| entry(&mut archive, name));
            let names = columns.map(str::to_string);
            let shared = shared(archive);
            let mut opened = Vec::with_capacity(4);
            for e in entries {
                opened.push(Member::new(shared.clone(), e?));
            }
            let Ok(opened) = <[Member<R>; 4]>::try_from(opened) else {
                unreachable!("one member per field");
            };
            let fields = fields::Fields::new(names, opened)?;
            return Ok(Self {
                inner: Inner::Fields(Box::new(fields)),
            });
        }
        // Else the one event record array.
        let mut records = Vec::new();
        for m in &members {
            let mut entry = member(&mut archive, m)?;
            let is_record = npy::read_header(&mut entry).is_ok_and(|(h, _)| h.layout().is_ok());
            if is_record || members.len() == 1 {
                records.push(m.clone());
            }
        }
        match records.as_slice() {
            [one] => {
                let e = entry(&mut archive, one)?;
                let size = e.size;
                let reader = NpyReader::new(Member::new(shared(archive), e)).map_err(|error| {
                    NpzError::Member {
                        member: one.clone(),
                        error,
                    }
                })?;
                Ok(Self {
                    inner: Inner::Records(one.clone(), size, Box::new(reader)),
                })
            }
            [] => Err(NpzError::NoEvents { members }),
            _ => Err(NpzError::Several { members: records }),
        }
    }

    /// The members the events come from (`t, x, y, p` order for per-field arrays).
    pub fn members(&self) -> Vec<String> {
        match &self.inner {
            Inner::Records(name, ..) => vec![name.clone()],
            Inner::Fields(f) => f.names().to_vec(),
        }
    }

    /// A line for `evtac info`: where the events came from.
    pub fn note(&self) -> String {
        note(&self.members())
    }

    /// The sensor size events are checked against, if one was set.
    pub fn resolution(&self) -> Option<Resolution> {
        match &self.inner {
            Inner::Records(.., r) => r.resolution(),
            Inner::Fields(f) => f.resolution(),
        }
    }

    /// Declares the sensor size: events from now on must lie inside it.
    pub fn set_resolution(&mut self, resolution: Resolution) {
        match &mut self.inner {
            Inner::Records(.., r) => r.set_resolution(resolution),
            Inner::Fields(f) => f.check().set_resolution(Some(resolution)),
        }
    }

    /// The share of the events read so far, from 0 to 1 (for progress bars).
    pub fn progress(&self) -> f64 {
        let (done, all) = match &self.inner {
            Inner::Records(_, size, r) => (r.position(), *size),
            Inner::Fields(f) => f.progress(),
        };
        done as f64 / all.max(1) as f64
    }

    /// The next chunk of events; `Ok(None)` after the last (every member read to its end).
    pub fn next_chunk(&mut self) -> Result<Option<&[Event]>, NpzError> {
        match &mut self.inner {
            Inner::Records(name, _, r) => r.next_chunk().map_err(|error| NpzError::Member {
                member: name.clone(),
                error,
            }),
            Inner::Fields(f) => f.next_chunk(),
        }
    }

    /// Every remaining event, with the members they came from.
    pub fn read_to_end(mut self) -> Result<NpzEvents, NpzError> {
        let mut events = Vec::new();
        while let Some(chunk) = self.next_chunk()? {
            events.extend_from_slice(chunk);
        }
        Ok(NpzEvents {
            events,
            members: self.members(),
        })
    }
}

/// The note for events read from `members`.
fn note(members: &[String]) -> String {
    match members {
        [one] => format!("events from the record array `{one}`"),
        many => format!("events from one array per field: {}", many.join(", ")),
    }
}

/// The archive's source, to be shared by the members read from it.
fn shared<R: Read + Seek>(archive: zip::ZipArchive<R>) -> Shared<R> {
    // The position is unknown: the first read of a member seeks.
    std::sync::Arc::new(std::sync::Mutex::new((archive.into_inner(), u64::MAX)))
}

/// Where the member `name` of `archive` lies, or the crate's reason it cannot be read.
fn entry<R: Read + Seek>(archive: &mut zip::ZipArchive<R>, name: &str) -> Result<Entry, NpzError> {
    Entry::of(archive, name).map_err(|e| NpzError::Member {
        member: name.to_string(),
        error: NpyError::Io(std::io::Error::other(e)),
    })
}

/// The member `name` of `archive`, ready to read.
fn member<'a, R: Read + Seek>(
    archive: &'a mut zip::ZipArchive<R>,
    name: &str,
) -> Result<zip::read::ZipFile<'a, R>, NpzError> {
    archive.by_name(name).map_err(|e| NpzError::Member {
        member: name.to_string(),
        error: NpyError::Io(std::io::Error::other(e)),
    })
}

/// Where a zip's end record is: the zip crate's errors do not say where the archive is broken,
/// and an error must (a cut file loses its end record, a damaged one points at the wrong place).
enum EndRecord {
    /// Not in the last `searched` bytes of the file.
    Missing { searched: u64 },
    /// At byte `at`, putting the central directory at byte `directory`.
    At { at: u64, directory: u64 },
}

/// The longest tail a zip's end record can be in: the record (22 bytes) and its comment (at
/// most 65,535).
const END_RECORD_SEARCH: u64 = 22 + 65_535;

/// Finds the last end record signature in the tail of `source`, and rewinds it.
fn end_record(source: &mut (impl Read + Seek)) -> std::io::Result<EndRecord> {
    let len = source.seek(SeekFrom::End(0))?;
    let searched = len.min(END_RECORD_SEARCH);
    source.seek(SeekFrom::Start(len - searched))?;
    let mut tail = Vec::new();
    source.take(searched).read_to_end(&mut tail)?;
    source.rewind()?;
    let found = tail
        .windows(22)
        .rposition(|w| w.starts_with(b"PK\x05\x06"))
        .map(|i| EndRecord::At {
            at: len - searched + i as u64,
            directory: u64::from(u32::from_le_bytes(
                tail[i + 16..i + 20].try_into().expect("4 bytes"),
            )),
        });
    Ok(found.unwrap_or(EndRecord::Missing { searched }))
}

impl EndRecord {
    /// The zip crate's error `e` on opening the archive, with where the archive is broken.
    fn explain(&self, e: zip::result::ZipError) -> String {
        match *self {
            EndRecord::Missing { searched } => format!(
                "no zip end record in the file's last {searched} bytes (a zip ends with one): \
                 the archive is cut short, or is not a zip ({e})"
            ),
            EndRecord::At { at, directory } => format!(
                "the end record at byte {at} puts the central directory at byte {directory}, \
                 which does not read: {e}"
            ),
        }
    }
}

/// Decodes `bytes` as an NPZ archive, for the fuzz target: any input gives events or an
/// error, never a panic or an allocation the input does not back.
pub fn fuzz_decode(bytes: &[u8]) -> Result<usize, NpzError> {
    let mut reader = NpzReader::new(std::io::Cursor::new(bytes))?;
    let mut n = 0;
    while let Some(chunk) = reader.next_chunk()? {
        n += chunk.len();
    }
    Ok(n)
}
