//! NPY event files: a one-dimensional array of the structured dtype
//! `[('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')]` (us, column, row, 1 = ON).
//!
//! The NPY header is parsed by hand: `ndarray-npy` reads plain numeric arrays only, not
//! structured (record) dtypes. The reader accepts the records other tools write: the fields in
//! any order and under the names of [`crate::columns::Field`] (dv-processing's `timestamp` and
//! `polarity`, the `aedat` package's `on`), as any little-endian integer or bool (`t` as `<u8`,
//! `p` as `|i1` or `|b1`, with -1 read as OFF), padding fields (`('', '|V3')`, written for
//! aligned dtypes), and format versions 1.0 to 3.0; it rejects anything else with an error
//! naming the field. The writer writes the packed form above (version 1.0). NPZ archives of
//! such arrays are read by [`crate::npy::npz`].
//!
//! ```
//! use evtac_formats::npy::{NpyReader, NpyWriter};
//! use evtac_events::Event;
//!
//! let mut writer = NpyWriter::new(std::io::Cursor::new(Vec::new()))?;
//! writer.write_events(&[Event { t: 5, x: 1, y: 2, polarity: true }])?;
//! let bytes = writer.finish()?.into_inner();
//! let mut reader = NpyReader::from_slice(&bytes)?;
//! assert_eq!(reader.len(), 1);
//! assert_eq!(reader.next_chunk()?.unwrap()[0].t, 5);
//! # Ok::<(), evtac_formats::npy::NpyError>(())
//! ```

pub(crate) mod family;
mod header;
pub mod npz;

pub(crate) use header::{Scalar, coordinates, polarity};

use std::fs::File;
use std::io::{BufWriter, ErrorKind, Read, Seek, SeekFrom, Write};
use std::path::Path;

use crate::check::{CheckError, EventCheck};
use crate::{Event, Resolution};

pub use header::Layout;

/// The NPY magic string.
pub const MAGIC: &[u8; 6] = b"\x93NUMPY";
/// Records decoded per chunk.
const CHUNK: usize = 1 << 14;

/// What can go wrong reading or writing NPY event files.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NpyError {
    /// Reading or writing failed.
    #[error("I/O failed: {0}")]
    Io(std::io::Error),
    /// The file holds no bytes.
    #[error("the file is empty")]
    Empty,
    /// The file does not start with `\x93NUMPY`.
    #[error("not an NPY file: the first bytes are not `\\x93NUMPY`")]
    BadMagic,
    /// An NPY format version evtac does not know.
    #[error("NPY format version {major}.{minor} is not supported (1.0, 2.0 and 3.0 are)")]
    UnsupportedVersion {
        /// Major version byte.
        major: u8,
        /// Minor version byte.
        minor: u8,
    },
    /// The file ends inside the header.
    #[error("the header is cut off: the file ends at byte {offset}, the header needs {needed}")]
    TruncatedHeader {
        /// Bytes present.
        offset: u64,
        /// Bytes the header declares.
        needed: u64,
    },
    /// The header dictionary is malformed or lacks a key.
    #[error("bad header: {0}")]
    BadHeader(String),
    /// The dtype is not the event record.
    #[error("unsupported dtype {descr}: {reason}")]
    UnsupportedDtype {
        /// The header's `descr` as written.
        descr: String,
        /// What does not match.
        reason: String,
    },
    /// The array is not one-dimensional in C order.
    #[error("header field `{field}`: {reason}")]
    BadShape {
        /// The header key (`shape` or `fortran_order`).
        field: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The data ends before the number of records the header declares.
    #[error(
        "truncated: the header declares {declared} records but the data ends after {complete} \
         (at byte offset {offset})"
    )]
    Truncated {
        /// Records declared by `shape`.
        declared: u64,
        /// Complete records present.
        complete: u64,
        /// Offset where the data ends.
        offset: u64,
    },
    /// Bytes follow the declared records.
    #[error("unexpected data after the {declared} declared records, at byte offset {offset}")]
    TrailingData {
        /// Records declared by `shape`.
        declared: u64,
        /// Offset of the first extra byte.
        offset: u64,
    },
    /// A record holds a value that is not an event.
    #[error("record {index} (byte offset {offset}): {reason}")]
    BadRecord {
        /// Zero-based record index.
        index: u64,
        /// Offset of the record.
        offset: u64,
        /// What is wrong with it.
        reason: String,
    },
    /// A decoded event is invalid (outside the sensor, or earlier than its predecessor).
    #[error("{error} (record at byte offset {offset})")]
    Event {
        /// What is wrong with it.
        error: CheckError,
        /// Offset of the record holding the event.
        offset: u64,
    },
    /// An event to write has a coordinate that `<i2` cannot hold.
    #[error("event {index} at (x={x}, y={y}) cannot be written: NPY coordinates must be <= 32767")]
    CoordinateTooLarge {
        /// Zero-based index of the event among those written.
        index: u64,
        /// Its column.
        x: u16,
        /// Its row.
        y: u16,
    },
}

// Not `#[from]`: that would also make the I/O error the `source()`, and `{:#}` chains would
// print its message twice (it is already part of ours).
impl From<std::io::Error> for NpyError {
    fn from(error: std::io::Error) -> Self {
        Self::Io(error)
    }
}

/// Reads into `buf` until it is full or the source ends; returns the bytes read.
pub(crate) fn read_full(source: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match source.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// A streaming reader of NPY event files over any [`Read`].
#[derive(Debug)]
pub struct NpyReader<R> {
    source: R,
    layout: Layout,
    declared: u64,
    /// Records decoded so far.
    done: u64,
    /// Offset of the first data byte.
    data_start: u64,
    buf: Vec<u8>,
    events: Vec<Event>,
    check: EventCheck,
}

impl NpyReader<File> {
    /// Opens the file at `path`.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, NpyError> {
        Self::new(File::open(path)?)
    }
}

impl<'a> NpyReader<&'a [u8]> {
    /// Reads from bytes in memory.
    pub fn from_slice(bytes: &'a [u8]) -> Result<Self, NpyError> {
        Self::new(bytes)
    }
}

/// Reads an NPY preamble and header from `source`: the parsed header and the offset of the
/// first data byte.
pub(crate) fn read_header(source: &mut impl Read) -> Result<(header::Header, u64), NpyError> {
    let mut preamble = [0u8; 12];
    let n = read_full(source, &mut preamble[..8])?;
    if n == 0 {
        return Err(NpyError::Empty);
    }
    if n < 6 || &preamble[..6] != MAGIC {
        return Err(NpyError::BadMagic);
    }
    if n < 8 {
        return Err(NpyError::TruncatedHeader {
            offset: n as u64,
            needed: 10,
        });
    }
    let (major, minor) = (preamble[6], preamble[7]);
    let len_bytes = match (major, minor) {
        (1, 0) => 2,
        (2, 0) | (3, 0) => 4,
        _ => return Err(NpyError::UnsupportedVersion { major, minor }),
    };
    let got = read_full(source, &mut preamble[8..8 + len_bytes])?;
    if got < len_bytes {
        return Err(NpyError::TruncatedHeader {
            offset: (8 + got) as u64,
            needed: (8 + len_bytes) as u64,
        });
    }
    let header_len = if len_bytes == 2 {
        u64::from(u16::from_le_bytes([preamble[8], preamble[9]]))
    } else {
        u64::from(u32::from_le_bytes([
            preamble[8],
            preamble[9],
            preamble[10],
            preamble[11],
        ]))
    };
    let start = 8 + len_bytes as u64;
    // A header this long is not one numpy writes for a record of four fields.
    if header_len > 1 << 20 {
        return Err(NpyError::BadHeader(format!(
            "the header length field (byte offset 8) claims {header_len} bytes"
        )));
    }
    // Read through `take`: the buffer grows with the bytes present, not with the claim.
    let mut text = Vec::new();
    let got = source.take(header_len).read_to_end(&mut text)?;
    if (got as u64) < header_len {
        return Err(NpyError::TruncatedHeader {
            offset: start + got as u64,
            needed: start + header_len,
        });
    }
    let text = std::str::from_utf8(&text).map_err(|e| {
        NpyError::BadHeader(format!(
            "the header is not valid UTF-8 text (bad byte at byte offset {})",
            start + e.valid_up_to() as u64
        ))
    })?;
    Ok((header::parse(text)?, start + header_len))
}

impl<R: Read> NpyReader<R> {
    /// Reads and checks the header from `source`.
    pub fn new(mut source: R) -> Result<Self, NpyError> {
        let (header, data_start) = read_header(&mut source)?;
        let layout = header.layout()?;
        Ok(Self {
            source,
            buf: Vec::new(),
            layout,
            declared: header.count,
            done: 0,
            data_start,
            events: Vec::with_capacity(CHUNK),
            check: EventCheck::new(None),
        })
    }

    /// Number of records the header declares.
    pub fn len(&self) -> u64 {
        self.declared
    }

    /// Whether the header declares no records.
    pub fn is_empty(&self) -> bool {
        self.declared == 0
    }

    /// Where each field sits in a record.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The sensor size events are checked against, if one was set.
    pub fn resolution(&self) -> Option<Resolution> {
        self.check.resolution()
    }

    /// Declares the sensor size: events from now on must lie inside it.
    pub fn set_resolution(&mut self, resolution: Resolution) {
        self.check.set_resolution(Some(resolution));
    }

    /// Bytes of the source consumed so far.
    pub fn position(&self) -> u64 {
        self.data_start + self.done * self.layout.itemsize as u64
    }

    /// Every remaining event, read chunk by chunk (the whole file for a fresh reader).
    pub fn read_to_end(mut self) -> Result<Vec<Event>, NpyError> {
        let mut out = Vec::new();
        while let Some(chunk) = self.next_chunk()? {
            out.extend_from_slice(chunk);
        }
        Ok(out)
    }

    /// The next chunk of events; `Ok(None)` after the last declared record (checking that no
    /// data follows).
    pub fn next_chunk(&mut self) -> Result<Option<&[Event]>, NpyError> {
        self.events.clear();
        let size = self.layout.itemsize;
        let remaining = self.declared - self.done;
        if remaining == 0 {
            let mut probe = [0u8; 1];
            if read_full(&mut self.source, &mut probe)? > 0 {
                return Err(NpyError::TrailingData {
                    declared: self.declared,
                    offset: self.position(),
                });
            }
            return Ok(None);
        }
        let records = remaining.min(CHUNK as u64) as usize;
        let bytes = records * size;
        // Grown by the bytes actually read, so a record count the data does not back costs
        // nothing; after the first chunk the capacity is reused.
        self.buf.clear();
        let got = (&mut self.source)
            .take(bytes as u64)
            .read_to_end(&mut self.buf)?;
        if got < bytes {
            return Err(NpyError::Truncated {
                declared: self.declared,
                complete: self.done + (got / size) as u64,
                offset: self.position() + got as u64,
            });
        }
        let l = &self.layout;
        for (i, record) in self.buf[..bytes].chunks_exact(size).enumerate() {
            match l.decode(record) {
                Ok(e) => self.events.push(e),
                Err(reason) => {
                    let index = self.done + i as u64;
                    return Err(NpyError::BadRecord {
                        index,
                        offset: self.data_start + index * size as u64,
                        reason,
                    });
                }
            }
        }
        self.done += records as u64;
        let (start, size) = (self.data_start, size as u64);
        self.check
            .check(&self.events)
            .map_err(|error| NpyError::Event {
                offset: start + error.index() * size,
                error,
            })?;
        Ok(Some(&self.events))
    }
}

/// Size of a packed record as written.
const RECORD: usize = 13;
/// The header is written at this fixed size so the record count can be patched in afterwards.
const HEADER_TOTAL: usize = 192;

/// The header bytes (magic to final line break) for `count` records.
fn header_bytes(count: u64) -> Vec<u8> {
    let dict = format!(
        "{{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')], \
         'fortran_order': False, 'shape': ({count},), }}"
    );
    let mut out = Vec::with_capacity(HEADER_TOTAL);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    let len = HEADER_TOTAL - 10;
    out.extend_from_slice(&(len as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    // Pad with spaces to the fixed size, ending with a line break (numpy's layout). The longest
    // dict (20-digit count) takes 137 bytes with the preamble, so it always fits.
    out.resize(HEADER_TOTAL - 1, b' ');
    out.push(b'\n');
    out
}

/// Writes NPY event files (packed `t <i8, x <i2, y <i2, p |u1`, format 1.0).
///
/// The record count is only known at the end, so the writer needs [`Seek`] to patch the header
/// in [`finish`](Self::finish).
#[derive(Debug)]
pub struct NpyWriter<W: Write + Seek> {
    sink: W,
    count: u64,
    buf: Vec<u8>,
}

impl NpyWriter<BufWriter<File>> {
    /// Creates (or truncates) the file at `path`.
    pub fn create(path: impl AsRef<Path>) -> Result<Self, NpyError> {
        Self::new(BufWriter::with_capacity(1 << 16, File::create(path)?))
    }
}

impl<W: Write + Seek> NpyWriter<W> {
    /// Starts an NPY file in `sink` (at its current position, which must be its start).
    pub fn new(mut sink: W) -> Result<Self, NpyError> {
        sink.write_all(&header_bytes(0))?;
        Ok(Self {
            sink,
            count: 0,
            buf: Vec::new(),
        })
    }

    /// Appends events.
    pub fn write_events(&mut self, events: &[Event]) -> Result<(), NpyError> {
        self.buf.clear();
        self.buf.reserve(events.len() * RECORD);
        for (i, e) in events.iter().enumerate() {
            if e.x > i16::MAX as u16 || e.y > i16::MAX as u16 {
                return Err(NpyError::CoordinateTooLarge {
                    index: self.count + i as u64,
                    x: e.x,
                    y: e.y,
                });
            }
            self.buf.extend_from_slice(&e.t.to_le_bytes());
            self.buf.extend_from_slice(&e.x.to_le_bytes());
            self.buf.extend_from_slice(&e.y.to_le_bytes());
            self.buf.push(u8::from(e.polarity));
        }
        self.sink.write_all(&self.buf)?;
        self.count += events.len() as u64;
        Ok(())
    }

    /// Writes the final record count into the header, flushes and returns the sink.
    pub fn finish(mut self) -> Result<W, NpyError> {
        self.sink.seek(SeekFrom::Start(0))?;
        self.sink.write_all(&header_bytes(self.count))?;
        self.sink.seek(SeekFrom::End(0))?;
        self.sink.flush()?;
        Ok(self.sink)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn write(events: &[Event]) -> Vec<u8> {
        let mut w = NpyWriter::new(Cursor::new(Vec::new())).unwrap();
        w.write_events(events).unwrap();
        w.finish().unwrap().into_inner()
    }

    fn read_all(bytes: &[u8]) -> Result<Vec<Event>, NpyError> {
        NpyReader::from_slice(bytes)?.read_to_end()
    }

    #[test]
    fn header_has_fixed_size_for_any_count() {
        assert_eq!(header_bytes(0).len(), HEADER_TOTAL);
        assert_eq!(header_bytes(u64::MAX).len(), HEADER_TOTAL);
        assert_eq!(header_bytes(u64::MAX)[HEADER_TOTAL - 2], b' ');
    }

    #[test]
    fn round_trip() {
        let events = vec![
            Event {
                t: -1,
                x: 0,
                y: 32767,
                polarity: false,
            },
            Event {
                t: 3,
                x: 639,
                y: 479,
                polarity: true,
            },
        ];
        let bytes = write(&events);
        assert_eq!(bytes.len(), HEADER_TOTAL + 2 * RECORD);
        assert_eq!(read_all(&bytes).unwrap(), events);
    }

    #[test]
    fn coordinates_beyond_i16_are_refused() {
        let mut w = NpyWriter::new(Cursor::new(Vec::new())).unwrap();
        let err = w
            .write_events(&[Event {
                x: 40000,
                ..Event::default()
            }])
            .unwrap_err();
        assert!(err.to_string().contains("x=40000"), "{err}");
    }

    #[test]
    fn truncation_and_trailing_bytes_are_errors() {
        let bytes = write(&[Event::default(); 3]);
        for cut in 0..bytes.len() {
            assert!(read_all(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let err = read_all(&bytes[..bytes.len() - 1]).unwrap_err();
        assert!(
            matches!(
                err,
                NpyError::Truncated {
                    declared: 3,
                    complete: 2,
                    ..
                }
            ),
            "{err}"
        );
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(matches!(
            read_all(&longer),
            Err(NpyError::TrailingData { .. })
        ));
    }

    #[test]
    fn polarity_other_than_0_or_1_is_named() {
        let mut bytes = write(&[Event::default()]);
        let last = bytes.len() - 1;
        bytes[last] = 7;
        let err = read_all(&bytes).unwrap_err();
        assert!(err.to_string().contains("record 0"), "{err}");
    }
}
