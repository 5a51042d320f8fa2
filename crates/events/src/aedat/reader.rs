//! The streaming AEDAT 4.0 reader: files (magic, header, packets, data table) and DV network
//! streams (header and packets only), from any `Read`.

use std::fs::File;
use std::io::{self, BufReader, Read};
use std::path::Path;

use super::compression::{Decompressor, MAX_PACKET_BYTES};
use super::error::{AedatError, Result};
use super::header::{AedatHeader, Compression, MAGIC, StreamKind};
use super::packet::{self, StreamState};
use crate::{Event, ImuSample, Resolution, Trigger};

/// Largest `IOHeader` accepted (DV's are a few KiB: the XML description of a handful of streams).
const MAX_HEADER_BYTES: u64 = 16 << 20;

/// One decoded packet: the elements of one stream, borrowed from the reader's reused buffers.
/// Exactly one of `events`, `imu`, `triggers` is non-empty (or none, for an empty packet).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AedatChunk<'a> {
    /// The stream the packet belongs to (see [`AedatHeader::streams`]).
    pub stream_id: i32,
    /// Byte offset of the packet's 8-byte header in the input.
    pub offset: u64,
    /// Events (from an `EVTS` stream).
    pub events: &'a [Event],
    /// IMU samples (from an `IMUS` stream).
    pub imu: &'a [ImuSample],
    /// Triggers (from a `TRIG` stream).
    pub triggers: &'a [Trigger],
}

/// File or network framing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    File,
    Network,
}

/// Reads AEDAT 4.0 packet by packet, handing out chunks that borrow reused buffers: memory stays
/// bounded by the largest packet whatever the file size. Works with any [`Read`], including one
/// that returns a single byte per call; wrap unbuffered sources (files, sockets) in a
/// [`BufReader`] for speed ([`AedatReader::open`] does).
///
/// ```no_run
/// use evtac_events::aedat::AedatReader;
///
/// let mut reader = AedatReader::open("recording.aedat4")?;
/// println!("{:?} from {:?}", reader.resolution(), reader.source());
/// let mut on = 0;
/// while let Some(chunk) = reader.next_chunk()? {
///     on += chunk.events.iter().filter(|e| e.polarity).count();
/// }
/// println!("{on} ON events");
/// # Ok::<(), evtac_events::aedat::AedatError>(())
/// ```
pub struct AedatReader<R> {
    reader: R,
    mode: Mode,
    header: AedatHeader,
    /// Bytes consumed so far.
    offset: u64,
    decompressor: Decompressor,
    streams: Vec<StreamState>,
    events: Vec<Event>,
    imu: Vec<ImuSample>,
    triggers: Vec<Trigger>,
    /// Set at the end of the data or after an error: the reader then yields nothing more.
    finished: bool,
}

impl AedatReader<BufReader<File>> {
    /// Opens an AEDAT 4.0 file (buffered).
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        let file = File::open(path).map_err(|source| AedatError::Io { offset: 0, source })?;
        Self::new(BufReader::with_capacity(1 << 16, file))
    }
}

impl<'a> AedatReader<&'a [u8]> {
    /// Reads an AEDAT 4.0 file held in memory.
    pub fn from_slice(bytes: &'a [u8]) -> Result<Self> {
        Self::new(bytes)
    }
}

/// Reads until `buf` is full or the input ends; returns the number of bytes read.
fn read_up_to(reader: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match reader.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

impl<R: Read> AedatReader<R> {
    /// Starts reading an AEDAT 4.0 file: checks the magic and parses the header.
    pub fn new(reader: R) -> Result<Self> {
        Self::start(reader, Mode::File)
    }

    /// Starts reading a DV network stream (what `dv.io.NetworkWriter` serves over TCP or a local
    /// socket): the same size-prefixed `IOHeader` and packets as a file, without the magic and
    /// without a data table; the stream ends when the input does (at a packet boundary).
    pub fn network(reader: R) -> Result<Self> {
        Self::start(reader, Mode::Network)
    }

    fn start(mut reader: R, mode: Mode) -> Result<Self> {
        let io = |offset| move |source| AedatError::Io { offset, source };
        let mut offset = 0u64;
        if mode == Mode::File {
            let mut magic = [0u8; 14];
            let n = read_up_to(&mut reader, &mut magic).map_err(io(0))?;
            if magic[..n] != MAGIC[..n] || n == 0 {
                return Err(AedatError::BadMagic {
                    found: String::from_utf8_lossy(&magic[..n]).into_owned(),
                });
            }
            if n < MAGIC.len() {
                return Err(AedatError::TruncatedHeader {
                    offset: n as u64,
                    needed: (MAGIC.len() - n) as u64,
                });
            }
            offset = MAGIC.len() as u64;
        }
        let mut prefix = [0u8; 4];
        let n = read_up_to(&mut reader, &mut prefix).map_err(io(offset))?;
        if n < 4 {
            return Err(AedatError::TruncatedHeader {
                offset: offset + n as u64,
                needed: (4 - n) as u64,
            });
        }
        let size = u64::from(u32::from_le_bytes(prefix));
        if size > MAX_HEADER_BYTES {
            return Err(AedatError::BadSize {
                field: "IOHeader size",
                offset,
                value: size as i64,
                limit: MAX_HEADER_BYTES,
            });
        }
        let mut buf = prefix.to_vec();
        let got = (&mut reader)
            .take(size)
            .read_to_end(&mut buf)
            .map_err(io(offset + 4))? as u64;
        if got < size {
            return Err(AedatError::TruncatedHeader {
                offset: offset + 4 + got,
                needed: size - got,
            });
        }
        let mut header = AedatHeader::parse(&buf, offset)?;
        if mode == Mode::Network {
            // A network stream has no data table, whatever the header says.
            header.data_table_position = None;
        }
        let streams = header
            .streams
            .iter()
            .map(|s| StreamState {
                id: s.id,
                kind: s.kind.clone(),
                resolution: s.resolution,
                count: 0,
                last_t: i64::MIN,
            })
            .collect();
        Ok(Self {
            reader,
            mode,
            decompressor: Decompressor::new(header.compression),
            header,
            offset: offset + 4 + size,
            streams,
            events: Vec::new(),
            imu: Vec::new(),
            triggers: Vec::new(),
            finished: false,
        })
    }

    /// Everything the header says (streams, compression, data-table position, XML).
    pub fn header(&self) -> &AedatHeader {
        &self.header
    }

    /// The event stream's declared resolution.
    pub fn resolution(&self) -> Option<Resolution> {
        self.header.resolution()
    }

    /// The camera name (`source` in the stream description).
    pub fn source(&self) -> Option<&str> {
        self.header.source()
    }

    /// The packets' compression.
    pub fn compression(&self) -> Compression {
        self.header.compression
    }

    /// Bytes consumed from the input so far.
    pub fn offset(&self) -> u64 {
        self.offset
    }

    /// Gives back the underlying reader.
    pub fn into_inner(self) -> R {
        self.reader
    }

    /// Decodes the next packet of events, IMU samples or triggers (frame packets and unknown
    /// types are skipped). `Ok(None)` at the end of the data: the data table in a file, or the
    /// end of input at a packet boundary. Truncation or corruption is an error; after an error
    /// the reader is finished and returns `Ok(None)`.
    pub fn next_chunk(&mut self) -> Result<Option<AedatChunk<'_>>> {
        if self.finished {
            return Ok(None);
        }
        match self.next_packet() {
            Ok(Some((stream_id, offset, index))) => {
                let kind = &self.streams[index].kind;
                let (events, imu, triggers): (&[Event], &[ImuSample], &[Trigger]) = match kind {
                    StreamKind::Events => (&self.events, &[], &[]),
                    StreamKind::Imu => (&[], &self.imu, &[]),
                    _ => (&[], &[], &self.triggers),
                };
                Ok(Some(AedatChunk {
                    stream_id,
                    offset,
                    events,
                    imu,
                    triggers,
                }))
            }
            Ok(None) => {
                self.finished = true;
                Ok(None)
            }
            Err(e) => {
                self.finished = true;
                Err(e)
            }
        }
    }

    /// Reads and decodes packets until one of a decoded kind; returns its stream id, offset and
    /// index into `self.streams`.
    fn next_packet(&mut self) -> Result<Option<(i32, u64, usize)>> {
        loop {
            let offset = self.offset;
            if self.header.data_table_position == Some(offset) {
                self.check_data_table(offset)?;
                return Ok(None);
            }
            let mut head = [0u8; 8];
            let n = read_up_to(&mut self.reader, &mut head)
                .map_err(|source| AedatError::Io { offset, source })?;
            if n == 0 {
                return match self.header.data_table_position {
                    Some(table) if self.mode == Mode::File => Err(AedatError::MissingDataTable {
                        offset,
                        data_table: table,
                    }),
                    _ => Ok(None),
                };
            }
            let [s0, s1, s2, s3, z0, z1, z2, z3] = head;
            let stream_id = i32::from_le_bytes([s0, s1, s2, s3]);
            if n < 8 {
                return Err(AedatError::TruncatedPacket {
                    offset,
                    stream_id: -1,
                    expected: 8,
                    got: n as u64,
                });
            }
            let size = i32::from_le_bytes([z0, z1, z2, z3]);
            let size = u64::try_from(size).map_err(|_| AedatError::BadSize {
                field: "packet size",
                offset,
                value: size.into(),
                limit: MAX_PACKET_BYTES,
            })?;
            if let Some(table) = self.header.data_table_position
                && offset + 8 + size > table
            {
                return Err(AedatError::PacketOverlapsDataTable {
                    offset,
                    stream_id,
                    size,
                    data_table: table,
                });
            }
            let index = self
                .streams
                .iter()
                .position(|s| s.id == stream_id)
                .ok_or(AedatError::UnknownStream { offset, stream_id })?;
            // `take` + `read_to_end` grows the buffer as bytes arrive, so a corrupt size cannot
            // allocate more than the input actually holds.
            let input = self.decompressor.input();
            input.reserve(size.min(1 << 20) as usize);
            let got = (&mut self.reader)
                .take(size)
                .read_to_end(input)
                .map_err(|source| AedatError::Io {
                    offset: offset + 8,
                    source,
                })? as u64;
            self.offset = offset + 8 + got;
            if got < size {
                return Err(AedatError::TruncatedPacket {
                    offset,
                    stream_id,
                    expected: size + 8,
                    got: got + 8,
                });
            }
            let state = &mut self.streams[index];
            if !matches!(
                state.kind,
                StreamKind::Events | StreamKind::Imu | StreamKind::Triggers
            ) {
                continue;
            }
            let payload =
                self.decompressor
                    .decompress()
                    .map_err(|reason| AedatError::Decompression {
                        offset,
                        stream_id,
                        compression: self.header.compression.name(),
                        reason,
                    })?;
            match state.kind {
                StreamKind::Events => {
                    packet::decode_events(payload, state, offset, &mut self.events)?
                }
                StreamKind::Imu => packet::decode_imu(payload, state, offset, &mut self.imu)?,
                _ => packet::decode_triggers(payload, state, offset, &mut self.triggers)?,
            }
            return Ok(Some((stream_id, offset, index)));
        }
    }

    /// Reads the data table at `offset` (the rest of the file) and verifies it, so that a file
    /// cut at or inside its data table is reported rather than taken as complete.
    fn check_data_table(&mut self, offset: u64) -> Result<()> {
        let input = self.decompressor.input();
        let got = (&mut self.reader)
            .take(MAX_PACKET_BYTES)
            .read_to_end(input)
            .map_err(|source| AedatError::Io { offset, source })? as u64;
        self.offset = offset + got;
        if got == 0 {
            return Err(AedatError::MissingDataTable {
                offset,
                data_table: offset,
            });
        }
        let payload =
            self.decompressor
                .decompress()
                .map_err(|reason| AedatError::Decompression {
                    offset,
                    stream_id: -1,
                    compression: self.header.compression.name(),
                    reason,
                })?;
        packet::check_data_table(payload, offset)
    }

    /// An iterator over the events of every event stream, one `Result` per event (convenient, but
    /// slower than [`Self::next_chunk`]).
    pub fn into_events(self) -> Events<R> {
        Events {
            reader: self,
            pos: 0,
        }
    }
}

/// Iterator over events, from [`AedatReader::into_events`].
pub struct Events<R> {
    reader: AedatReader<R>,
    pos: usize,
}

impl<R: Read> Iterator for Events<R> {
    type Item = Result<Event>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(&e) = self.reader.events.get(self.pos) {
                self.pos += 1;
                return Some(Ok(e));
            }
            self.pos = 0;
            match self.reader.next_chunk() {
                Ok(Some(chunk)) => {
                    // Only event chunks leave `events` to iterate; clear it otherwise.
                    if chunk.events.is_empty() {
                        self.reader.events.clear();
                    }
                }
                Ok(None) => return None,
                Err(e) => return Some(Err(e)),
            }
        }
    }
}
