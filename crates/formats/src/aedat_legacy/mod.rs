//! The AEDAT files of older iniVation setups: AEDAT 2.0 (jAER) and AEDAT 3.1 (cAER), as the first
//! NeuroTac's DAVIS240 recorded them.
//!
//! Both start with `#` text header lines: `#!AER-DAT2.0` or `#!AER-DAT3.1` first, then comments
//! and settings. The data that follows differs:
//!
//! - AEDAT 2.0 ([`v2`]): big-endian 8-byte records (32-bit address, 32-bit timestamp in us) whose
//!   address layout depends on the camera. evtac decodes DAVIS240 and DAVIS346 polarity events
//!   (see [`v2`] for the layout, the flips and the timestamp wrap).
//! - AEDAT 3.1 ([`v3`]): little-endian packets of one event type each, behind a 28-byte header
//!   (iniVation's AEDAT 3.1 format description, libcaer's `events/common.h`); evtac decodes
//!   polarity, IMU6 and special (trigger, timestamp reset) events and skips the other types.
//!
//! [`LegacyReader`] streams any [`Read`] with reused buffers, carrying bytes that straddle two
//! reads over to the next; a file that ends inside a record or packet is an error naming the
//! offset, as is anything the layout does not allow. Nothing is allocated from a size a header
//! merely claims: packets are decoded (or skipped) as their bytes arrive.
//!
//! ```no_run
//! use evtac_formats::aedat_legacy::LegacyReader;
//!
//! let mut reader = LegacyReader::from_path("neurotac.aedat")?;
//! let mut on = 0;
//! while let Some(chunk) = reader.next_chunk()? {
//!     on += chunk.events.iter().filter(|e| e.polarity).count();
//! }
//! println!("{on} ON events, {:?} sensor", reader.resolution());
//! # Ok::<(), evtac_formats::aedat_legacy::LegacyError>(())
//! ```

pub(crate) mod family;
mod header;
pub mod v2;
pub mod v3;

use std::fs::File;
use std::io::Read;
use std::path::Path;

pub use header::{Header, Version, sniff};

use crate::check::{CheckError, EventCheck};
use crate::text_header::{self, DataBuffer, HeaderReadError};
use crate::{Event, ImuSample, Resolution, Trigger};

/// What can go wrong reading an AEDAT 2.0 or 3.1 file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LegacyError {
    /// Reading the source failed.
    #[error("read failed: {0}")]
    Io(std::io::Error),
    /// The source holds no bytes at all.
    #[error("the file is empty")]
    Empty,
    /// The first line is not `#!AER-DAT<version>`.
    #[error("the file does not start with `#!AER-DAT`: not an AEDAT 2.0 / 3.1 file")]
    NotAedat,
    /// The version line names a version evtac does not read here.
    #[error(
        "line 1: the version field after `#!AER-DAT` says `{version}`; evtac reads AEDAT 2.0, \
         3.1 and 4.0 (`#!AER-DAT4.0` and a line break)"
    )]
    UnsupportedVersion {
        /// The version as written after `#!AER-DAT`.
        version: String,
    },
    /// The text header never ends (no line break, or no `#!END-HEADER` in AEDAT 3.1).
    #[error("the text header is cut off at byte {offset}")]
    TruncatedHeader {
        /// Offset where the header stops.
        offset: u64,
    },
    /// An AEDAT 2.0 header names a camera whose address layout evtac does not decode.
    #[error(
        "line {line}: the `# AEChip:` field names the camera `{chip}`; evtac decodes AEDAT 2.0 \
         from DAVIS240 and DAVIS346 cameras only"
    )]
    UnsupportedChip {
        /// The header line (1-based).
        line: usize,
        /// The camera class named by the `# AEChip:` line.
        chip: String,
    },
    /// An AEDAT 3.1 header declares a data encoding other than `RAW`.
    #[error(
        "line {line}: the `#Format:` field says `{value}`; evtac reads the RAW (uncompressed) \
         format only"
    )]
    UnsupportedFormat {
        /// The header line (1-based).
        line: usize,
        /// The declared format.
        value: String,
    },
    /// The file ends inside a record, a packet header or a packet's events.
    #[error(
        "truncated: the file ends at byte {len}, inside the {what} that starts at byte offset \
         {offset} and needs {needed} byte(s)"
    )]
    Truncated {
        /// What was cut (`record`, `packet header`, `packet`).
        what: &'static str,
        /// Offset where it starts.
        offset: u64,
        /// Its size in bytes.
        needed: u64,
        /// Length of the file.
        len: u64,
    },
    /// An AEDAT 3.1 packet header holds a value the format does not allow.
    #[error("bad packet header at byte offset {offset}: {field} = {value} ({reason})")]
    BadPacket {
        /// Offset of the packet header.
        offset: u64,
        /// The field (`eventSize`, `eventCapacity`, ...).
        field: &'static str,
        /// Its value.
        value: i64,
        /// The limit it breaks.
        reason: &'static str,
    },
    /// An AEDAT 2.0 polarity event's address lies outside the sensor.
    #[error(
        "the record at byte offset {offset} (address {address:#010x}) has x address {x} and \
         y address {y}, outside the {width}x{height} sensor"
    )]
    AddressOutside {
        /// Offset of the record.
        offset: u64,
        /// Its address word.
        address: u32,
        /// Its raw x address.
        x: u32,
        /// Its raw y address.
        y: u32,
        /// Sensor width.
        width: u16,
        /// Sensor height.
        height: u16,
    },
    /// A decoded event is invalid (outside the sensor, or earlier than its predecessor).
    #[error("{error} (in the data ending at byte offset {offset})")]
    Event {
        /// What is wrong with it.
        error: CheckError,
        /// Offset of the end of the data decoded when the problem was found.
        offset: u64,
    },
}

// Not `#[from]`: that would also make the I/O error the `source()`, and `{:#}` chains would
// print its message twice.
impl From<std::io::Error> for LegacyError {
    fn from(error: std::io::Error) -> Self {
        Self::Io(error)
    }
}

/// One decoded chunk: views into the reader's reused buffers.
#[derive(Debug, Clone, Copy)]
pub struct LegacyChunk<'a> {
    /// Polarity events, in time order.
    pub events: &'a [Event],
    /// IMU samples (AEDAT 3.1 IMU6 events).
    pub imu: &'a [ImuSample],
    /// Triggers and timestamp resets (AEDAT 3.1 special events, AEDAT4 codes).
    pub triggers: &'a [Trigger],
}

/// What a decoder appends to.
#[derive(Debug, Default)]
pub(crate) struct Out {
    pub(crate) events: Vec<Event>,
    pub(crate) imu: Vec<ImuSample>,
    pub(crate) triggers: Vec<Trigger>,
}

impl Out {
    fn clear(&mut self) {
        self.events.clear();
        self.imu.clear();
        self.triggers.clear();
    }

    fn is_empty(&self) -> bool {
        self.events.is_empty() && self.imu.is_empty() && self.triggers.is_empty()
    }
}

#[derive(Debug, Clone)]
enum Decoder {
    V2(v2::Decoder),
    V3(v3::Decoder),
}

/// A streaming AEDAT 2.0 / 3.1 reader over any [`Read`].
#[derive(Debug)]
pub struct LegacyReader<R> {
    data: DataBuffer<R>,
    header: Header,
    decoder: Decoder,
    out: Out,
    check: EventCheck,
}

impl LegacyReader<File> {
    /// Opens the file at `path`.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, LegacyError> {
        Self::new(File::open(path)?)
    }
}

impl<'a> LegacyReader<&'a [u8]> {
    /// Reads from bytes in memory.
    pub fn from_slice(bytes: &'a [u8]) -> Result<Self, LegacyError> {
        Self::new(bytes)
    }
}

impl<R: Read> LegacyReader<R> {
    /// Reads and parses the header from `source`, leaving it at the first data byte.
    pub fn new(mut source: R) -> Result<Self, LegacyError> {
        let mut text = text_header::read(&mut source, b'#', |line| line == b"!END-HEADER")
            .map_err(|error| match error {
                HeaderReadError::Io(error) => LegacyError::Io(error),
                HeaderReadError::Empty => LegacyError::Empty,
                HeaderReadError::Truncated(offset) => LegacyError::TruncatedHeader { offset },
            })?;
        let lines = text
            .lines
            .iter()
            .map(|line| String::from_utf8_lossy(line).into_owned())
            .collect();
        let header = header::parse(lines, text.len as u64)?;
        let decoder = match header.version {
            Version::Aedat2 => Decoder::V2(v2::Decoder::new(header.resolution)),
            Version::Aedat31 => Decoder::V3(v3::Decoder::default()),
        };
        let check = EventCheck::new(header.resolution);
        Ok(Self {
            data: DataBuffer::after(source, &mut text),
            decoder,
            out: Out::default(),
            check,
            header,
        })
    }

    /// The parsed header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The sensor size the events are checked against (from the camera the header names, or
    /// set by [`set_resolution`](Self::set_resolution)).
    pub fn resolution(&self) -> Option<Resolution> {
        self.check.resolution()
    }

    /// Declares the sensor size for a file whose header names no camera evtac knows (AEDAT 3.1):
    /// events from now on are checked against it.
    pub fn set_resolution(&mut self, resolution: Resolution) {
        self.check.set_resolution(Some(resolution));
    }

    /// Bytes of the source consumed so far (header included).
    pub fn position(&self) -> u64 {
        self.data.position()
    }

    /// Decodes the next chunk; `Ok(None)` at the end of the data. Chunks hold at least one
    /// event, IMU sample or trigger.
    pub fn next_chunk(&mut self) -> Result<Option<LegacyChunk<'_>>, LegacyError> {
        self.out.clear();
        loop {
            let (bytes, at) = (self.data.bytes(), self.data.offset());
            let used = match &mut self.decoder {
                Decoder::V2(d) => d.decode(bytes, at, &mut self.out)?,
                Decoder::V3(d) => d.decode(bytes, at, &mut self.out)?,
            };
            self.data.consume(used);
            if used > 0 {
                let offset = self.data.offset();
                self.check
                    .check(&self.out.events)
                    .map_err(|error| LegacyError::Event { error, offset })?;
                if !self.out.is_empty() {
                    return Ok(Some(LegacyChunk {
                        events: &self.out.events,
                        imu: &self.out.imu,
                        triggers: &self.out.triggers,
                    }));
                }
                continue;
            }
            // Carry the partial record to the front and read more behind it.
            if self.data.refill()? == 0 {
                let (available, at) = (self.data.bytes().len(), self.data.offset());
                let len = at + available as u64;
                return match &self.decoder {
                    Decoder::V2(d) => d.finish(available, at, len),
                    Decoder::V3(d) => d.finish(available, at, len),
                }
                .map(|()| None);
            }
        }
    }
}

/// A whole AEDAT 2.0 / 3.1 file decoded in memory (for fuzzing and tests).
pub type Decoded = (Header, Vec<Event>, Vec<ImuSample>, Vec<Trigger>);

/// Decodes a whole AEDAT 2.0 / 3.1 file held in memory, for fuzzing and tests: every event, IMU
/// sample and trigger, or the first error.
pub fn decode_all(bytes: &[u8]) -> Result<Decoded, LegacyError> {
    let mut reader = LegacyReader::from_slice(bytes)?;
    let (mut events, mut imu, mut triggers) = (Vec::new(), Vec::new(), Vec::new());
    while let Some(chunk) = reader.next_chunk()? {
        events.extend_from_slice(chunk.events);
        imu.extend_from_slice(chunk.imu);
        triggers.extend_from_slice(chunk.triggers);
    }
    Ok((reader.header, events, imu, triggers))
}
