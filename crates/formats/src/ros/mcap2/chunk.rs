//! What evtac checks of MCAP records before the `mcap` crate parses them, and the chunks it
//! opens itself.
//!
//! The crate's linear reader walked an uncompressed chunk's records trusting each one's length:
//! a record reaching past its chunk made it subtract past zero (an overflow panic where overflow
//! is checked, a wrapped count and records read from outside the chunk where not), found by the
//! `mcap` fuzz target. So the reader hands each chunk over whole (`emit_chunks`) and this module
//! decompresses it (zstd, or lz4 through the workspace's safe `lz4_flex`), growing the buffer
//! with the bytes produced and never past the declared size, and walks its records with every
//! length checked against the chunk. The crate also reserves a string's declared length before
//! reading it (4 GiB seen), so the strings of the records that hold some are checked against
//! their record first (`strings_fit`). Chunk CRCs are not checked, as the crate's reader did
//! not check them by default.

use std::io::Read;

use mcap::records::{ChunkHeader, op};

use super::super::RosError;

fn mcap_error(what: String) -> RosError {
    RosError::Mcap { read_to: 0, what }
}

/// The records of a chunk: its data as they are, or decompressed into `inflated`; at most
/// `limit` bytes of them.
pub(super) fn records<'a>(
    header: &ChunkHeader,
    data: &'a [u8],
    limit: usize,
    inflated: &'a mut Vec<u8>,
) -> Result<&'a [u8], RosError> {
    let size = header.uncompressed_size;
    let compression = header.compression.as_str();
    let records: &[u8] = match compression {
        "" => data,
        "zstd" | "lz4" => {
            if size > limit as u64 {
                return Err(mcap_error(format!(
                    "a {compression} chunk declares {size} bytes of records, more than the \
                     {limit} accepted"
                )));
            }
            inflated.clear();
            // One byte past the declared size, to notice a longer stream.
            let take = size + 1;
            let read = if compression == "zstd" {
                zstd::stream::read::Decoder::with_buffer(data)
                    .and_then(|d| d.take(take).read_to_end(inflated))
            } else {
                lz4_flex::frame::FrameDecoder::new(data)
                    .take(take)
                    .read_to_end(inflated)
            };
            read.map_err(|e| {
                mcap_error(format!("a {compression} chunk does not decompress: {e}"))
            })?;
            inflated
        }
        other => {
            return Err(mcap_error(format!(
                "a chunk's compression `{}` is not one evtac reads (none, zstd, lz4)",
                other.chars().take(40).collect::<String>()
            )));
        }
    };
    if records.len() as u64 != size {
        return Err(mcap_error(format!(
            "a chunk holds {} bytes of records but declares {size}",
            records.len()
        )));
    }
    Ok(records)
}

/// Hands each record of a chunk's `records` (its opcode and body) to `each`.
pub(super) fn each_record(
    records: &[u8],
    mut each: impl FnMut(u8, &[u8]) -> Result<(), RosError>,
) -> Result<(), RosError> {
    let mut at = 0;
    while at < records.len() {
        let Some(head) = records.get(at..at + 9) else {
            return Err(mcap_error(format!(
                "a record inside a chunk is cut off: its opcode and length at byte {at} run past \
                 the chunk's {} bytes of records",
                records.len()
            )));
        };
        let opcode = head[0];
        let len = u64::from_le_bytes(head[1..].try_into().expect("8 bytes"));
        let body = usize::try_from(len)
            .ok()
            .and_then(|len| records.get(at + 9..)?.get(..len))
            .ok_or_else(|| {
                mcap_error(format!(
                    "a record (opcode 0x{opcode:02x}) at byte {at} of a chunk's records claims \
                     {len} bytes, past the chunk's end ({} bytes)",
                    records.len()
                ))
            })?;
        if opcode == op::CHUNK {
            return Err(mcap_error(format!(
                "a chunk holds a chunk record (at byte {at} of its records)"
            )));
        }
        each(opcode, body)?;
        at += 9 + body.len();
    }
    Ok(())
}

/// Checks that the length-prefixed strings of a record (and the strings of its string maps)
/// lie inside it, for the records the scan parses that hold strings (schemas, channels,
/// chunks): the `mcap` crate (0.26) reserves a string's declared length before reading it, and
/// a damaged length of 4 GiB (found by fuzzing, in a channel record of a few bytes) was
/// reserved.
pub(super) fn strings_fit(opcode: u8, record: &[u8]) -> Result<(), RosError> {
    /// What comes next in a record: fixed-size fields, a string, or a string map (its length in
    /// bytes, then key and value strings).
    #[derive(Clone, Copy)]
    enum Step {
        Skip(usize),
        Str,
        Map,
    }
    use Step::{Map, Skip, Str};
    /// A length prefix at `at` and the end of what it counts, if that is inside `end`.
    fn prefixed(record: &[u8], at: usize, end: usize) -> Option<usize> {
        let len = record.get(at..at.checked_add(4)?)?;
        let len = u32::from_le_bytes(len.try_into().ok()?) as usize;
        at.checked_add(4)?.checked_add(len).filter(|&e| e <= end)
    }
    let steps: &[Step] = match opcode {
        op::SCHEMA => &[Skip(2), Str, Str],
        op::CHANNEL => &[Skip(4), Str, Str, Map],
        // Start and end times, sizes and CRC, then the compression.
        op::CHUNK => &[Skip(28), Str],
        _ => &[],
    };
    let end = record.len();
    let mut at = Some(0usize);
    for step in steps {
        at = at.and_then(|at| match *step {
            Skip(n) => at.checked_add(n).filter(|&e| e <= end),
            Str => prefixed(record, at, end),
            Map => {
                let map_end = prefixed(record, at, end)?;
                let mut at = at + 4;
                while at < map_end {
                    at = prefixed(record, prefixed(record, at, map_end)?, map_end)?;
                }
                Some(at)
            }
        });
    }
    match at {
        Some(_) => Ok(()),
        None => Err(RosError::Mcap {
            read_to: 0, // set by `scan`
            what: format!(
                "a record (opcode 0x{opcode:02x}) of {end} bytes holds a string longer than the \
                 record"
            ),
        }),
    }
}
