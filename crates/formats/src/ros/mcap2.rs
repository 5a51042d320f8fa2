//! The MCAP container (rosbag2's default storage since ROS 2 Iron), read with Foxglove's `mcap`
//! crate: the format's reference Rust reader, kept in step with the specification. Its sans-io
//! linear reader is driven here with a record length limit (see `record_limit`), which bounds
//! every record before any buffer is sized by it: the crate's `RawMessageStream` (0.26) sets no
//! limit for the records of a chunk and reserved a damaged length (5 PB, found by fuzzing),
//! which aborted the process. The reader hands chunks over whole, and the `chunk` module
//! decompresses them (zstd, lz4) and walks their records itself: the crate's own walk trusted a
//! record's length inside an uncompressed chunk (an overflow panic, found by fuzzing), and it
//! reserves a string's declared length before checking it. A file cut short after its last whole
//! message (the end magic missing) is an error, as for any truncated file.
//!
//! The file is streamed through the reader (its buffer holds a record or a chunk at a time), not
//! read whole first: the messages are copied out of it anyway. It is read in order, not through
//! its summary: the summary is optional (a recording that crashed has none), and every message
//! is needed anyway. A channel's schema name is the message type (`dvs_msgs/msg/EventArray`)
//! and its message encoding says how to decode (`cdr` from rosbag2, `ros1` from a converted
//! ROS 1 bag).

use std::collections::HashMap;
use std::io::Read;

use mcap::records::Record;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use super::{Collector, Place, RosError};
use crate::npy::read_full;

mod chunk;

/// Scans the MCAP file in `source`, `len` bytes long, into `c`. An MCAP error says how far the
/// file had been read when it was found (`RosError::Mcap::read_to`): the crate's reader does
/// not say where a record starts, and an error must say where the file is broken.
pub(crate) fn scan(source: impl Read, len: u64, c: &mut Collector) -> Result<(), RosError> {
    let mut read_to = 0;
    scan_from(source, len, c, &mut read_to).map_err(|e| match e {
        RosError::Mcap { what, .. } => RosError::Mcap { read_to, what },
        other => other,
    })
}

/// [`scan`], keeping `read_to` at the bytes handed to the MCAP reader so far.
fn scan_from(
    mut source: impl Read,
    len: u64,
    c: &mut Collector,
    read_to: &mut u64,
) -> Result<(), RosError> {
    let failed = |e: std::io::Error| RosError::Mcap {
        read_to: 0, // set by `scan`
        what: format!("reading the file failed: {e}"),
    };
    let mut head = [0u8; 8];
    let got = read_full(&mut source, &mut head).map_err(failed)?;
    if !head[..got].starts_with(super::MCAP_MAGIC) {
        return Err(RosError::Container {
            offset: 0,
            what: "not an MCAP file: it does not start with the magic `\\x89MCAP0\\r\\n`".into(),
        });
    }
    let limit = record_limit(usize::try_from(len).unwrap_or(usize::MAX));
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_record_length_limit(limit)
            .with_emit_chunks(true),
    );
    // The magic, read above, goes to the reader first; then the rest of the file as it asks.
    let mut pending: &[u8] = &head;
    let mut left = len.saturating_sub(head.len() as u64);
    let mut scan = Scan {
        c,
        limit,
        schemas: HashMap::new(),
        channels: HashMap::new(),
        topics: HashMap::new(),
        past_data_end: false,
        ended: false,
        inflated: Vec::new(),
    };
    while let Some(event) = reader.next_event() {
        match event.map_err(broken)? {
            LinearReadEvent::ReadRequest(need) => {
                // Never more than the file still holds: the reader's buffer grows by what is
                // asked here, and a damaged length may ask for gigabytes.
                let available = (pending.len() as u64).saturating_add(left);
                let n = need.min(usize::try_from(available).unwrap_or(usize::MAX));
                let buf = reader.insert(n);
                let from_head = pending.len().min(n);
                buf[..from_head].copy_from_slice(&pending[..from_head]);
                pending = &pending[from_head..];
                let read = read_full(&mut source, &mut buf[from_head..]).map_err(failed)?;
                left = left.saturating_sub(read as u64);
                reader.notify_read(from_head + read);
                *read_to += (from_head + read) as u64;
            }
            LinearReadEvent::Record { opcode, data } => scan.record(opcode, data)?,
        }
    }
    if !scan.ended {
        return Err(RosError::Mcap {
            read_to: 0, // set by `scan`
            what: "the file ends before its footer and end magic (cut short?)".into(),
        });
    }
    Ok(())
}

fn broken(e: mcap::McapError) -> RosError {
    RosError::Mcap {
        read_to: 0, // set by `scan`
        what: e.to_string(),
    }
}

/// The scan's state: the schemas and channels defined so far, the topic of each channel with
/// messages, and where in the file the scan is.
struct Scan<'c> {
    c: &'c mut Collector,
    /// The longest record (and decompressed chunk) accepted.
    limit: usize,
    /// Schema id -> name.
    schemas: HashMap<u16, String>,
    /// Channel id -> channel, and -> topic index in the collector from its first message.
    channels: HashMap<u16, mcap::records::Channel>,
    topics: HashMap<u16, usize>,
    past_data_end: bool,
    ended: bool,
    /// A compressed chunk's records, decompressed (reused from chunk to chunk).
    inflated: Vec<u8>,
}

impl Scan<'_> {
    /// Handles one record of the file, or of a chunk.
    fn record(&mut self, opcode: u8, data: &[u8]) -> Result<(), RosError> {
        // The summary repeats schemas and channels: read on to the end magic only.
        if self.past_data_end {
            self.ended |= opcode == mcap::records::op::FOOTER;
            return Ok(());
        }
        // Only the records the scan uses are parsed: the others (indexes, attachments,
        // metadata) hold nothing evtac reads, and the crate allocates for their strings before
        // checking them (a 1.4 GB index string, found by fuzzing). Those parsed have their
        // strings checked first.
        use mcap::records::op;
        if !matches!(
            opcode,
            op::SCHEMA | op::CHANNEL | op::MESSAGE | op::CHUNK | op::DATA_END | op::FOOTER
        ) {
            return Ok(());
        }
        chunk::strings_fit(opcode, data)?;
        match mcap::parse_record(opcode, data).map_err(broken)? {
            Record::Schema { header, .. } => {
                self.schemas.insert(header.id, header.name);
            }
            Record::Channel(channel) => {
                self.channels.insert(channel.id, channel);
            }
            Record::Message { header, data } => {
                let topic = self.topic(header.channel_id, header.sequence)?;
                self.c
                    .message(topic, header.log_time, &data, Place::Unknown)?;
            }
            Record::Chunk { header, data } => {
                let mut inflated = std::mem::take(&mut self.inflated);
                let limit = self
                    .limit
                    .min(usize::try_from(self.c.limit()).unwrap_or(usize::MAX));
                let records = chunk::records(&header, &data, limit, &mut inflated);
                let walked = records.and_then(|records| {
                    chunk::each_record(records, |opcode, data| self.record(opcode, data))
                });
                self.inflated = inflated;
                walked?;
            }
            Record::DataEnd(_) => self.past_data_end = true,
            Record::Footer(_) => self.ended = true,
            _ => {}
        }
        Ok(())
    }

    /// The collector's topic of channel `id` (added at its first message, `sequence`).
    fn topic(&mut self, id: u16, sequence: u32) -> Result<usize, RosError> {
        if let Some(&topic) = self.topics.get(&id) {
            return Ok(topic);
        }
        let channel = self.channels.get(&id).ok_or_else(|| RosError::Mcap {
            read_to: 0, // set by `scan`
            what: format!(
                "message {sequence} refers to channel {id}, which the file has not defined"
            ),
        })?;
        let message_type = match channel.schema_id {
            0 => "(no schema)",
            sid => self
                .schemas
                .get(&sid)
                .map(String::as_str)
                .ok_or_else(|| RosError::Mcap {
                    read_to: 0, // set by `scan`
                    what: format!(
                        "channel {id} ({}) refers to schema {sid}, which the file has not defined",
                        channel.topic
                    ),
                })?,
        };
        let topic = self
            .c
            .topic(&channel.topic, message_type, &channel.message_encoding);
        self.topics.insert(id, topic);
        Ok(topic)
    }
}

/// The longest record accepted, in a chunk or not: sixteen times the file, at least 64 MiB, at
/// most 2 GiB (rosbag2 writes chunks of about a megabyte; a record is never longer than its
/// decompressed chunk, and a chunk this far beyond its file is a damaged size field).
fn record_limit(file_len: usize) -> usize {
    file_len.saturating_mul(16).clamp(64 << 20, 2 << 30)
}
