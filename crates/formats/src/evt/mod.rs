//! Prophesee EVT 2.0, EVT 2.1 and EVT 3.0 raw files (with their `%` text header).
//!
//! [`EvtReader`] streams any [`Read`]: it parses the header, then decodes fixed-size reads into
//! reused event and trigger buffers, carrying a word that straddles two reads over to the next.
//! Timestamps and vector decoding follow Prophesee's own decoders (openeb), without time shifting,
//! so the times are the camera's. Events outside the sensor and timestamps that go backwards
//! are errors (where Prophesee's decoder silently drops rows beyond the sensor height), as is a
//! file that ends inside a word.
//!
//! ```no_run
//! use evtac_formats::evt::EvtReader;
//!
//! let mut reader = EvtReader::from_path("recording.raw")?;
//! let mut count = 0;
//! while let Some(chunk) = reader.next_chunk()? {
//!     count += chunk.events.len();
//! }
//! println!("{count} events, {:?}", reader.header().resolution);
//! # Ok::<(), evtac_formats::evt::EvtError>(())
//! ```

mod evt2;
mod evt21;
mod evt3;
pub(crate) mod family;
mod header;

use std::fs::File;
use std::io::Read;
use std::path::Path;

pub use header::{EvtVersion, Header, HeaderError};

/// The EVT 3.0 word decoder, for the ROS bags' `evt3` event packets ([`crate::ros`]).
pub(crate) use evt3::Evt3Decoder;

use crate::check::{CheckError, EventCheck};
use crate::text_header::{self, DataBuffer, HeaderReadError};
use crate::{Event, Resolution, Trigger};

/// What can go wrong reading an EVT file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EvtError {
    /// Reading the source failed.
    #[error("read failed: {0}")]
    Io(std::io::Error),
    /// The source holds no bytes at all.
    #[error("the file is empty")]
    Empty,
    /// The source does not start with a `%` header line.
    #[error("no `%` text header at the start: not a Prophesee EVT file")]
    NoHeader,
    /// The header ended without a line break, or never ended.
    #[error("the text header is cut off at byte {offset}")]
    TruncatedHeader {
        /// Offset where the header stops.
        offset: u64,
    },
    /// A header field is missing or malformed.
    #[error("bad header: {0}")]
    Header(HeaderError),
    /// The data ends inside a word.
    #[error(
        "truncated: the file ends {got} byte(s) into a {word}-byte word at byte offset {offset}"
    )]
    Truncated {
        /// Offset of the incomplete word.
        offset: u64,
        /// Bytes of it present.
        got: usize,
        /// Size of a word.
        word: usize,
    },
    /// A decoded event is invalid (outside the sensor, or earlier than its predecessor).
    #[error("{error} (in the data chunk ending at byte offset {offset})")]
    Event {
        /// What is wrong with it.
        error: CheckError,
        /// Offset of the end of the data decoded when the problem was found.
        offset: u64,
    },
}

// Not `#[from]`: that would also make the I/O error the `source()`, and `{:#}` chains would
// print its message twice (it is already part of ours).
impl From<std::io::Error> for EvtError {
    fn from(error: std::io::Error) -> Self {
        Self::Io(error)
    }
}

/// One decoded chunk: views into the reader's reused buffers.
#[derive(Debug, Clone, Copy)]
pub struct EvtChunk<'a> {
    /// CD events, in file order.
    pub events: &'a [Event],
    /// External triggers (rising edge = AEDAT4 code 1, falling = 2).
    pub triggers: &'a [Trigger],
}

#[derive(Debug, Clone)]
enum Decoder {
    Evt2(evt2::Evt2Decoder),
    Evt21(evt21::Evt21Decoder),
    Evt3(evt3::Evt3Decoder),
}

/// A streaming EVT 2.0 / 2.1 / 3.0 reader over any [`Read`].
#[derive(Debug)]
pub struct EvtReader<R> {
    data: DataBuffer<R>,
    header: Header,
    decoder: Decoder,
    events: Vec<Event>,
    triggers: Vec<Trigger>,
    check: EventCheck,
}

impl EvtReader<File> {
    /// Opens the file at `path`.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, EvtError> {
        Self::new(File::open(path)?)
    }
}

impl<'a> EvtReader<&'a [u8]> {
    /// Reads from bytes in memory.
    pub fn from_slice(bytes: &'a [u8]) -> Result<Self, EvtError> {
        Self::new(bytes)
    }
}

impl<R: Read> EvtReader<R> {
    /// Reads and parses the header from `source`, leaving it at the first data byte.
    pub fn new(mut source: R) -> Result<Self, EvtError> {
        let mut text = text_header::read(&mut source, b'%', |line| {
            header::split_line(line).0 == "end"
        })
        .map_err(|error| match error {
            HeaderReadError::Io(error) => EvtError::Io(error),
            HeaderReadError::Empty => EvtError::Empty,
            HeaderReadError::Truncated(offset) => EvtError::TruncatedHeader { offset },
        })?;
        let fields = text
            .lines
            .iter()
            .map(|line| header::split_line(line))
            .take_while(|(key, _)| key != "end")
            .collect();
        if text.len == 0 {
            return Err(EvtError::NoHeader);
        }
        let header = header::parse_fields(fields, text.len as u64).map_err(EvtError::Header)?;
        let decoder = match header.version {
            EvtVersion::Evt2 => Decoder::Evt2(evt2::Evt2Decoder::default()),
            EvtVersion::Evt21 => Decoder::Evt21(evt21::Evt21Decoder::default()),
            EvtVersion::Evt3 => Decoder::Evt3(evt3::Evt3Decoder::default()),
        };
        let check = EventCheck::new(header.resolution);
        Ok(Self {
            data: DataBuffer::after(source, &mut text),
            decoder,
            events: Vec::new(),
            triggers: Vec::new(),
            check,
            header,
        })
    }

    /// The parsed header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The sensor size the events are checked against (from the header, or set by
    /// [`set_resolution`](Self::set_resolution)).
    pub fn resolution(&self) -> Option<Resolution> {
        self.check.resolution()
    }

    /// Declares the sensor size for a file whose header does not state it (or overrides it):
    /// events from now on are checked against it.
    pub fn set_resolution(&mut self, resolution: Resolution) {
        self.check.set_resolution(Some(resolution));
    }

    /// Bytes of the source consumed so far (header included).
    pub fn position(&self) -> u64 {
        self.data.position()
    }

    /// Decodes the next chunk; `Ok(None)` at the end of the data. Chunks hold at least one event
    /// or trigger.
    pub fn next_chunk(&mut self) -> Result<Option<EvtChunk<'_>>, EvtError> {
        let word = self.header.version.word_size();
        self.events.clear();
        self.triggers.clear();
        loop {
            let available = self.data.bytes().len();
            let whole = available - available % word;
            if whole > 0 {
                let bytes = &self.data.bytes()[..whole];
                // `events` is empty before each decode (the loop goes round again only when
                // nothing was decoded), so an EVT2 summary covers every event checked.
                let resolution = self.check.resolution();
                let summary = match &mut self.decoder {
                    Decoder::Evt2(d) => {
                        Some(d.decode(bytes, &mut self.events, &mut self.triggers, resolution))
                    }
                    Decoder::Evt21(d) => {
                        d.decode(bytes, &mut self.events, &mut self.triggers);
                        None
                    }
                    Decoder::Evt3(d) => {
                        d.decode(bytes, &mut self.events, &mut self.triggers);
                        None
                    }
                };
                self.data.consume(whole);
                let offset = self.data.offset();
                match summary {
                    Some(summary) => self.check.check_summarized(&self.events, summary),
                    None => self.check.check(&self.events),
                }
                .map_err(|error| EvtError::Event { error, offset })?;
                if !self.events.is_empty() || !self.triggers.is_empty() {
                    return Ok(Some(EvtChunk {
                        events: &self.events,
                        triggers: &self.triggers,
                    }));
                }
                continue;
            }
            // Carry the partial word (if any) to the front and read more behind it.
            if self.data.refill()? == 0 {
                if available > 0 {
                    return Err(EvtError::Truncated {
                        offset: self.data.offset(),
                        got: available,
                        word,
                    });
                }
                return Ok(None);
            }
        }
    }
}

/// Decodes a whole EVT file held in memory, for fuzzing and tests: every event and trigger, or
/// the first error.
pub fn decode_all(bytes: &[u8]) -> Result<(Header, Vec<Event>, Vec<Trigger>), EvtError> {
    let mut reader = EvtReader::from_slice(bytes)?;
    let (mut events, mut triggers) = (Vec::new(), Vec::new());
    while let Some(chunk) = reader.next_chunk()? {
        events.extend_from_slice(chunk.events);
        triggers.extend_from_slice(chunk.triggers);
    }
    Ok((reader.header, events, triggers))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(header: &str, words: &[u16]) -> Vec<u8> {
        let mut bytes = header.as_bytes().to_vec();
        bytes.extend(words.iter().flat_map(|w| w.to_le_bytes()));
        bytes
    }

    #[test]
    fn reads_header_and_events() {
        let bytes = file(
            "% evt 3.0\r\n% geometry 16x8\n% end\n",
            &[0x8001, 0x0003, 0x2805],
        );
        let (header, events, _) = decode_all(&bytes).unwrap();
        assert_eq!(header.resolution, Some(Resolution::new(16, 8)));
        assert_eq!(header.len, 33);
        assert_eq!(
            events,
            vec![Event {
                t: 4096,
                x: 5,
                y: 3,
                polarity: true
            }]
        );
    }

    #[test]
    fn data_may_start_with_a_percent_sign_after_end() {
        // 0x2025 is an EVT_ADDR_X word whose first byte is `%`.
        let bytes = file(
            "% evt 3.0\n% geometry 64x8\n% end\n",
            &[0x8001, 0x0003, 0x2025],
        );
        let (_, events, _) = decode_all(&bytes).unwrap();
        assert_eq!(events.len(), 1);
        assert_eq!(events[0].x, 0x25);
    }

    #[test]
    fn errors_name_what_is_wrong() {
        assert!(matches!(decode_all(b""), Err(EvtError::Empty)));
        assert!(matches!(decode_all(b"\x00\x01"), Err(EvtError::NoHeader)));
        assert!(matches!(
            decode_all(b"% evt 3.0"),
            Err(EvtError::TruncatedHeader { offset: 9 })
        ));
        let mut bytes = file("% evt 3.0\n% geometry 16x8\n", &[0x8001, 0x0003]);
        bytes.push(0x05);
        let err = decode_all(&bytes).unwrap_err();
        assert!(
            matches!(
                err,
                EvtError::Truncated {
                    offset: 30,
                    got: 1,
                    word: 2
                }
            ),
            "{err}"
        );
        let bytes = file("% evt 3.0\n% geometry 16x8\n", &[0x8001, 0x0009, 0x2805]);
        let err = decode_all(&bytes).unwrap_err();
        assert!(err.to_string().contains("y=9"), "{err}");
    }
}
