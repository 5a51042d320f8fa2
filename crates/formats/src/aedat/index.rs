//! The data table (`FileDataTable`) as an index: which packets a range read needs.
//!
//! DV ends a finished file with a table of every packet: where its body starts (`ByteOffset`,
//! just past the 8-byte packet header), its stream and size, how many elements it holds and the
//! timestamps of its first and last element. A range read trusts the table only after checking
//! what can be checked without reading the packets: the entries must tile the packet area
//! exactly (each packet starts where the one before ends, the last ends at the table), name
//! declared streams, and keep each stream's time from going backwards. A flipped byte in an
//! offset, a size or (almost always) a timestamp breaks one of these, and the reader falls back
//! to a scan instead of silently skipping data. What the table says about the packets it selects
//! is checked again when they are decoded ([`AedatError::DataTableMismatch`]).
//!
//! What no check can see without reading every packet, a table damaged yet consistent (an
//! entry's element count set to zero, an end time lowered within its neighbours' bounds), can
//! make a range read miss that packet; what the read returns is still always the file's own
//! elements in the range, in file order (the `damaged_files_never_panic_a_range_read` proptest).
//!
//! [`AedatError::DataTableMismatch`]: super::AedatError::DataTableMismatch

use std::collections::VecDeque;

use super::compression::MAX_PACKET_BYTES;
use super::packet::StreamState;
use super::schema::{self, DataTableEntry};

/// Most elements a packet can hold: every element takes at least 8 bytes of its decompressed
/// flatbuffer (a timestamp), which is at most [`MAX_PACKET_BYTES`] long.
const MAX_ELEMENTS: u64 = MAX_PACKET_BYTES / 8;

/// A packet the data table says overlaps the range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct PlannedPacket {
    /// Byte offset of the packet's 8-byte header.
    pub offset: u64,
    /// Its stream.
    pub stream_id: i32,
    /// Its (compressed) body size.
    pub size: u64,
    /// Elements it holds.
    pub elements: u64,
    /// Timestamp of its first element.
    pub t_start: i64,
    /// Timestamp of its last element.
    pub t_end: i64,
}

/// The packets to read, in file order, and what is needed to report errors as a full read would.
#[derive(Debug, Default, PartialEq, Eq)]
pub(crate) struct Plan {
    /// Packets overlapping the range.
    pub packets: VecDeque<PlannedPacket>,
    /// Packets in the file.
    pub total: usize,
    /// Per stream (in the order of the reader's streams): elements in the packets before its
    /// first selected one, so element indices in errors count from the start of the file.
    pub first_index: Vec<u64>,
}

/// Checks the decompressed data table `payload` of a file whose packets fill
/// `data_start..position`, and selects the packets of decoded streams (events, IMU, triggers)
/// with elements overlapping `[from, to)`. The error says what is wrong with the table.
pub(crate) fn plan(
    payload: &[u8],
    data_start: u64,
    position: u64,
    streams: &[StreamState],
    from: i64,
    to: i64,
) -> Result<Plan, String> {
    let Some(prefix) = payload.first_chunk::<4>() else {
        return Err(format!(
            "{} bytes, too short for a flatbuffer",
            payload.len()
        ));
    };
    let declared = u32::from_le_bytes(*prefix) as usize;
    let body = payload
        .get(..declared.saturating_add(4))
        .ok_or_else(|| format!("its size prefix says {declared} bytes, but fewer follow"))?;
    if !super::has_identifier(body, schema::FILE_DATA_TABLE_IDENTIFIER) {
        return Err("missing file identifier \"FTAB\"".into());
    }
    let table = schema::size_prefixed_root_as_file_data_table(body).map_err(|e| e.to_string())?;
    let mut planner = Planner::new(data_start, position, streams, from, to);
    for def in table.table().into_iter().flatten() {
        planner.entry(&def.entry())?;
    }
    planner.finish()
}

/// Plans a range read entry by entry, in the table's order: what [`plan`] does with each entry
/// of a verified table, for a table read whole or streamed (`table_check::plan`), so that both
/// give the same plan and the same error.
pub(crate) struct Planner<'a> {
    position: u64,
    streams: &'a [StreamState],
    from: i64,
    to: i64,
    out: Plan,
    /// Per stream: elements seen so far, last timestamp, and whether a packet was selected.
    seen: Vec<u64>,
    last_t: Vec<i64>,
    started: Vec<bool>,
    /// Where the next packet starts, and the next entry's index.
    cursor: u64,
    index: usize,
}

impl<'a> Planner<'a> {
    pub(crate) fn new(
        data_start: u64,
        position: u64,
        streams: &'a [StreamState],
        from: i64,
        to: i64,
    ) -> Self {
        Self {
            position,
            streams,
            from,
            to,
            out: Plan {
                first_index: vec![0; streams.len()],
                ..Plan::default()
            },
            seen: vec![0; streams.len()],
            last_t: vec![i64::MIN; streams.len()],
            started: vec![false; streams.len()],
            cursor: data_start,
            index: 0,
        }
    }

    /// The next entry; the error says what is wrong with it.
    pub(crate) fn entry(&mut self, e: &DataTableEntry) -> Result<(), String> {
        let i = self.index;
        self.index += 1;
        let header = self.cursor;
        if e.byte_offset != header as i64 + 8 {
            return Err(format!(
                "entry {i} puts a packet body at byte {}, but the packet before ends at byte \
                 {header} (a body starts 8 bytes after it)",
                e.byte_offset
            ));
        }
        let size = u64::try_from(e.size).map_err(|_| format!("entry {i} has size {}", e.size))?;
        self.cursor = header + 8 + size;
        if self.cursor > self.position {
            return Err(format!(
                "entry {i} (a packet of {size} bytes at byte {header}) runs past the table"
            ));
        }
        let s = self
            .streams
            .iter()
            .position(|s| s.id == e.stream_id)
            .ok_or_else(|| format!("entry {i} names undeclared stream {}", e.stream_id))?;
        let elements = u64::try_from(e.num_elements)
            .ok()
            .filter(|&n| n <= MAX_ELEMENTS)
            .ok_or_else(|| {
                format!(
                    "entry {i} counts {} elements (a packet holds at most {MAX_ELEMENTS})",
                    e.num_elements
                )
            })?;
        self.out.total += 1;
        if elements == 0 {
            return Ok(());
        }
        if e.timestamp_start > e.timestamp_end || e.timestamp_start < self.last_t[s] {
            return Err(format!(
                "entry {i} (stream {}) spans {} .. {} us after a packet ending at {} us",
                e.stream_id, e.timestamp_start, e.timestamp_end, self.last_t[s]
            ));
        }
        self.last_t[s] = e.timestamp_end;
        if self.streams[s].decoded && e.timestamp_end >= self.from && e.timestamp_start < self.to {
            if !self.started[s] {
                self.started[s] = true;
                self.out.first_index[s] = self.seen[s];
            }
            self.out.packets.push_back(PlannedPacket {
                offset: header,
                stream_id: e.stream_id,
                size,
                elements,
                t_start: e.timestamp_start,
                t_end: e.timestamp_end,
            });
        }
        self.seen[s] = self.seen[s].saturating_add(elements);
        Ok(())
    }

    /// The plan, once every entry is in.
    pub(crate) fn finish(self) -> Result<Plan, String> {
        if self.cursor != self.position {
            return Err(format!(
                "its entries end at byte {}, but the table starts at byte {}",
                self.cursor, self.position
            ));
        }
        Ok(self.out)
    }
}
