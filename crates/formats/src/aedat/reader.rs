//! The streaming AEDAT 4.0 reader: files (magic, header, packets, data table) and DV network
//! streams (header and packets only), from any `Read`; with `Seek` too, a time range read
//! through the data table ([`AedatReader::select_range`]).

use std::fs::File;
use std::io::{self, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use super::compression::{Decompressor, MAX_PACKET_BYTES};
use super::error::{AedatError, Result};
use super::header::{AedatHeader, Compression, MAGIC, StreamKind};
use super::index::{self, Plan, PlannedPacket, Planner};
use super::packet::{self, StreamState};
use super::table_check::{self, ENTRIES_PER_PASS, Verdict};
use crate::range::{RangeIndex, ScanReason, retain_within};
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

/// Moves a seekable input to a byte offset (kept as a function pointer so that reading, which
/// needs only `Read`, can follow a plan made where `Seek` was available).
type SeekTo<R> = fn(&mut R, u64) -> io::Result<()>;

fn seek_to<R: Seek>(reader: &mut R, offset: u64) -> io::Result<()> {
    reader.seek(SeekFrom::Start(offset)).map(drop)
}

/// A range read in progress (see [`AedatReader::select_range`]).
struct RangeRead<R> {
    from: i64,
    to: i64,
    /// The packets the data table selected, or `None` while scanning.
    plan: Option<(Plan, SeekTo<R>)>,
}

/// What reading one packet gave.
enum Packet {
    /// The end of the input, at a packet boundary.
    End,
    /// A packet of a stream that is not decoded (frames, unknown types).
    Skipped,
    /// A decoded packet: stream id, offset, index into the reader's streams.
    Decoded(i32, u64, usize),
}

/// Reads AEDAT 4.0 packet by packet, handing out chunks that borrow reused buffers: memory stays
/// bounded by the largest packet whatever the file size. Works with any [`Read`], including one
/// that returns a single byte per call; wrap unbuffered sources (files, sockets) in a
/// [`BufReader`] for speed ([`AedatReader::open`] does).
///
/// ```no_run
/// use evtac_formats::aedat::AedatReader;
///
/// let mut reader = AedatReader::open("recording.aedat4")?;
/// println!("{:?} from {:?}", reader.resolution(), reader.source());
/// let mut on = 0;
/// while let Some(chunk) = reader.next_chunk()? {
///     on += chunk.events.iter().filter(|e| e.polarity).count();
/// }
/// println!("{on} ON events");
/// # Ok::<(), evtac_formats::aedat::AedatError>(())
/// ```
pub struct AedatReader<R> {
    reader: R,
    mode: Mode,
    header: AedatHeader,
    /// Bytes consumed so far.
    offset: u64,
    /// Offset of the first packet (just past the header).
    data_start: u64,
    /// Where the packets end: the data table, when there is one.
    table_end: Option<u64>,
    /// Decode this stream kind only ([`Self::triggers_only`], [`Self::imu_only`]).
    only: Option<StreamKind>,
    /// Whether to verify the data table on reaching it (not when a range read already found it
    /// unusable and said so).
    check_table: bool,
    /// How to seek, when the input can: the data table is then checked in passes over it,
    /// holding constant memory ([`table_check`]), rather than read whole.
    rewind: Option<SeekTo<R>>,
    decompressor: Decompressor,
    streams: Vec<StreamState>,
    events: Vec<Event>,
    imu: Vec<ImuSample>,
    triggers: Vec<Trigger>,
    /// The selected time range, if any.
    range: Option<RangeRead<R>>,
    /// Whether a range read plans from the data table streamed ([`table_check::plan`]) before
    /// falling back to the whole table (off in tests comparing the two).
    stream_table: bool,
    /// Set at the end of the data or after an error: the reader then yields nothing more.
    finished: bool,
}

impl AedatReader<BufReader<File>> {
    /// Opens an AEDAT 4.0 file (buffered).
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        let file = File::open(path).map_err(|source| AedatError::Io { offset: 0, source })?;
        let mut reader = Self::new(BufReader::with_capacity(1 << 16, file))?;
        reader.rewind = Some(seek_to);
        Ok(reader)
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
                decoded: decodable(&s.kind),
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
            table_end: header.data_table_position,
            check_table: true,
            only: None,
            stream_table: true,
            rewind: None,
            header,
            offset: offset + 4 + size,
            data_start: offset + 4 + size,
            streams,
            events: Vec::new(),
            imu: Vec::new(),
            triggers: Vec::new(),
            range: None,
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

    /// From now on, decodes only the streams `chosen` names, one of each kind (see
    /// [`StreamSelection::resolve`](crate::StreamSelection::resolve)): packets of the others are
    /// read past like frames. Without it, every event, IMU and trigger stream is decoded and
    /// their elements are handed out as they come, whatever stream they belong to
    /// ([`AedatChunk::stream_id`] tells).
    pub fn select_streams(&mut self, chosen: &super::ChosenStreams) {
        for s in &mut self.streams {
            s.decoded = decodable(&s.kind) && chosen.contains(s.id);
        }
    }

    /// From now on, decodes trigger packets only: event and IMU packets are read past like
    /// frames, undecoded (their data is not checked either), so that finding a long
    /// recording's triggers decompresses nothing else.
    pub fn triggers_only(&mut self) {
        self.only = Some(StreamKind::Triggers);
    }

    /// From now on, decodes IMU packets only (as [`Self::triggers_only`] does triggers), so
    /// that a pass over a long recording's IMU decompresses nothing else.
    pub fn imu_only(&mut self) {
        self.only = Some(StreamKind::Imu);
    }

    /// Decodes the next packet of events, IMU samples or triggers (frame packets and unknown
    /// types are skipped). `Ok(None)` at the end of the data: the data table in a file, or the
    /// end of input at a packet boundary. Truncation or corruption is an error; after an error
    /// the reader is finished and returns `Ok(None)`.
    ///
    /// After [`Self::select_range`], only elements inside the range are handed out, and packets
    /// with none are passed over: every chunk is non-empty.
    pub fn next_chunk(&mut self) -> Result<Option<AedatChunk<'_>>> {
        if self.finished {
            return Ok(None);
        }
        loop {
            let next = if self.range.as_ref().is_some_and(|r| r.plan.is_some()) {
                self.next_planned()
            } else {
                self.next_packet()
            };
            match next {
                Ok(Some((stream_id, offset, index))) => {
                    if self.keep_range(index) {
                        return Ok(Some(self.chunk(stream_id, offset, index)));
                    }
                }
                Ok(None) => {
                    self.finished = true;
                    return Ok(None);
                }
                Err(e) => {
                    self.finished = true;
                    return Err(e);
                }
            }
        }
    }

    /// Cuts the just-decoded elements of stream `index` to the selected range; whether any are
    /// left (always true without a range).
    fn keep_range(&mut self, index: usize) -> bool {
        let Some(range) = &self.range else {
            return true;
        };
        let (from, to) = (range.from, range.to);
        match self.streams[index].kind {
            StreamKind::Events => {
                retain_within(&mut self.events, |e| e.t, from, to);
                !self.events.is_empty()
            }
            StreamKind::Imu => {
                retain_within(&mut self.imu, |s| s.t, from, to);
                !self.imu.is_empty()
            }
            _ => {
                retain_within(&mut self.triggers, |t| t.t, from, to);
                !self.triggers.is_empty()
            }
        }
    }

    /// The chunk of the packet just decoded.
    fn chunk(&self, stream_id: i32, offset: u64, index: usize) -> AedatChunk<'_> {
        let (events, imu, triggers): (&[Event], &[ImuSample], &[Trigger]) =
            match self.streams[index].kind {
                StreamKind::Events => (&self.events, &[], &[]),
                StreamKind::Imu => (&[], &self.imu, &[]),
                _ => (&[], &[], &self.triggers),
            };
        AedatChunk {
            stream_id,
            offset,
            events,
            imu,
            triggers,
        }
    }

    /// Reads and decodes packets until one of a decoded kind; returns its stream id, offset and
    /// index into `self.streams`.
    fn next_packet(&mut self) -> Result<Option<(i32, u64, usize)>> {
        loop {
            let offset = self.offset;
            if self.table_end == Some(offset) {
                if self.check_table {
                    self.check_data_table(offset)?;
                }
                return Ok(None);
            }
            match self.read_packet(None)? {
                Packet::Decoded(stream_id, offset, index) => {
                    return Ok(Some((stream_id, offset, index)));
                }
                Packet::Skipped => {}
                Packet::End => {
                    return match self.table_end {
                        Some(table) if self.mode == Mode::File => {
                            Err(AedatError::MissingDataTable {
                                offset,
                                data_table: table,
                            })
                        }
                        _ => Ok(None),
                    };
                }
            }
        }
    }

    /// Reads and decodes the next packet the data table selected, checking it against its
    /// table entry.
    fn next_planned(&mut self) -> Result<Option<(i32, u64, usize)>> {
        let Some((plan, seek)) = self.range.as_mut().and_then(|r| r.plan.as_mut()) else {
            return Ok(None);
        };
        let Some(p) = plan.packets.pop_front() else {
            return Ok(None);
        };
        if self.offset != p.offset {
            seek(&mut self.reader, p.offset).map_err(|source| AedatError::Io {
                offset: p.offset,
                source,
            })?;
            self.offset = p.offset;
        }
        match self.read_packet(Some(&p))? {
            Packet::Decoded(stream_id, offset, index) => {
                self.check_planned(&p, index)?;
                Ok(Some((stream_id, offset, index)))
            }
            // The plan holds decoded streams only, and `read_packet` reports a cut.
            Packet::Skipped | Packet::End => Err(AedatError::TruncatedPacket {
                offset: p.offset,
                stream_id: p.stream_id,
                expected: p.size + 8,
                got: 0,
            }),
        }
    }

    /// Checks what the data table said about a packet against what it decoded to.
    fn check_planned(&self, p: &PlannedPacket, index: usize) -> Result<()> {
        let ts = |first: Option<i64>, last: Option<i64>, n: usize| (n, first, last);
        let (n, first, last) = match self.streams[index].kind {
            StreamKind::Events => ts(
                self.events.first().map(|e| e.t),
                self.events.last().map(|e| e.t),
                self.events.len(),
            ),
            StreamKind::Imu => ts(
                self.imu.first().map(|s| s.t),
                self.imu.last().map(|s| s.t),
                self.imu.len(),
            ),
            _ => ts(
                self.triggers.first().map(|t| t.t),
                self.triggers.last().map(|t| t.t),
                self.triggers.len(),
            ),
        };
        let mismatch = |field: &'static str, table: i64, found: i64| {
            Err(AedatError::DataTableMismatch {
                offset: p.offset,
                field,
                table,
                found,
            })
        };
        if n as u64 != p.elements {
            return mismatch("NumElements", p.elements as i64, n as i64);
        }
        if let Some(first) = first
            && first != p.t_start
        {
            return mismatch("TimestampStart", p.t_start, first);
        }
        if let Some(last) = last
            && last != p.t_end
        {
            return mismatch("TimestampEnd", p.t_end, last);
        }
        Ok(())
    }

    /// Reads the packet at the current offset and decodes it when its stream is decoded. With
    /// `planned`, its header must match the data table's entry.
    fn read_packet(&mut self, planned: Option<&PlannedPacket>) -> Result<Packet> {
        let offset = self.offset;
        let mut head = [0u8; 8];
        let n = read_up_to(&mut self.reader, &mut head)
            .map_err(|source| AedatError::Io { offset, source })?;
        if n == 0 && planned.is_none() {
            return Ok(Packet::End);
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
        if let Some(p) = planned {
            if stream_id != p.stream_id {
                return Err(AedatError::DataTableMismatch {
                    offset,
                    field: "StreamID",
                    table: p.stream_id.into(),
                    found: stream_id.into(),
                });
            }
            if i64::from(size) != p.size as i64 {
                return Err(AedatError::DataTableMismatch {
                    offset,
                    field: "Size",
                    table: p.size as i64,
                    found: size.into(),
                });
            }
        }
        let size = u64::try_from(size).map_err(|_| AedatError::BadSize {
            field: "packet size",
            offset,
            value: size.into(),
            limit: MAX_PACKET_BYTES,
        })?;
        if let Some(table) = self.table_end
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
        // A range read's plan lists the packets it needs: those are all decoded.
        let decoded = match self.only.as_ref().filter(|_| planned.is_none()) {
            Some(only) => state.decoded && state.kind == *only,
            None => state.decoded,
        };
        if !decoded {
            return Ok(Packet::Skipped);
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
            StreamKind::Events => packet::decode_events(payload, state, offset, &mut self.events)?,
            StreamKind::Imu => packet::decode_imu(payload, state, offset, &mut self.imu)?,
            _ => packet::decode_triggers(payload, state, offset, &mut self.triggers)?,
        }
        Ok(Packet::Decoded(stream_id, offset, index))
    }

    /// Reads the data table at `offset` (the rest of the file) and verifies it, so that a file
    /// cut at or inside its data table is reported rather than taken as complete: streamed when
    /// the input can seek, whole when it cannot or the streamed check is unsure (a damaged
    /// table then gets the whole verifier's error).
    fn check_data_table(&mut self, offset: u64) -> Result<()> {
        if let Some(seek) = self.rewind {
            let compression = self.header.compression;
            let per_pass = ENTRIES_PER_PASS;
            match table_check::check(&mut self.reader, seek, offset, compression, per_pass) {
                Verdict::Valid(length) => {
                    self.offset = offset + length;
                    return Ok(());
                }
                Verdict::Unsure => seek(&mut self.reader, offset)
                    .map_err(|source| AedatError::Io { offset, source })?,
            }
        }
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

impl<R: Read + Seek> AedatReader<R> {
    /// Restricts the reader to the time range `[from, to)` (microseconds): from now on
    /// [`Self::next_chunk`] hands out exactly the events, IMU samples and triggers with
    /// `from <= t < to`, in file order, as if the whole file had been read and then filtered.
    ///
    /// With a data table, only the packets it lists as overlapping the range are read: reading a
    /// few seconds of a multi-gigabyte recording touches a few megabytes, and memory holds the
    /// table's entries for the range only. The table (about 60 bytes a packet decompressed) is
    /// decompressed block by block in passes over it, as the end-of-read check reads it
    /// (`table_check::plan`), never whole; a table that check cannot vouch for is read whole
    /// as before, so that a damaged one gets the same reason. Without one, or when the table is
    /// unusable, the reader scans the file
    /// from its first packet; the returned [`RangeIndex`] says which happened and why, so that
    /// the caller can warn once. The read starts over from the first packet whatever was read
    /// before.
    ///
    /// ```
    /// use std::io::Cursor;
    /// use evtac_formats::aedat::{AedatReader, AedatWriter, WriterConfig};
    /// use evtac_events::{Event, Resolution};
    /// use evtac_formats::RangeIndex;
    ///
    /// let config = WriterConfig::new(Resolution::new(64, 48), "cam");
    /// let mut writer = AedatWriter::new_seekable(Cursor::new(Vec::new()), config)?;
    /// let events: Vec<Event> = (0..100_000).map(|t| Event { t, x: 1, y: 2, polarity: true }).collect();
    /// writer.write_events(&events)?;
    /// let file = writer.finish()?.into_inner();
    ///
    /// let mut reader = AedatReader::new(Cursor::new(&file))?;
    /// let how = reader.select_range(50_000, 50_010)?;
    /// assert!(matches!(how, RangeIndex::DataTable { packets: 1, .. }));
    /// let chunk = reader.next_chunk()?.unwrap();
    /// assert_eq!(chunk.events, &events[50_000..50_010]);
    /// assert!(reader.next_chunk()?.is_none());
    /// # Ok::<(), evtac_formats::aedat::AedatError>(())
    /// ```
    pub fn select_range(&mut self, from: i64, to: i64) -> Result<RangeIndex> {
        if from >= to {
            return Err(AedatError::EmptyRange { from, to });
        }
        self.range = None;
        self.finished = false;
        self.table_end = self.header.data_table_position;
        self.check_table = true;
        self.rewind = Some(seek_to::<R>);
        for s in &mut self.streams {
            s.count = 0;
            s.last_t = i64::MIN;
        }
        let index = match self.header.data_table_position {
            None => RangeIndex::Scan(ScanReason::NoDataTable),
            Some(position) => match self.load_plan(position, from, to)? {
                Ok(plan) => {
                    for (s, &first) in self.streams.iter_mut().zip(&plan.first_index) {
                        s.count = first;
                    }
                    let index = RangeIndex::DataTable {
                        packets: plan.packets.len(),
                        total: plan.total,
                    };
                    self.range = Some(RangeRead {
                        from,
                        to,
                        plan: Some((plan, seek_to::<R>)),
                    });
                    return Ok(index);
                }
                Err(reason) => {
                    // Said once, here; the scan then stops at the table without verifying it.
                    self.check_table = false;
                    RangeIndex::Scan(ScanReason::DamagedDataTable { position, reason })
                }
            },
        };
        seek_to(&mut self.reader, self.data_start).map_err(|source| AedatError::Io {
            offset: self.data_start,
            source,
        })?;
        self.offset = self.data_start;
        self.range = Some(RangeRead {
            from,
            to,
            plan: None,
        });
        Ok(index)
    }

    /// Reads and checks the data table at `position` and selects the packets overlapping
    /// `[from, to)`. The outer error is an I/O failure; the inner one says why the table cannot
    /// be used.
    fn load_plan(
        &mut self,
        position: u64,
        from: i64,
        to: i64,
    ) -> Result<std::result::Result<Plan, String>> {
        let io = |offset| move |source| AedatError::Io { offset, source };
        let len = self.reader.seek(SeekFrom::End(0)).map_err(io(position))?;
        if position >= len || position < self.data_start {
            // The position itself is wrong: the scan runs to the end of the input.
            self.table_end = None;
            return Ok(Err(format!(
                "it lies outside the file's packets (bytes {} .. {len})",
                self.data_start
            )));
        }
        // Streamed, holding the entries in the range only, when the table is one the streamed
        // check vouches for; whole otherwise, so that a damaged table gets the error it got.
        if self.stream_table {
            let planner = Planner::new(self.data_start, position, &self.streams, from, to);
            let (compression, per_pass) = (self.header.compression, ENTRIES_PER_PASS);
            let seek = seek_to::<R>;
            if let Some(plan) = table_check::plan(
                &mut self.reader,
                seek,
                position,
                compression,
                per_pass,
                planner,
            ) {
                // Where the reader is after the passes is not known: the next read seeks.
                self.offset = len;
                return Ok(plan);
            }
        }
        seek_to(&mut self.reader, position).map_err(io(position))?;
        let input = self.decompressor.input();
        (&mut self.reader)
            .take(MAX_PACKET_BYTES)
            .read_to_end(input)
            .map_err(io(position))?;
        self.offset = position + input.len() as u64;
        let payload = match self.decompressor.decompress() {
            Ok(payload) => payload,
            Err(reason) => return Ok(Err(format!("it does not decompress: {reason}"))),
        };
        let plan = index::plan(payload, self.data_start, position, &self.streams, from, to);
        self.decompressor.shrink_to(1 << 20);
        Ok(plan)
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

/// Whether evtac decodes packets of `kind` (events, IMU, triggers; frames and unknown types are
/// read past).
fn decodable(kind: &StreamKind) -> bool {
    matches!(
        kind,
        StreamKind::Events | StreamKind::Imu | StreamKind::Triggers
    )
}

#[cfg(test)]
mod tests {
    use super::super::{AedatWriter, WriterConfig};
    use super::*;
    use std::io::Cursor;

    /// A file of events, IMU and triggers in many packets, with its data table.
    fn file(compression: Compression) -> Vec<u8> {
        let config = WriterConfig {
            compression,
            ..WriterConfig::new(Resolution::new(64, 48), "cam")
        };
        let mut w = AedatWriter::new_seekable(Cursor::new(Vec::new()), config).unwrap();
        for k in 0..40i64 {
            let events: Vec<Event> = (0..700)
                .map(|i| Event {
                    t: k * 10_000 + i * 13,
                    x: (i % 64) as u16,
                    y: (k % 48) as u16,
                    polarity: i % 3 == 0,
                })
                .collect();
            w.write_events(&events).unwrap();
            let imu: Vec<ImuSample> = (0..8)
                .map(|i| ImuSample {
                    t: k * 10_000 + i * 1250,
                    ..ImuSample::default()
                })
                .collect();
            w.write_imu(&imu).unwrap();
            if k % 5 == 0 {
                w.write_triggers(&[Trigger {
                    t: k * 10_000 + 7,
                    ..Trigger::default()
                }])
                .unwrap();
            }
        }
        w.finish().unwrap().into_inner()
    }

    /// A range read of `bytes`, planned streamed or from the whole table: how, and what it read.
    fn range(bytes: &[u8], (from, to): (i64, i64), streamed: bool) -> String {
        let mut reader = match AedatReader::new(Cursor::new(bytes)) {
            Ok(reader) => reader,
            Err(e) => return format!("open: {e}"),
        };
        reader.stream_table = streamed;
        let how = match reader.select_range(from, to) {
            Ok(how) => how,
            Err(e) => return format!("select: {e}"),
        };
        let mut read = Vec::new();
        loop {
            match reader.next_chunk() {
                Ok(Some(c)) => read.push(format!("{c:?}")),
                Ok(None) => break,
                Err(e) => {
                    read.push(format!("error: {e}"));
                    break;
                }
            }
        }
        format!("{how:?}\n{}", read.join("\n"))
    }

    /// A range read planned from the streamed table reads what one planned from the whole
    /// table reads, for many ranges, and says the same of a table damaged at any byte (the
    /// same `RangeIndex`, the same reason, the same elements and errors).
    #[test]
    fn streamed_plans_read_what_whole_plans_read() {
        let ranges = [
            (-10, 0),
            (0, 1),
            (9_999, 10_001),
            (57_000, 123_456),
            (199_993, 200_000),
            (390_000, 500_000),
            (i64::MIN, i64::MAX),
        ];
        for c in [Compression::None, Compression::Lz4, Compression::Zstd] {
            let good = file(c);
            for &r in &ranges {
                let whole = range(&good, r, false);
                assert!(whole.starts_with("DataTable"), "{c} {r:?}: {whole}");
                assert_eq!(range(&good, r, true), whole, "{c} {r:?}");
            }
            let reader = AedatReader::new(Cursor::new(&good)).unwrap();
            let position = reader.header().data_table_position.unwrap() as usize;
            for at in position..good.len() {
                let flip = if at % 2 == 0 { 0x01u8 } else { 0xff };
                let mut bad = good.clone();
                bad[at] ^= flip;
                let r = ranges[at % ranges.len()];
                let whole = range(&bad, r, false);
                assert_eq!(range(&bad, r, true), whole, "{c}: byte {at} ^ {flip:#x}");
            }
        }
    }
}
