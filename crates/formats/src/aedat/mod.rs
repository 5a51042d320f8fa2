//! AEDAT 4.0 (iniVation DV) files and network streams: reader and writer.
//!
//! An AEDAT 4.0 file is the magic `#!AER-DAT4.0\r\n`, a size-prefixed `IOHeader` flatbuffer
//! (compression, data-table position, and an XML description of the streams), then packets:
//! an 8-byte header (stream id `i32`, size `i32`, little-endian) and the packet's size-prefixed
//! flatbuffer (`EventPacket`, `IMUPacket`, `TriggerPacket`, ...), compressed on its own with LZ4
//! or zstd when the header says so. An optional data table (an index of the packets) ends the
//! file. DV's network protocol (`dv.io.NetworkWriter`) sends the same header and packets without
//! the magic and the data table. The schemas are in `crates/formats/schema/`.
//!
//! [`AedatReader`] streams packets from any `Read` with bounded memory; [`AedatWriter`] writes
//! events, IMU samples and triggers (DV's `Trigger` stream: the camera's sync input) that
//! dv-processing reads back exactly, and ends seekable outputs with the data table as DV does.
//!
//! The data table is an index: each packet's offset, stream, element count and first and last
//! timestamps. [`AedatReader::select_range`] uses it to read a time range `[from, to)` of a
//! long recording by seeking to the packets that overlap it, so reading a trial out of a
//! multi-gigabyte session touches only that trial's packets; without a usable table it scans
//! the file instead and says why.
//!
//! ```
//! use evtac_formats::aedat::{AedatReader, AedatWriter, Compression, WriterConfig};
//! use evtac_events::{Event, ImuSample, Resolution, Trigger};
//!
//! let config = WriterConfig {
//!     resolution: Resolution::new(640, 480),
//!     source_name: "DVXplorer_DXA00000".into(),
//!     compression: Compression::Lz4,
//! };
//! let mut writer = AedatWriter::new(Vec::new(), config)?;
//! writer.write_events(&[Event { t: 10, x: 320, y: 240, polarity: false }])?;
//! writer.write_imu(&[ImuSample { t: 12, accelerometer: [0.0, -1.0, 0.0], ..Default::default() }])?;
//! writer.write_triggers(&[Trigger { t: 15, kind: 1 }])?; // EXTERNAL_SIGNAL_RISING_EDGE
//! let bytes = writer.finish()?;
//!
//! let mut reader = AedatReader::from_slice(&bytes)?;
//! assert_eq!(reader.source(), Some("DVXplorer_DXA00000"));
//! let (mut events, mut imu, mut triggers) = (0, 0, 0);
//! while let Some(chunk) = reader.next_chunk()? {
//!     events += chunk.events.len();
//!     imu += chunk.imu.len();
//!     triggers += chunk.triggers.len();
//! }
//! assert_eq!((events, imu, triggers), (1, 1, 1));
//! # Ok::<(), evtac_formats::aedat::AedatError>(())
//! ```

mod compression;
mod error;
pub(crate) mod family;
mod header;
mod index;
mod packet;
mod reader;
pub mod schema;
mod selection;
mod table_check;
mod table_stream;
mod writer;

pub use compression::MAX_PACKET_BYTES;
pub use error::{AedatError, Result};
pub use header::{AedatHeader, Compression, MAGIC, StreamInfo, StreamKind, parse_description};
pub use reader::{AedatChunk, AedatReader, Events};
pub use selection::{ChosenStreams, SelectionError, list_streams};
pub use writer::{
    AedatWriter, EVENTS_PER_PACKET, IMU_PER_PACKET, PACKET_SPAN_US, TRIGGERS_PER_PACKET,
    WriterConfig,
};

/// Whether the size-prefixed flatbuffer `buf` carries `identifier`. flatbuffers'
/// `buffer_has_identifier` asserts (panics) on a buffer too short to hold a prefix, a root
/// offset and an identifier, so the length is checked here first (found by the `aedat` fuzz
/// target).
pub(crate) fn has_identifier(buf: &[u8], identifier: &str) -> bool {
    const PREFIX_ROOT_AND_IDENTIFIER: usize = 4 + 4 + 4;
    buf.len() >= PREFIX_ROOT_AND_IDENTIFIER
        && flatbuffers::buffer_has_identifier(buf, identifier, true)
}

/// Decodes `data` completely, as a file (sequentially, the streams a default selection picks,
/// and through its data table as a range read) and as a network stream, discarding the results: the entry point of the `aedat`
/// cargo-fuzz target. It must never panic, whatever the bytes.
#[doc(hidden)]
pub fn fuzz_decode(data: &[u8]) {
    if let Ok(mut reader) = AedatReader::from_slice(data) {
        while let Ok(Some(_)) = reader.next_chunk() {}
    }
    // The streams a default selection picks (several cameras: an error listing them).
    if let Ok(mut reader) = AedatReader::from_slice(data)
        && let Ok(chosen) = crate::StreamSelection::default().resolve(reader.header())
    {
        reader.select_streams(&chosen);
        while let Ok(Some(_)) = reader.next_chunk() {}
    }
    if let Ok(mut reader) = AedatReader::new(std::io::Cursor::new(data))
        && reader.select_range(i64::MIN, i64::MAX).is_ok()
    {
        while let Ok(Some(_)) = reader.next_chunk() {}
    }
    if let Ok(mut reader) = AedatReader::network(data) {
        while let Ok(Some(_)) = reader.next_chunk() {}
    }
    let _ = std::str::from_utf8(data).map(parse_description);
}
