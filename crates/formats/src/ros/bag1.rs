//! The ROS 1 bag container (format 2.0): after the `#ROSBAG V2.0\n` line, records of
//! `u32 header_len, header, u32 data_len, data`, the header a list of `u32 len, name=value`
//! fields whose `op` byte gives the record's kind: `0x03` bag header, `0x05` chunk (its data are
//! more records, compressed `none`, `bz2` or `lz4`), `0x07` connection (topic, and in its data
//! the message type), `0x02` message data (connection, receive time), `0x04` index data and
//! `0x06` chunk info (the index, read past).
//!
//! The file is scanned from start to end, chunks decompressed one at a time, so a bag that was
//! never indexed (the recorder stopped before closing it: `index_pos` 0) reads as well as a
//! finished one, up to where it is broken. A closed bag's index, written last, is checked
//! against what its bag header declares ([`Index`]): a closed bag cut short is an error, never
//! read as a shorter bag. A message whose connection is only defined later (in the index section) is kept
//! until the connection is known.
//!
//! Why not the `rosbag` crate (0.6): it memory-maps the file (undefined behaviour if the file
//! changes under it), panics on some malformed input (a bag header whose index position lies
//! past the end of the file; index records with leftover bytes), reserves a chunk's declared
//! uncompressed size before decompressing, and decompresses lz4 through C bindings when the
//! workspace already has a safe lz4 decoder (`lz4_flex`). The container is small enough that
//! checking every length here costs less than working around those.

use std::collections::HashMap;
use std::io::Read;

use super::{Collector, Place, RosError};

/// A record: its header fields, data, and where it starts.
struct Record<'a> {
    offset: u64,
    header: &'a [u8],
    data: &'a [u8],
}

/// Reads records from a byte slice (the file, or a decompressed chunk).
struct Records<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// The file offset of `bytes[0]` (for a decompressed chunk: the chunk's offset, and
    /// `inside` set).
    base: u64,
    inside: bool,
}

impl<'a> Records<'a> {
    fn error(&self, offset: usize, what: String) -> RosError {
        if self.inside {
            RosError::Container {
                offset: self.base,
                what: format!("in this chunk, {what} (at byte {offset} of its decompressed data)"),
            }
        } else {
            RosError::Container {
                offset: self.base + offset as u64,
                what,
            }
        }
    }

    /// A `u32` length and the bytes it counts, at `self.pos`.
    fn sized(&mut self, what: &str, start: usize) -> Result<&'a [u8], RosError> {
        let at = self.pos;
        let left = self.bytes.len() - at;
        let len = self
            .bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")) as usize)
            .ok_or_else(|| {
                self.error(
                    start,
                    format!(
                        "the record's {what} length is cut off: the data ends {left} byte(s) in"
                    ),
                )
            })?;
        let body = self
            .bytes
            .get(at + 4..)
            .and_then(|rest| rest.get(..len))
            .ok_or_else(|| {
                self.error(
                    start,
                    format!(
                        "the record's {what} claims {len} bytes but only {} remain: the bag is \
                         truncated or corrupt",
                        left - 4
                    ),
                )
            })?;
        self.pos = at + 4 + len;
        Ok(body)
    }

    fn next(&mut self) -> Result<Option<Record<'a>>, RosError> {
        if self.pos >= self.bytes.len() {
            return Ok(None);
        }
        let start = self.pos;
        let header = self.sized("header", start)?;
        let data = self.sized("data", start)?;
        Ok(Some(Record {
            offset: if self.inside {
                self.base
            } else {
                self.base + start as u64
            },
            header,
            data,
        }))
    }
}

/// A record header's fields: `(name, value)` pairs.
type Fields<'a> = Vec<(&'a [u8], &'a [u8])>;

/// The `name=value` fields of a record header (or of a connection record's data).
fn fields(bytes: &[u8]) -> Result<Fields<'_>, String> {
    let mut out = Vec::new();
    let mut rest = bytes;
    while !rest.is_empty() {
        let Some((len, tail)) = rest.split_first_chunk::<4>() else {
            return Err(format!(
                "a header field's length is cut off ({} byte(s) left)",
                rest.len()
            ));
        };
        let len = u32::from_le_bytes(*len) as usize;
        let field = tail.get(..len).ok_or_else(|| {
            format!(
                "a header field claims {len} bytes but the header has {} left",
                tail.len()
            )
        })?;
        let eq = field
            .iter()
            .position(|&b| b == b'=')
            .ok_or_else(|| format!("the header field {:?} has no `=`", lossy(field)))?;
        out.push((&field[..eq], &field[eq + 1..]));
        rest = &tail[len..];
    }
    Ok(out)
}

fn lossy(bytes: &[u8]) -> String {
    String::from_utf8_lossy(&bytes[..bytes.len().min(40)]).into_owned()
}

fn field<'a>(fields: &[(&[u8], &'a [u8])], name: &str) -> Option<&'a [u8]> {
    fields
        .iter()
        .find(|(n, _)| *n == name.as_bytes())
        .map(|(_, v)| *v)
}

fn le_u32(v: &[u8]) -> Option<u32> {
    Some(u32::from_le_bytes(v.try_into().ok()?))
}

const OP_MESSAGE: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONNECTION: u8 = 0x07;

/// The index a closed bag ends with, as its bag header declares it and as the scan finds it.
/// A bag cut short after it was closed (or whose header is damaged) must be an error, not a
/// shorter bag: the index, written last, is what shows the cut. A bag that was never closed
/// (`index_pos` 0: the recorder stopped before writing the index) has none to check, and is
/// read up to where it is broken.
struct Index {
    /// Where the bag header puts the index (0: never written), and the record counts it
    /// declares.
    pos: u64,
    connections: u32,
    chunks: u32,
    /// The offset of the first top-level connection or chunk info record found, and the
    /// counts found.
    found_at: Option<u64>,
    found_connections: u32,
    found_chunks: u32,
}

impl Index {
    /// The declaration in the bag header `header` (the record at `offset`) of a file of
    /// `file_len` bytes.
    fn declared(header: &[(&[u8], &[u8])], offset: u64, file_len: u64) -> Result<Self, RosError> {
        let at = |what: String| RosError::Container { offset, what };
        let pos = field(header, "index_pos")
            .and_then(|v| Some(u64::from_le_bytes(v.try_into().ok()?)))
            .ok_or_else(|| at("the bag header has no 8-byte index_pos field".into()))?;
        let count = |name: &str| {
            field(header, name)
                .and_then(le_u32)
                .ok_or_else(|| at(format!("the bag header has no 4-byte {name} field")))
        };
        let (connections, chunks) = (count("conn_count")?, count("chunk_count")?);
        if pos >= file_len {
            return Err(at(format!(
                "the bag header's index_pos puts the index at byte {pos}, at or past the end of \
                 the file ({file_len} bytes): the bag is cut short"
            )));
        }
        Ok(Index {
            pos,
            connections,
            chunks,
            found_at: None,
            found_connections: 0,
            found_chunks: 0,
        })
    }

    /// Notes a top-level record of kind `op` at `offset`.
    fn saw(&mut self, op: u8, offset: u64) {
        if op == OP_CONNECTION || op == OP_CHUNK_INFO {
            self.found_at.get_or_insert(offset);
            match op {
                OP_CONNECTION => self.found_connections += 1,
                _ => self.found_chunks += 1,
            }
        }
    }

    /// Whether the index found is the one declared (always, for a bag never closed).
    fn check(&self, header_offset: u64) -> Result<(), RosError> {
        if self.pos == 0 {
            return Ok(());
        }
        let what = match self.found_at {
            None => format!(
                "the bag header's index_pos puts the index at byte {}, but the file holds no \
                 index records: the bag is cut short or damaged",
                self.pos
            ),
            Some(at) if at != self.pos => format!(
                "the bag header's index_pos puts the index at byte {}, but it starts at byte \
                 {at}: the bag header is damaged",
                self.pos
            ),
            Some(_)
                if (self.found_connections, self.found_chunks)
                    != (self.connections, self.chunks) =>
            {
                format!(
                    "the index (from byte {}) holds {} connection and {} chunk info records, \
                     but the bag header declares {} and {}: the bag is cut short or damaged",
                    self.pos,
                    self.found_connections,
                    self.found_chunks,
                    self.connections,
                    self.chunks
                )
            }
            Some(_) => return Ok(()),
        };
        Err(RosError::Container {
            offset: header_offset,
            what,
        })
    }
}

/// A message whose connection was not defined yet when it was read.
struct Pending {
    conn: u32,
    time_ns: u64,
    data: Vec<u8>,
    place: Place,
}

/// The scan's state: connections seen, messages waiting for theirs.
struct Scan<'c> {
    c: &'c mut Collector,
    /// Connection id -> topic index in the collector.
    connections: HashMap<u32, usize>,
    pending: Vec<Pending>,
}

impl Scan<'_> {
    /// Handles one record of the file or of a chunk (`records.inside`), and returns its op.
    fn record(&mut self, records: &Records<'_>, r: &Record<'_>) -> Result<u8, RosError> {
        let at = |what: String| RosError::Container {
            offset: r.offset,
            what: if records.inside {
                format!("in this chunk, {what}")
            } else {
                what
            },
        };
        let header = fields(r.header).map_err(at)?;
        let op = match field(&header, "op") {
            Some([op]) => *op,
            Some(v) => {
                return Err(at(format!(
                    "the record's op field holds {} bytes, not 1",
                    v.len()
                )));
            }
            None => return Err(at("a record has no op field".into())),
        };
        let conn = || {
            field(&header, "conn")
                .and_then(le_u32)
                .ok_or_else(|| at("the record has no 4-byte conn field".into()))
        };
        match op {
            OP_CHUNK if !records.inside => self.chunk(r, &header)?,
            OP_CONNECTION => {
                let conn = conn()?;
                let data = fields(r.data).map_err(|e| at(format!("connection {conn}: {e}")))?;
                let topic = field(&header, "topic")
                    .or_else(|| field(&data, "topic"))
                    .ok_or_else(|| at(format!("connection {conn} names no topic")))?;
                let message_type = field(&data, "type")
                    .ok_or_else(|| at(format!("connection {conn} names no message type")))?;
                let text = |v: &[u8], what: &str| {
                    std::str::from_utf8(v)
                        .map(str::to_string)
                        .map_err(|_| at(format!("connection {conn}: its {what} is not UTF-8")))
                };
                let topic = text(topic, "topic")?;
                let message_type = text(message_type, "type")?;
                let index = self.c.topic(&topic, &message_type, "ros1");
                // The index section repeats the chunks' connection records.
                self.connections.entry(conn).or_insert(index);
            }
            OP_MESSAGE => {
                let conn = conn()?;
                let time = field(&header, "time")
                    .filter(|t| t.len() == 8)
                    .ok_or_else(|| at("a message record has no 8-byte time field".into()))?;
                let secs = u64::from(le_u32(&time[..4]).expect("4 bytes"));
                let nsecs = u64::from(le_u32(&time[4..]).expect("4 bytes"));
                let time_ns = secs * 1_000_000_000 + nsecs;
                let place = if records.inside {
                    Place::Chunk(records.base)
                } else {
                    Place::Record(r.offset)
                };
                match self.connections.get(&conn) {
                    Some(&topic) => self.c.message(topic, time_ns, r.data, place)?,
                    None => self.pending.push(Pending {
                        conn,
                        time_ns,
                        data: r.data.to_vec(),
                        place,
                    }),
                }
            }
            // The bag header, index data and chunk info: nothing the scan needs (the index is
            // checked against the bag header by `Index`).
            _ => {}
        }
        Ok(op)
    }

    /// Decompresses a chunk and handles the records inside.
    fn chunk(&mut self, r: &Record<'_>, header: &[(&[u8], &[u8])]) -> Result<(), RosError> {
        let at = |what: String| RosError::Container {
            offset: r.offset,
            what,
        };
        let compression = field(header, "compression")
            .ok_or_else(|| at("a chunk has no compression field".into()))?;
        let size = field(header, "size")
            .and_then(le_u32)
            .ok_or_else(|| at("a chunk has no 4-byte size field".into()))?;
        let decompressed;
        let data: &[u8] = match compression {
            b"none" => r.data,
            b"bz2" | b"lz4" => {
                // Read at most one byte more than the chunk declares (to notice a longer
                // stream), and no more than the collector's cap (fuzzing); the buffer grows
                // with the bytes decompressed, never with the declared size alone.
                if u64::from(size) > self.c.limit() {
                    return Err(RosError::TooLarge {
                        limit: self.c.limit(),
                    });
                }
                let limit = u64::from(size) + 1;
                let mut out = Vec::new();
                let read = if compression == b"bz2" {
                    bzip2::read::BzDecoder::new(r.data)
                        .take(limit)
                        .read_to_end(&mut out)
                } else {
                    lz4_flex::frame::FrameDecoder::new(r.data)
                        .take(limit)
                        .read_to_end(&mut out)
                };
                read.map_err(|e| {
                    at(format!(
                        "the {} chunk does not decompress: {e}",
                        lossy(compression)
                    ))
                })?;
                decompressed = out;
                &decompressed
            }
            other => {
                return Err(at(format!(
                    "unknown chunk compression `{}` (ROS 1 bags use none, bz2 or lz4)",
                    lossy(other)
                )));
            }
        };
        if data.len() != size as usize {
            return Err(at(format!(
                "the {} chunk holds {} bytes of records, but its header says {size}",
                lossy(compression),
                data.len()
            )));
        }
        let mut inner = Records {
            bytes: data,
            pos: 0,
            base: r.offset,
            inside: compression != b"none",
        };
        if !inner.inside {
            // An uncompressed chunk's records are at known file offsets: its data start after
            // the header and the two length prefixes.
            inner.base = r.offset + 8 + r.header.len() as u64;
        }
        while let Some(record) = inner.next()? {
            self.record(&inner, &record)?;
        }
        Ok(())
    }
}

/// Scans the ROS 1 bag `bytes` into `c`.
pub(crate) fn scan(bytes: &[u8], c: &mut Collector) -> Result<(), RosError> {
    let magic = super::ROSBAG_MAGIC;
    if !bytes.starts_with(magic) {
        let what = if bytes.starts_with(b"#ROSBAG V") {
            let version = bytes
                .iter()
                .skip(9)
                .take_while(|&&b| b != b'\n')
                .take(10)
                .map(|&b| char::from(b))
                .collect::<String>();
            format!(
                "a ROS bag of version {version}; evtac reads version 2.0 (`rosbag fix` converts older bags)"
            )
        } else {
            "not a ROS 1 bag: it does not start with `#ROSBAG V2.0`".to_string()
        };
        return Err(RosError::Container { offset: 0, what });
    }
    let mut records = Records {
        bytes: &bytes[magic.len()..],
        pos: 0,
        base: magic.len() as u64,
        inside: false,
    };
    let mut scan = Scan {
        c,
        connections: HashMap::new(),
        pending: Vec::new(),
    };
    let header_offset = magic.len() as u64;
    let mut index: Option<Index> = None;
    while let Some(record) = records.next()? {
        let Some(index) = index.as_mut() else {
            let header = fields(record.header).map_err(|what| RosError::Container {
                offset: record.offset,
                what,
            })?;
            if field(&header, "op") != Some(&[OP_BAG_HEADER]) {
                return Err(RosError::Container {
                    offset: record.offset,
                    what: "the first record is not the bag header (op 0x03)".into(),
                });
            }
            index = Some(Index::declared(&header, record.offset, bytes.len() as u64)?);
            continue;
        };
        let op = scan.record(&records, &record)?;
        index.saw(op, record.offset);
    }
    index
        .ok_or_else(|| RosError::Container {
            offset: header_offset,
            what: "the file ends after its first line: it has no bag header record".into(),
        })?
        .check(header_offset)?;
    for p in std::mem::take(&mut scan.pending) {
        let topic = *scan.connections.get(&p.conn).ok_or_else(|| {
            let offset = match p.place {
                Place::Record(o) | Place::Chunk(o) => o,
                Place::Unknown => 0,
            };
            RosError::Container {
                offset,
                what: format!(
                    "a message refers to connection {}, which the bag never defines",
                    p.conn
                ),
            }
        })?;
        scan.c.message(topic, p.time_ns, &p.data, p.place)?;
    }
    Ok(())
}
