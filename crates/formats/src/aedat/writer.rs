//! The AEDAT 4.0 writer: events (stream 0, `EVTS`), IMU samples (stream 1, `IMUS`) and triggers
//! (stream 2, `TRIG`), laid out as dv-processing's `MonoCameraWriter` does with
//! `addEventStream`, `addImuStream` and `addTriggerStream`, so DV tools open the result and list
//! the streams with the camera name and resolution. The trigger stream is always declared, even
//! when empty, as in DV's own recordings of a DVXplorer: a file's layout does not depend on
//! whether the robot sent sync pulses.
//!
//! Packets are cut by content, not by how the caller slices its calls (at most
//! [`EVENTS_PER_PACKET`] events or [`PACKET_SPAN_US`] of time per packet, likewise for IMU and
//! triggers), so the same data gives the same bytes.

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::Path;

use flatbuffers::FlatBufferBuilder;

use super::compression::Compressor;
use super::error::{AedatError, Result};
use super::header::{Compression, DeclaredStream, MAGIC, write_description};
use super::schema::{self, DataTableEntry, FbEvent, ImuFields};
use crate::{Event, ImuSample, Resolution, Trigger};

/// Most events per packet (DV cameras send packets of a few thousand events).
pub const EVENTS_PER_PACKET: usize = 4096;
/// Most IMU samples per packet.
pub const IMU_PER_PACKET: usize = 64;
/// Most triggers per packet.
pub const TRIGGERS_PER_PACKET: usize = 64;
/// Longest time a packet spans, in microseconds.
pub const PACKET_SPAN_US: i64 = 10_000;

/// Stream ids, as `MonoCameraWriter` numbers an events + IMU + triggers configuration (what DV
/// records from a DVXplorer).
const EVENT_STREAM: i32 = 0;
const IMU_STREAM: i32 = 1;
const TRIGGER_STREAM: i32 = 2;

/// How to write a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WriterConfig {
    /// Sensor size: every event must lie inside it.
    pub resolution: Resolution,
    /// Camera name, stored as every stream's `source` (e.g. `DVXplorer_DXA00000`).
    pub source_name: String,
    /// Packet compression.
    pub compression: Compression,
}

impl WriterConfig {
    /// A configuration with LZ4 compression (DV's default).
    pub fn new(resolution: Resolution, source_name: impl Into<String>) -> Self {
        Self {
            resolution,
            source_name: source_name.into(),
            compression: Compression::Lz4,
        }
    }
}

/// Rewrites the header in place once the data table's position is known.
type PatchHeader<W> = fn(&mut W, &[u8]) -> io::Result<()>;

fn patch_header<W: Write + Seek>(w: &mut W, header: &[u8]) -> io::Result<()> {
    let end = w.stream_position()?;
    w.seek(SeekFrom::Start(MAGIC.len() as u64))?;
    w.write_all(header)?;
    w.seek(SeekFrom::Start(end))?;
    Ok(())
}

/// Writes AEDAT 4.0 to any [`Write`]. Call [`AedatWriter::finish`] at the end: it writes the
/// buffered packets (dropping the writer without it loses them).
///
/// Writers made by [`AedatWriter::create`] or [`AedatWriter::new_seekable`] also end the file
/// with DV's data table (an index of the packets) and record its position in the header, as DV
/// does: a file cut short is then detected as truncated. [`AedatWriter::new`] cannot go back
/// to the header, so it writes no data table (position -1, what DV leaves in a recording that
/// was interrupted; DV's readers index such files by scanning them).
///
/// ```
/// use evtac_formats::aedat::{AedatReader, AedatWriter, Compression, WriterConfig};
/// use evtac_events::{Event, Resolution};
///
/// let mut config = WriterConfig::new(Resolution::new(320, 240), "DVXplorer_TEST");
/// config.compression = Compression::Zstd;
/// let mut writer = AedatWriter::new(Vec::new(), config)?;
/// writer.write_events(&[Event { t: 5, x: 1, y: 2, polarity: true }])?;
/// let bytes = writer.finish()?;
///
/// let mut reader = AedatReader::from_slice(&bytes)?;
/// assert_eq!(reader.resolution(), Some(Resolution::new(320, 240)));
/// let chunk = reader.next_chunk()?.unwrap();
/// assert_eq!(chunk.events, &[Event { t: 5, x: 1, y: 2, polarity: true }]);
/// # Ok::<(), evtac_formats::aedat::AedatError>(())
/// ```
pub struct AedatWriter<W: Write> {
    writer: W,
    config: WriterConfig,
    compressor: Compressor,
    fbb: FlatBufferBuilder<'static>,
    offset: u64,
    events: Vec<FbEvent>,
    imu: Vec<(i64, ImuFields)>,
    triggers: Vec<(i64, i8)>,
    /// Last timestamps written (or buffered), to reject time going backwards.
    last_event_t: i64,
    last_imu_t: i64,
    last_trigger_t: i64,
    /// Timestamp of the first buffered event.
    packet_start_t: i64,
    /// How to rewrite the header at the end (seekable outputs only).
    patch: Option<PatchHeader<W>>,
    /// One entry per packet written, for the data table.
    table: Vec<DataTableEntry>,
    /// The XML description (kept to rebuild the header at the end).
    description: String,
    /// Length of the header as first written.
    header_len: usize,
    /// Elements accepted so far, for error messages.
    event_count: u64,
    imu_count: u64,
    trigger_count: u64,
}

impl AedatWriter<BufWriter<File>> {
    /// Creates (or truncates) the file at `path` and writes the header.
    pub fn create(path: impl AsRef<Path>, config: WriterConfig) -> Result<Self> {
        let file = File::create(path).map_err(|source| AedatError::Io { offset: 0, source })?;
        Self::new_seekable(BufWriter::with_capacity(1 << 16, file), config)
    }
}

impl<W: Write + Seek> AedatWriter<W> {
    /// Writes the magic and header to `writer`, which must be positioned at its start; the file
    /// will end with a data table.
    pub fn new_seekable(writer: W, config: WriterConfig) -> Result<Self> {
        Self::start(writer, config, Some(patch_header::<W>))
    }
}

impl<W: Write> AedatWriter<W> {
    /// Writes the magic and header to `writer` (no data table: see the type's docs).
    pub fn new(writer: W, config: WriterConfig) -> Result<Self> {
        Self::start(writer, config, None)
    }

    fn start(writer: W, config: WriterConfig, patch: Option<PatchHeader<W>>) -> Result<Self> {
        let res = config.resolution;
        if res.width == 0 || res.height == 0 || res.width > 32768 || res.height > 32768 {
            return Err(AedatError::InvalidInput {
                what: format!("resolution {res}"),
                reason: "AEDAT stores coordinates as int16: width and height must be 1..=32768"
                    .into(),
            });
        }
        let compressor = Compressor::new(config.compression)
            .map_err(|source| AedatError::Io { offset: 0, source })?;
        let mut me = Self {
            writer,
            compressor,
            fbb: FlatBufferBuilder::with_capacity(EVENTS_PER_PACKET * 16 + 256),
            offset: 0,
            events: Vec::with_capacity(EVENTS_PER_PACKET),
            imu: Vec::with_capacity(IMU_PER_PACKET),
            triggers: Vec::with_capacity(TRIGGERS_PER_PACKET),
            last_event_t: i64::MIN,
            last_imu_t: i64::MIN,
            last_trigger_t: i64::MIN,
            packet_start_t: 0,
            patch,
            table: Vec::new(),
            description: String::new(),
            header_len: 0,
            event_count: 0,
            imu_count: 0,
            trigger_count: 0,
            config,
        };
        let description = write_description(
            &[
                DeclaredStream {
                    id: EVENT_STREAM,
                    output_name: "events",
                    type_identifier: "EVTS",
                    type_description: "Array of events (polarity ON/OFF).",
                    resolution: Some(me.config.resolution),
                },
                DeclaredStream {
                    id: IMU_STREAM,
                    output_name: "imu",
                    type_identifier: "IMUS",
                    type_description: "Inertial Measurement Unit data samples.",
                    resolution: None,
                },
                DeclaredStream {
                    id: TRIGGER_STREAM,
                    output_name: "triggers",
                    type_identifier: "TRIG",
                    type_description: "External triggers and special signals.",
                    resolution: None,
                },
            ],
            &me.config.source_name,
            me.config.compression,
        );
        // A seekable output gets a placeholder position (present, so the final header has the
        // same length and can be rewritten in place); otherwise -1: no data table.
        let position = if me.patch.is_some() { i64::MAX } else { -1 };
        me.description = description;
        schema::build_io_header(
            &mut me.fbb,
            me.config.compression.to_raw(),
            position,
            &me.description,
        );
        me.put(MAGIC)?;
        let header = me.fbb.finished_data().to_vec();
        me.header_len = header.len();
        me.put(&header)?;
        Ok(me)
    }

    /// The configuration in use.
    pub fn config(&self) -> &WriterConfig {
        &self.config
    }

    /// Bytes written so far (buffered packets not included).
    pub fn bytes_written(&self) -> u64 {
        self.offset
    }

    fn put(&mut self, bytes: &[u8]) -> Result<()> {
        let offset = self.offset;
        self.writer
            .write_all(bytes)
            .map_err(|source| AedatError::Io { offset, source })?;
        self.offset += bytes.len() as u64;
        Ok(())
    }

    /// Appends events. They must lie inside the resolution and their timestamps must not
    /// decrease (across calls too).
    pub fn write_events(&mut self, events: &[Event]) -> Result<()> {
        let res = self.config.resolution;
        for e in events {
            let index = self.event_count;
            let what = || format!("event {index}");
            if !res.contains(e.x, e.y) {
                return Err(AedatError::InvalidInput {
                    what: what(),
                    reason: format!("x={}, y={} is outside {res}", e.x, e.y),
                });
            }
            if e.t < self.last_event_t {
                return Err(AedatError::InvalidInput {
                    what: what(),
                    reason: format!("timestamp {} after {}", e.t, self.last_event_t),
                });
            }
            if self.events.len() >= EVENTS_PER_PACKET
                || (!self.events.is_empty()
                    && e.t.saturating_sub(self.packet_start_t) >= PACKET_SPAN_US)
            {
                self.flush_events()?;
            }
            if self.events.is_empty() {
                self.packet_start_t = e.t;
            }
            // `start` checked that the resolution fits AEDAT's int16 coordinates.
            let (Ok(x), Ok(y)) = (i16::try_from(e.x), i16::try_from(e.y)) else {
                return Err(AedatError::InvalidInput {
                    what: what(),
                    reason: format!("x={}, y={} does not fit AEDAT's int16", e.x, e.y),
                });
            };
            self.last_event_t = e.t;
            self.event_count += 1;
            self.events.push(FbEvent::new(e.t, x, y, e.polarity));
        }
        Ok(())
    }

    /// Appends IMU samples (timestamps must not decrease). The magnetometer is stored as zeros.
    pub fn write_imu(&mut self, samples: &[ImuSample]) -> Result<()> {
        for s in samples {
            if s.t < self.last_imu_t {
                return Err(AedatError::InvalidInput {
                    what: format!("IMU sample {}", self.imu_count),
                    reason: format!("timestamp {} after {}", s.t, self.last_imu_t),
                });
            }
            if self.imu.len() >= IMU_PER_PACKET
                || self
                    .imu
                    .first()
                    .is_some_and(|f| s.t.saturating_sub(f.0) >= PACKET_SPAN_US)
            {
                self.flush_imu()?;
            }
            self.last_imu_t = s.t;
            self.imu_count += 1;
            let [ax, ay, az] = s.accelerometer;
            let [gx, gy, gz] = s.gyroscope;
            self.imu
                .push((s.t, [s.temperature, ax, ay, az, gx, gy, gz, 0.0, 0.0, 0.0]));
        }
        Ok(())
    }

    /// Appends triggers (timestamps must not decrease). `kind` is stored as the `TriggerType`
    /// code unchanged (dv-processing's `TriggerType` enum: 0 `TIMESTAMP_RESET` .. 9
    /// `APS_EXPOSURE_END`).
    pub fn write_triggers(&mut self, triggers: &[Trigger]) -> Result<()> {
        for tr in triggers {
            if tr.t < self.last_trigger_t {
                return Err(AedatError::InvalidInput {
                    what: format!("trigger {}", self.trigger_count),
                    reason: format!("timestamp {} after {}", tr.t, self.last_trigger_t),
                });
            }
            if self.triggers.len() >= TRIGGERS_PER_PACKET
                || self
                    .triggers
                    .first()
                    .is_some_and(|f| tr.t.saturating_sub(f.0) >= PACKET_SPAN_US)
            {
                self.flush_triggers()?;
            }
            self.last_trigger_t = tr.t;
            self.trigger_count += 1;
            self.triggers.push((tr.t, tr.kind));
        }
        Ok(())
    }

    fn flush_events(&mut self) -> Result<()> {
        if self.events.is_empty() {
            return Ok(());
        }
        let time = |e: Option<&FbEvent>| {
            e.and_then(|e| e.0.first_chunk::<8>())
                .map_or(0, |t| i64::from_le_bytes(*t))
        };
        let span = (time(self.events.first()), time(self.events.last()));
        self.fbb.reset();
        schema::build_event_packet(&mut self.fbb, &self.events);
        let n = self.events.len();
        self.events.clear();
        self.write_packet(EVENT_STREAM, n, span)
    }

    fn flush_imu(&mut self) -> Result<()> {
        if self.imu.is_empty() {
            return Ok(());
        }
        let span = (
            self.imu.first().map_or(0, |s| s.0),
            self.imu.last().map_or(0, |s| s.0),
        );
        self.fbb.reset();
        schema::build_imu_packet(&mut self.fbb, &self.imu);
        let n = self.imu.len();
        self.imu.clear();
        self.write_packet(IMU_STREAM, n, span)
    }

    fn flush_triggers(&mut self) -> Result<()> {
        let (Some(first), Some(last)) = (self.triggers.first(), self.triggers.last()) else {
            return Ok(());
        };
        let span = (first.0, last.0);
        self.fbb.reset();
        schema::build_trigger_packet(&mut self.fbb, &self.triggers);
        let n = self.triggers.len();
        self.triggers.clear();
        self.write_packet(TRIGGER_STREAM, n, span)
    }

    /// Compresses the finished flatbuffer in `fbb` and writes it with its packet header.
    fn write_packet(&mut self, stream_id: i32, elements: usize, span: (i64, i64)) -> Result<()> {
        let offset = self.offset;
        let body = self
            .compressor
            .compress(self.fbb.finished_data())
            .map_err(|source| AedatError::Io { offset, source })?;
        let size = i32::try_from(body.len()).map_err(|_| AedatError::InvalidInput {
            what: format!("packet of stream {stream_id}"),
            reason: format!("{} bytes exceed AEDAT's int32 packet size", body.len()),
        })?;
        let mut head = [0u8; 8];
        head[..4].copy_from_slice(&stream_id.to_le_bytes());
        head[4..].copy_from_slice(&size.to_le_bytes());
        let io = |source| AedatError::Io { offset, source };
        self.writer.write_all(&head).map_err(io)?;
        self.writer.write_all(body).map_err(io)?;
        self.offset += 8 + body.len() as u64;
        self.table.push(DataTableEntry {
            byte_offset: offset as i64 + 8,
            stream_id,
            size,
            num_elements: elements as i64,
            timestamp_start: span.0,
            timestamp_end: span.1,
        });
        Ok(())
    }

    /// Writes the data table (compressed like the packets, without a packet header) and
    /// rewrites the header with its position.
    fn write_data_table(&mut self, patch: PatchHeader<W>) -> Result<()> {
        let position = self.offset;
        self.fbb.reset();
        schema::build_file_data_table(&mut self.fbb, &self.table);
        let body = self
            .compressor
            .compress(self.fbb.finished_data())
            .map_err(|source| AedatError::Io {
                offset: position,
                source,
            })?
            .to_vec();
        self.put(&body)?;
        let old_len = self.header_len;
        self.fbb.reset();
        schema::build_io_header(
            &mut self.fbb,
            self.config.compression.to_raw(),
            position as i64,
            &self.description,
        );
        let header = self.fbb.finished_data();
        if header.len() != old_len {
            return Err(AedatError::InvalidInput {
                what: "the final header".into(),
                reason: format!("{} bytes, placeholder had {old_len}", header.len()),
            });
        }
        patch(&mut self.writer, header).map_err(|source| AedatError::Io {
            offset: MAGIC.len() as u64,
            source,
        })
    }

    /// Writes the buffered packets (and the data table, for seekable outputs), flushes and
    /// returns the underlying writer.
    pub fn finish(mut self) -> Result<W> {
        self.flush_events()?;
        self.flush_imu()?;
        self.flush_triggers()?;
        if let Some(patch) = self.patch {
            self.write_data_table(patch)?;
        }
        let offset = self.offset;
        self.writer
            .flush()
            .map_err(|source| AedatError::Io { offset, source })?;
        Ok(self.writer)
    }
}
