//! Packet (de)compression: DV compresses each packet's flatbuffer on its own, LZ4 as one LZ4
//! *frame* (`LZ4F_compressFrame`: magic `04 22 4D 18`, linked 64 KiB blocks) and zstd as one
//! zstd frame. Decompressor state and buffers live as long as the reader, so decoding a packet
//! allocates nothing once the buffers have grown to the largest packet.
//!
//! DV reads and writes these with the C libraries (`LZ4F_*`, `ZSTD_*`); the LZ4 frames are
//! decoded block by block with lz4_flex, the zstd frames with the zstd crate (bindings to the same
//! C library).

use std::io::{self, Read, Write};

use super::header::Compression;

/// Largest decompressed packet accepted (DV writes packets of a few hundred KiB at most); a
/// limit keeps a corrupt or hostile size from exhausting memory.
pub const MAX_PACKET_BYTES: u64 = 1 << 30;
/// A zstd frame declaring more than this many times its own size is decoded as a stream rather
/// than into a buffer reserved at the declared size (DV's event and IMU packets compress a few
/// times at most).
const MAX_BULK_RATIO: u64 = 64;

/// LZ4 frame magic number (little-endian `04 22 4D 18`).
pub(crate) const LZ4_MAGIC: u32 = 0x184D_2204;

/// What an LZ4 frame's descriptor (its `FLG` and `BD` bytes) says.
pub(crate) struct Lz4Frame {
    /// Blocks may refer to the 64 KiB of output before them.
    pub linked: bool,
    /// Bytes of checksum after each block.
    pub block_checksum: usize,
    /// Largest decoded block.
    pub max_block: usize,
    /// Bytes from the frame's start to its first block.
    pub header_len: usize,
    /// Bytes of checksum after the end mark.
    pub content_checksum: usize,
}

impl Lz4Frame {
    /// Reads the descriptor bytes `flg` and `bd` (after the 4-byte magic).
    pub fn parse(flg: u8, bd: u8) -> Result<Self, String> {
        if flg >> 6 != 1 {
            return Err(format!("unsupported LZ4 frame version {}", flg >> 6));
        }
        let max_block = match (bd >> 4) & 7 {
            4 => 64 << 10,
            5 => 256 << 10,
            6 => 1 << 20,
            7 => 4 << 20,
            other => return Err(format!("bad LZ4 block size code {other}")),
        };
        Ok(Self {
            linked: flg & 0x20 == 0,
            block_checksum: if flg & 0x10 != 0 { 4 } else { 0 },
            max_block,
            // magic, FLG, BD, optional content size (8) and dictionary id (4), header checksum.
            header_len: 6
                + if flg & 0x08 != 0 { 8 } else { 0 }
                + if flg & 0x01 != 0 { 4 } else { 0 }
                + 1,
            content_checksum: if flg & 0x04 != 0 { 4 } else { 0 },
        })
    }
}

/// Decodes one LZ4 frame (the format of the LZ4 frame specification, v1.6) into
/// the front of `out`, growing `out` as needed; returns the decoded length.
///
/// Written here rather than with lz4_flex's `FrameDecoder` because that decoder (a) reports a
/// frame cut at a block boundary as a clean end, which would hide truncated packets, and (b)
/// copies every byte twice through its own buffers; this walks the blocks and hands each to
/// lz4_flex's block decoder, writing straight into the packet buffer. Block and content
/// checksums (which DV does not write) are skipped, not verified. `out` keeps its length
/// between packets (only `..returned` is meaningful) so it is zeroed only when it grows.
fn lz4_decode_frame(bytes: &[u8], out: &mut Vec<u8>) -> Result<usize, String> {
    let cut = || "the LZ4 frame is cut short".to_owned();
    let take = |pos: usize, n: usize| bytes.get(pos..pos + n).ok_or_else(cut);
    let word = |pos: usize| -> Result<u32, String> {
        let w = take(pos, 4)?;
        Ok(u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    if word(0)? != LZ4_MAGIC {
        return Err("not an LZ4 frame (bad magic number)".to_owned());
    }
    let Lz4Frame {
        linked,
        block_checksum,
        max_block,
        header_len,
        content_checksum,
    } = Lz4Frame::parse(take(4, 1)?[0], take(5, 1)?[0])?;
    let mut pos = header_len;
    let mut len = 0usize;
    loop {
        let head = word(pos)?;
        pos += 4;
        if head == 0 {
            break;
        }
        let size = (head & 0x7FFF_FFFF) as usize;
        if size > max_block {
            return Err(format!(
                "LZ4 block of {size} bytes exceeds the frame's {max_block}"
            ));
        }
        let block = take(pos, size)?;
        pos += size + block_checksum;
        if (len + max_block) as u64 > MAX_PACKET_BYTES {
            return Err(format!(
                "decompresses to more than the {MAX_PACKET_BYTES} bytes accepted"
            ));
        }
        if out.len() < len + max_block {
            out.resize(len + max_block, 0);
        }
        let n = if head & 0x8000_0000 != 0 {
            out[len..len + size].copy_from_slice(block);
            size
        } else if linked && len > 0 {
            // Linked blocks may refer to the previous 64 KiB of output.
            let (before, rest) = out.split_at_mut(len);
            let dict = &before[len.saturating_sub(64 << 10)..];
            lz4_flex::block::decompress_into_with_dict(block, &mut rest[..max_block], dict)
                .map_err(|e| e.to_string())?
        } else {
            lz4_flex::block::decompress_into(block, &mut out[len..len + max_block])
                .map_err(|e| e.to_string())?
        };
        len += n;
    }
    pos += content_checksum;
    match pos.cmp(&bytes.len()) {
        std::cmp::Ordering::Equal => Ok(len),
        std::cmp::Ordering::Greater => Err(cut()),
        std::cmp::Ordering::Less => Err(format!(
            "{} bytes left over after the LZ4 frame",
            bytes.len() - pos
        )),
    }
}

/// Decompresses packets one after the other into a reused buffer.
pub(crate) struct Decompressor {
    compression: Compression,
    input: Vec<u8>,
    zstd: Option<zstd::bulk::Decompressor<'static>>,
    out: Vec<u8>,
}

impl Decompressor {
    /// A decompressor for `compression`.
    pub fn new(compression: Compression) -> Self {
        Self {
            compression,
            input: Vec::new(),
            zstd: None,
            out: Vec::new(),
        }
    }

    /// The buffer to fill with the next packet's (compressed) body; cleared.
    pub fn input(&mut self) -> &mut Vec<u8> {
        self.input.clear();
        &mut self.input
    }

    /// Gives back the buffers' memory beyond `bytes` (after an unusually large input, such as a
    /// long recording's data table, so that it is not kept for the reader's lifetime).
    pub fn shrink_to(&mut self, bytes: usize) {
        self.input.clear();
        self.input.shrink_to(bytes);
        // Only `..returned` of `out` is ever meaningful: the rest may go.
        self.out.truncate(bytes);
        self.out.shrink_to(bytes);
    }

    /// Decompresses the bytes put into [`Self::input`] and returns the packet's flatbuffer.
    pub fn decompress(&mut self) -> Result<&[u8], String> {
        let input = &self.input;
        match self.compression {
            Compression::None => Ok(input),
            Compression::Lz4 | Compression::Lz4High => {
                let n = lz4_decode_frame(input, &mut self.out)?;
                Ok(&self.out[..n])
            }
            Compression::Zstd | Compression::ZstdHigh => {
                self.out.clear();
                let size = zstd::zstd_safe::get_frame_content_size(input)
                    .map_err(|_| "not a zstd frame (bad frame header)".to_owned())?;
                if let Some(size) = size
                    && size > MAX_PACKET_BYTES
                {
                    return Err(format!(
                        "frame declares {size} bytes, more than the {MAX_PACKET_BYTES} accepted"
                    ));
                }
                // Reserve the declared size only when the compressed bytes could plausibly hold
                // it: a 20-byte frame declaring 1 GiB must not allocate 1 GiB (found by the
                // bad-input matrix). Anything else is streamed, growing with the bytes produced.
                let plausible = (input.len() as u64).saturating_mul(MAX_BULK_RATIO);
                match size {
                    Some(size) if size <= plausible => {
                        let dctx = match &mut self.zstd {
                            Some(d) => d,
                            None => self.zstd.insert(
                                zstd::bulk::Decompressor::new().map_err(|e| e.to_string())?,
                            ),
                        };
                        // `size` is at most 1 GiB: fits in usize on every supported target.
                        self.out.reserve(size as usize);
                        let n = dctx
                            .decompress_to_buffer(input.as_slice(), &mut self.out)
                            .map_err(|e| e.to_string())?;
                        if n as u64 != size {
                            return Err(format!("frame says {size} bytes, decoded {n}"));
                        }
                    }
                    _ => {
                        // Frames written without a content size, or declaring more than their
                        // bytes plausibly hold: stream them, bounded.
                        zstd::stream::read::Decoder::with_buffer(input.as_slice())
                            .map_err(|e| e.to_string())?
                            .take(MAX_PACKET_BYTES + 1)
                            .read_to_end(&mut self.out)
                            .map_err(|e| e.to_string())?;
                        let n = self.out.len() as u64;
                        if n > MAX_PACKET_BYTES {
                            return Err(format!(
                                "decompresses to more than the {MAX_PACKET_BYTES} bytes accepted"
                            ));
                        }
                        if let Some(size) = size
                            && n != size
                        {
                            return Err(format!("frame says {size} bytes, decoded {n}"));
                        }
                    }
                }
                Ok(&self.out)
            }
        }
    }
}

/// Compresses packets for the writer into a reused buffer.
pub(crate) struct Compressor {
    compression: Compression,
    zstd: Option<zstd::bulk::Compressor<'static>>,
    out: Vec<u8>,
}

/// zstd level for [`Compression::Zstd`] (fast, as DV's default) and [`Compression::ZstdHigh`].
const ZSTD_LEVEL: i32 = 1;
const ZSTD_HIGH_LEVEL: i32 = 19;

impl Compressor {
    /// A compressor for `compression`.
    pub fn new(compression: Compression) -> io::Result<Self> {
        let mut zstd = match compression {
            Compression::Zstd => Some(zstd::bulk::Compressor::new(ZSTD_LEVEL)?),
            Compression::ZstdHigh => Some(zstd::bulk::Compressor::new(ZSTD_HIGH_LEVEL)?),
            _ => None,
        };
        if let Some(z) = zstd.as_mut() {
            // Readers size their output from the frame header: always record the content size.
            z.include_contentsize(true)?;
            z.include_checksum(false)?;
        }
        Ok(Self {
            compression,
            zstd,
            out: Vec::new(),
        })
    }

    /// `data` compressed (or `data` itself without compression).
    pub fn compress<'a>(&'a mut self, data: &'a [u8]) -> io::Result<&'a [u8]> {
        self.out.clear();
        match self.compression {
            Compression::None => return Ok(data),
            Compression::Lz4 | Compression::Lz4High => {
                // Linked 64 KiB blocks, no checksums: the frame `LZ4F_compressFrame` writes for DV.
                let info = lz4_flex::frame::FrameInfo::new()
                    .block_size(lz4_flex::frame::BlockSize::Max64KB)
                    .block_mode(lz4_flex::frame::BlockMode::Linked);
                let mut enc = lz4_flex::frame::FrameEncoder::with_frame_info(info, &mut self.out);
                enc.write_all(data)?;
                enc.finish().map_err(io::Error::other)?;
            }
            Compression::Zstd | Compression::ZstdHigh => {
                let z = self
                    .zstd
                    .as_mut()
                    .ok_or_else(|| io::Error::other("zstd compressor missing"))?;
                self.out
                    .reserve(zstd::zstd_safe::compress_bound(data.len()));
                z.compress_to_buffer(data, &mut self.out)?;
            }
        }
        Ok(&self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_every_compression() {
        let data: Vec<u8> = (0..200_000u32)
            .flat_map(|i| (i / 7).to_le_bytes())
            .collect();
        for c in [
            Compression::None,
            Compression::Lz4,
            Compression::Lz4High,
            Compression::Zstd,
            Compression::ZstdHigh,
        ] {
            let mut comp = Compressor::new(c).unwrap();
            let packed = comp.compress(&data).unwrap().to_vec();
            let mut d = Decompressor::new(c);
            // Twice, to check that state carries over cleanly between packets.
            for _ in 0..2 {
                d.input().extend_from_slice(&packed);
                assert_eq!(d.decompress().unwrap(), &data[..], "{c}");
            }
        }
    }

    #[test]
    fn lz4_frames_with_checksums_and_independent_blocks_decode() {
        let data: Vec<u8> = (0..300_000u32)
            .flat_map(|i| (i / 3).to_le_bytes())
            .collect();
        for (mode, checksums) in [
            (lz4_flex::frame::BlockMode::Linked, true),
            (lz4_flex::frame::BlockMode::Independent, false),
            (lz4_flex::frame::BlockMode::Independent, true),
        ] {
            let info = lz4_flex::frame::FrameInfo::new()
                .block_mode(mode)
                .block_checksums(checksums)
                .content_checksum(checksums);
            let mut enc = lz4_flex::frame::FrameEncoder::with_frame_info(info, Vec::new());
            enc.write_all(&data).unwrap();
            let frame = enc.finish().unwrap();
            let mut out = Vec::new();
            let n = lz4_decode_frame(&frame, &mut out).unwrap();
            assert_eq!(&out[..n], &data[..]);
        }
    }

    #[test]
    fn lz4_frame_cut_at_a_block_boundary_is_an_error() {
        let data: Vec<u8> = (0..100_000u32).flat_map(|i| i.to_le_bytes()).collect();
        let mut c = Compressor::new(Compression::Lz4).unwrap();
        let frame = c.compress(&data).unwrap().to_vec();
        // Drop the end mark, then also the last block.
        let mut out = Vec::new();
        assert!(lz4_decode_frame(&frame[..frame.len() - 4], &mut out).is_err());
        for cut in 0..frame.len() {
            assert!(
                lz4_decode_frame(&frame[..cut], &mut out).is_err(),
                "cut {cut}"
            );
        }
    }

    #[test]
    fn garbage_is_an_error() {
        for c in [Compression::Lz4, Compression::Zstd] {
            let mut d = Decompressor::new(c);
            d.input().extend_from_slice(b"definitely not compressed");
            assert!(d.decompress().is_err(), "{c}");
        }
    }
}
