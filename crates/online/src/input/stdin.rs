//! Standard input (`--input -`): an AEDAT4 file or DV network stream piped in, or CSV text.
//!
//! The first bytes tell which: the AEDAT4 magic `#!AER-DAT4.0`, a DV network stream's
//! size-prefixed `IOHeader` (file identifier `IOHE` at bytes 8..12), or anything else read as
//! `t,x,y,p` CSV.

use super::{ChunkInfo, EventSource, InputError, Next};
use crate::Notice;
use evtac_events::{Event, Resolution};
use evtac_formats::aedat::{AedatReader, MAGIC};
use evtac_formats::csv::CsvReader;
use std::io::{BufReader, Cursor, Read};

/// Bytes looked at to recognise the format.
const HEAD: usize = 16;

/// What is read: the bytes already looked at, then the rest of the input.
type Input = BufReader<std::io::Chain<Cursor<Vec<u8>>, Box<dyn Read + Send>>>;

enum Inner {
    Aedat(Box<AedatReader<Input>>),
    Csv(Box<CsvReader<Input>>),
}

/// Events from standard input (or any other byte stream).
pub struct StdinSource {
    inner: Inner,
    name: String,
    resolution: Option<Resolution>,
}

impl std::fmt::Debug for StdinSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StdinSource")
            .field("input", &self.name)
            .field("resolution", &self.resolution)
            .finish_non_exhaustive()
    }
}

impl StdinSource {
    /// Reads standard input; `sensor` declares the sensor size for CSV (and must match an
    /// AEDAT4 stream's own).
    pub fn open(sensor: Option<Resolution>) -> Result<Self, InputError> {
        Self::from_reader(Box::new(std::io::stdin()), "standard input", sensor)
    }

    /// Reads any byte stream the same way (`name` is used in messages).
    pub fn from_reader(
        mut reader: Box<dyn Read + Send>,
        name: &str,
        sensor: Option<Resolution>,
    ) -> Result<Self, InputError> {
        let name = name.to_string();
        let io = |source| InputError::Io {
            input: name.clone(),
            source,
        };
        let mut head = Vec::with_capacity(HEAD);
        (&mut reader)
            .take(HEAD as u64)
            .read_to_end(&mut head)
            .map_err(io)?;
        let is_aedat_file = head.starts_with(MAGIC);
        let is_network = head.get(8..12) == Some(b"IOHE".as_slice());
        let input: Input = BufReader::with_capacity(1 << 16, Cursor::new(head).chain(reader));
        let format = |reason: String| InputError::Format {
            input: name.clone(),
            reason,
        };
        let (inner, resolution) = if is_aedat_file || is_network {
            let r = if is_aedat_file {
                AedatReader::new(input)
            } else {
                AedatReader::network(input)
            }
            .map_err(|e| format(format!("AEDAT4 stream: {e}")))?;
            let found = r.resolution();
            if let (Some(declared), Some(found)) = (sensor, found)
                && declared != found
            {
                return Err(format(format!(
                    "the stream says the sensor is {found}, but {declared} was given"
                )));
            }
            (Inner::Aedat(Box::new(r)), found.or(sensor))
        } else {
            let mut r = CsvReader::new(input).map_err(|e| format(format!("CSV: {e}")))?;
            if let Some(sensor) = sensor {
                r.set_resolution(sensor);
            }
            (Inner::Csv(Box::new(r)), sensor)
        };
        Ok(Self {
            inner,
            name,
            resolution,
        })
    }

    /// The sensor size: the stream's own, or the one declared.
    pub fn resolution(&self) -> Option<Resolution> {
        self.resolution
    }
}

impl EventSource for StdinSource {
    fn next_chunk(&mut self, out: &mut Vec<Event>, _notify: &mut dyn FnMut(Notice)) -> Next {
        out.clear();
        let format = |reason: String| InputError::Format {
            input: self.name.clone(),
            reason,
        };
        match &mut self.inner {
            Inner::Aedat(r) => match r.next_chunk() {
                Ok(Some(chunk)) => out.extend_from_slice(chunk.events),
                Ok(None) => return Ok(None),
                Err(e) => return Err(format(format!("AEDAT4 stream: {e}"))),
            },
            Inner::Csv(r) => match r.next_chunk() {
                Ok(Some(events)) => out.extend_from_slice(events),
                Ok(None) => return Ok(None),
                Err(e) => return Err(format(format!("CSV: {e}"))),
            },
        }
        Ok(Some(ChunkInfo::default()))
    }
}
