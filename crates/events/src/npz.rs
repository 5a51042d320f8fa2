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
//! The zip container is the `zip` crate's (stored and deflate members, as numpy writes); the
//! NPY members are parsed by [`crate::npy`]. Members are decompressed through a reader that grows
//! its buffer with the bytes actually inflated, so a member's declared size never decides an
//! allocation.

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use crate::Event;
use crate::columns::{Field, Slots};
use crate::npy::{self, NpyError, NpyReader, coordinates, polarity};

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
        match self.members.as_slice() {
            [one] => format!("events from the record array `{one}`"),
            many => format!("events from one array per field: {}", many.join(", ")),
        }
    }
}

/// Reads the NPZ archive at `path`.
pub fn read(path: impl AsRef<Path>) -> Result<NpzEvents, NpzError> {
    let file = std::fs::File::open(path).map_err(|e| NpzError::Zip(e.to_string()))?;
    read_from(std::io::BufReader::new(file))
}

/// Reads an NPZ archive from any seekable source.
pub fn read_from(mut source: impl Read + Seek) -> Result<NpzEvents, NpzError> {
    let end = end_record(&mut source).map_err(|e| NpzError::Zip(e.to_string()))?;
    let mut archive = zip::ZipArchive::new(source).map_err(|e| NpzError::Zip(end.explain(e)))?;
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
        return read_columns(&mut archive, columns);
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
            let entry = member(&mut archive, one)?;
            let events = NpyReader::new(entry)
                .and_then(NpyReader::read_to_end)
                .map_err(|error| NpzError::Member {
                    member: one.clone(),
                    error,
                })?;
            Ok(NpzEvents {
                events,
                members: records,
            })
        }
        [] => Err(NpzError::NoEvents { members }),
        _ => Err(NpzError::Several { members: records }),
    }
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

/// Builds events from the four per-field members (`t, x, y, p` order).
fn read_columns<R: Read + Seek>(
    archive: &mut zip::ZipArchive<R>,
    names: [&str; 4],
) -> Result<NpzEvents, NpzError> {
    let mut columns: Vec<Vec<i64>> = Vec::with_capacity(4);
    for name in names {
        let entry = member(archive, name)?;
        columns.push(npy::read_column(entry).map_err(|error| NpzError::Member {
            member: name.to_string(),
            error,
        })?);
    }
    let n = columns[0].len();
    if columns.iter().any(|c| c.len() != n) {
        let lengths = names
            .iter()
            .zip(&columns)
            .map(|(m, c)| format!("{m} {}", c.len()))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(NpzError::Lengths { lengths });
    }
    let [t, x, y, p] = [&columns[0], &columns[1], &columns[2], &columns[3]];
    let mut events = Vec::with_capacity(n);
    for i in 0..n {
        let bad = |member: &str, reason: String| NpzError::BadValue {
            member: member.to_string(),
            index: i,
            reason,
        };
        let (ex, ey) = coordinates(Some(x[i]), Some(y[i])).map_err(|r| bad(names[1], r))?;
        let polarity = polarity(Some(p[i])).map_err(|r| bad(names[3], r))?;
        events.push(Event {
            t: t[i],
            x: ex,
            y: ey,
            polarity,
        });
    }
    Ok(NpzEvents {
        events,
        members: names.iter().map(|s| s.to_string()).collect(),
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
    read_from(std::io::Cursor::new(bytes)).map(|e| e.events.len())
}
