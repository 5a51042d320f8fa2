//! The one error type of the AEDAT 4.0 reader and writer.

/// What can go wrong reading or writing AEDAT 4.0. Byte offsets count from the start of the file
/// (network mode: of the stream), so a report points at the broken spot with `xxd -s OFFSET`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AedatError {
    /// The file does not start with `#!AER-DAT4.0\r\n`.
    #[error(
        "not an AEDAT 4.0 file: the first 14 bytes are {found:?}, expected \"#!AER-DAT4.0\\r\\n\""
    )]
    BadMagic {
        /// The bytes found (fewer than 14 when the file is shorter).
        found: String,
    },
    /// The input ended inside the header (magic, size prefix or IOHeader).
    #[error("truncated AEDAT 4.0 header at byte {offset}: needed {needed} more bytes")]
    TruncatedHeader {
        /// Where the missing bytes were expected.
        offset: u64,
        /// How many bytes were still needed.
        needed: u64,
    },
    /// The input ended inside a packet (its 8-byte header or its body).
    #[error(
        "truncated packet at byte {offset} (stream {stream_id}): {got} of {expected} bytes present"
    )]
    TruncatedPacket {
        /// Byte offset of the packet's 8-byte header.
        offset: u64,
        /// The stream the packet belongs to (-1 when even its header is cut).
        stream_id: i32,
        /// Bytes the packet header or body should have.
        expected: u64,
        /// Bytes actually present.
        got: u64,
    },
    /// The file ended before the data table that its header announces.
    #[error(
        "file ends at byte {offset} but its header announces a data table at byte {data_table}"
    )]
    MissingDataTable {
        /// Where the input ended.
        offset: u64,
        /// The header's `dataTablePosition`.
        data_table: u64,
    },
    /// A packet runs past the data table that the header announces.
    #[error(
        "packet at byte {offset} (stream {stream_id}, {size} bytes) runs past the data table at byte {data_table}"
    )]
    PacketOverlapsDataTable {
        /// Byte offset of the packet header.
        offset: u64,
        /// The packet's stream.
        stream_id: i32,
        /// The packet's declared size.
        size: u64,
        /// The header's `dataTablePosition`.
        data_table: u64,
    },
    /// A size field is negative or larger than this reader accepts.
    #[error("bad {field} at byte {offset}: {value} (allowed 0..={limit})")]
    BadSize {
        /// Which size (`IOHeader size`, `packet size`, `decompressed packet size`).
        field: &'static str,
        /// Byte offset of the header or packet holding it.
        offset: u64,
        /// The value found.
        value: i64,
        /// The largest accepted value.
        limit: u64,
    },
    /// A flatbuffer failed verification or carries the wrong file identifier.
    #[error("bad {what} flatbuffer at byte {offset}: {reason}")]
    BadFlatbuffer {
        /// The table expected (`IOHeader`, `EventPacket`, `IMUPacket`, `TriggerPacket`).
        what: &'static str,
        /// Byte offset of the header or packet holding it.
        offset: u64,
        /// The verifier's complaint.
        reason: String,
    },
    /// The header's XML stream description is malformed or lacks a required attribute.
    #[error("bad stream description (infoNode XML): {reason}")]
    BadDescription {
        /// What is wrong.
        reason: String,
    },
    /// The header names a compression this reader does not know.
    #[error("unknown compression type {value} in the IOHeader (known: 0 NONE .. 4 ZSTD_HIGH)")]
    UnknownCompression {
        /// The raw `CompressionType` value.
        value: i32,
    },
    /// A packet's payload did not decompress.
    #[error(
        "cannot decompress packet at byte {offset} (stream {stream_id}, {compression}): {reason}"
    )]
    Decompression {
        /// Byte offset of the packet header.
        offset: u64,
        /// The packet's stream.
        stream_id: i32,
        /// The compression in use.
        compression: &'static str,
        /// The decompressor's complaint.
        reason: String,
    },
    /// A packet belongs to a stream the header does not declare.
    #[error("packet at byte {offset} names stream {stream_id}, which the header does not declare")]
    UnknownStream {
        /// Byte offset of the packet header.
        offset: u64,
        /// The undeclared stream id.
        stream_id: i32,
    },
    /// An event lies outside the stream's declared resolution (or has negative coordinates).
    #[error(
        "event {index} of stream {stream_id} (packet at byte {offset}) at x={x}, y={y} is outside {width}x{height} (the declared resolution or the int16 range)"
    )]
    OutOfBounds {
        /// Index of the event within its stream, from 0.
        index: u64,
        /// The event's stream.
        stream_id: i32,
        /// Byte offset of the packet header.
        offset: u64,
        /// The event's x as stored.
        x: i32,
        /// The event's y as stored.
        y: i32,
        /// Declared width (32768 when the stream declares none: only the non-negative `int16`
        /// range applies).
        width: u32,
        /// Declared height (32768 when the stream declares none).
        height: u32,
    },
    /// A timestamp is smaller than the one before it in the same stream.
    #[error(
        "timestamps go backwards in stream {stream_id} at element {index} (packet at byte {offset}): {previous} then {current}"
    )]
    TimestampBackwards {
        /// The stream.
        stream_id: i32,
        /// Index of the offending element within its stream, from 0.
        index: u64,
        /// Byte offset of the packet header.
        offset: u64,
        /// The previous timestamp (microseconds).
        previous: i64,
        /// The offending timestamp (microseconds).
        current: i64,
    },
    /// A range read was asked for an empty time range.
    #[error("the time range [{from}, {to}) us is empty: from must be smaller than to")]
    EmptyRange {
        /// Start of the range (included), microseconds.
        from: i64,
        /// End of the range (excluded), microseconds.
        to: i64,
    },
    /// A packet that a range read located through the data table is not what the table says
    /// (the table passed every check that needs no packet, so it is damaged in a way only the
    /// packet shows; a full read does not use the table).
    #[error(
        "the data table disagrees with the packet at byte {offset}: its {field} is {found}, the table says {table}"
    )]
    DataTableMismatch {
        /// Byte offset of the packet header.
        offset: u64,
        /// The table field (`StreamID`, `Size`, `NumElements`, `TimestampStart`, `TimestampEnd`).
        field: &'static str,
        /// What the table says.
        table: i64,
        /// What the packet holds.
        found: i64,
    },
    /// The writer was given data it cannot store (e.g. coordinates outside its resolution).
    #[error("cannot write {what}: {reason}")]
    InvalidInput {
        /// What was being written (`event 12`, `IMU sample 3`, ...).
        what: String,
        /// Why it cannot be written.
        reason: String,
    },
    /// Reading or writing the underlying stream failed.
    #[error("I/O error at byte {offset}: {source}")]
    Io {
        /// Byte offset reached when the error happened.
        offset: u64,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

/// Shorthand for results of this module.
pub type Result<T, E = AedatError> = std::result::Result<T, E>;
