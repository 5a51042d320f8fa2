//! A data table decompressed as a stream, in pieces of at most [`PIECE`] bytes, so that checking
//! the table of a long recording (tens of megabytes decompressed) holds constant buffers rather
//! than the whole table (see [`super::table_check`]).
//!
//! The stream accepts only what [`super::compression::Decompressor`] accepts for the same bytes,
//! and is stricter where matching it exactly would take the whole input: a zstd frame must
//! declare its content size and be the input's only frame, an LZ4 frame must end exactly at the
//! input's end. Whatever it does not accept (`None`) the caller decompresses whole, so that the
//! error a damaged table gets is the whole decompressor's.

use std::io::Read;
use std::ops::ControlFlow;

use super::compression::{LZ4_MAGIC, Lz4Frame, MAX_PACKET_BYTES};
use super::header::Compression;

/// Largest piece handed to the sink, bytes.
pub(crate) const PIECE: usize = 64 << 10;

/// Compressed bytes read at a time.
const INPUT_BUFFER: usize = 128 << 10;

/// How a stream ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Streamed {
    /// All of the input decompressed: this many bytes.
    Whole(u64),
    /// The sink asked to stop.
    Stopped,
}

/// Decompresses `input` (all of it: a data table runs to the end of its file), handing the
/// output to `sink` piece by piece in order; `None` when the input is not one the stream
/// accepts (see the module docs), including an I/O error.
pub(crate) fn stream(
    input: &mut impl Read,
    compression: Compression,
    sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>,
) -> Option<Streamed> {
    match compression {
        Compression::None => raw(input, sink),
        Compression::Lz4 | Compression::Lz4High => lz4(input, sink),
        Compression::Zstd | Compression::ZstdHigh => zstd(input, sink),
    }
}

/// Hands `out` to `sink` in pieces; whether to go on.
fn emit(out: &[u8], sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>) -> ControlFlow<()> {
    out.chunks(PIECE).try_for_each(sink)
}

/// Uncompressed: the input itself.
fn raw(input: &mut impl Read, sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>) -> Option<Streamed> {
    let mut buf = vec![0u8; PIECE];
    let mut total = 0u64;
    loop {
        let n = fill(input, &mut buf)?;
        if n == 0 {
            return Some(Streamed::Whole(total));
        }
        total += n as u64;
        if sink(&buf[..n]).is_break() {
            return Some(Streamed::Stopped);
        }
    }
}

/// Reads until `buf` is full or the input ends; `None` on an I/O error.
fn fill(input: &mut impl Read, buf: &mut [u8]) -> Option<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match input.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => return None,
        }
    }
    Some(filled)
}

/// Exactly `n` bytes into `buf` (resized), `None` when the input ends first.
fn exact(input: &mut impl Read, buf: &mut Vec<u8>, n: usize) -> Option<()> {
    buf.resize(n, 0);
    (fill(input, buf)? == n).then_some(())
}

/// One zstd frame declaring its content size, ending at the input's end.
fn zstd(input: &mut impl Read, sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>) -> Option<Streamed> {
    use zstd::zstd_safe::{DCtx, InBuffer, OutBuffer, get_frame_content_size};
    let mut inbuf = vec![0u8; INPUT_BUFFER];
    let mut len = fill(input, &mut inbuf)?;
    // The frame header is at most 18 bytes: the first read holds it (or the whole input).
    let size = get_frame_content_size(&inbuf[..len]).ok()??;
    if size > MAX_PACKET_BYTES {
        return None;
    }
    let mut dctx = DCtx::create();
    let mut out = vec![0u8; PIECE];
    let mut total = 0u64;
    let mut ended = false;
    loop {
        let mut src = InBuffer::around(&inbuf[..len]);
        while src.pos() < len {
            if ended {
                // Bytes after the frame: another frame or garbage.
                return None;
            }
            let mut dst = OutBuffer::around(&mut out[..]);
            let hint = dctx.decompress_stream(&mut dst, &mut src).ok()?;
            let n = dst.pos();
            total += n as u64;
            if total > size || sink(&out[..n]).is_break() {
                return (total <= size).then_some(Streamed::Stopped);
            }
            ended = hint == 0;
        }
        // Flush what the context still holds once the input is used up.
        while !ended {
            let mut dst = OutBuffer::around(&mut out[..]);
            let mut none = InBuffer::around(&[]);
            let hint = dctx.decompress_stream(&mut dst, &mut none).ok()?;
            let n = dst.pos();
            if n == 0 {
                break;
            }
            total += n as u64;
            if total > size || sink(&out[..n]).is_break() {
                return (total <= size).then_some(Streamed::Stopped);
            }
            ended = hint == 0;
        }
        len = fill(input, &mut inbuf)?;
        if len == 0 {
            return (ended && total == size).then_some(Streamed::Whole(total));
        }
    }
}

/// One LZ4 frame, block by block (each decoded after the 64 KiB of output before it, as
/// [`super::compression`] decodes a whole frame), ending at the input's end.
fn lz4(input: &mut impl Read, sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>) -> Option<Streamed> {
    const DICT: usize = 64 << 10;
    let mut head = Vec::new();
    exact(input, &mut head, 6)?;
    if u32::from_le_bytes([head[0], head[1], head[2], head[3]]) != LZ4_MAGIC {
        return None;
    }
    let frame = Lz4Frame::parse(head[4], head[5]).ok()?;
    exact(input, &mut head, frame.header_len - 6)?;
    // `out[..kept]` is the output's last (up to) 64 KiB, the next block decodes after it.
    let mut out = vec![0u8; DICT + frame.max_block];
    let mut kept = 0usize;
    let mut block = Vec::new();
    let mut total = 0u64;
    loop {
        exact(input, &mut head, 4)?;
        let word = u32::from_le_bytes([head[0], head[1], head[2], head[3]]);
        if word == 0 {
            break;
        }
        let size = (word & 0x7FFF_FFFF) as usize;
        if size > frame.max_block || total + frame.max_block as u64 > MAX_PACKET_BYTES {
            return None;
        }
        exact(input, &mut block, size + frame.block_checksum)?;
        let block = &block[..size];
        let (before, rest) = out.split_at_mut(kept);
        let n = if word & 0x8000_0000 != 0 {
            rest[..size].copy_from_slice(block);
            size
        } else if frame.linked && total > 0 {
            lz4_flex::block::decompress_into_with_dict(block, &mut rest[..frame.max_block], before)
                .ok()?
        } else {
            lz4_flex::block::decompress_into(block, &mut rest[..frame.max_block]).ok()?
        };
        total += n as u64;
        if emit(&rest[..n], sink).is_break() {
            return Some(Streamed::Stopped);
        }
        let end = kept + n;
        let keep = end.min(DICT);
        out.copy_within(end - keep..end, 0);
        kept = keep;
    }
    exact(input, &mut head, frame.content_checksum)?;
    // Nothing may follow the frame.
    (fill(input, &mut [0u8; 1])? == 0).then_some(Streamed::Whole(total))
}
