//! Packet (de)compression: DV compresses each packet's flatbuffer on its own, LZ4 as one LZ4
//! *frame* (`LZ4F_compressFrame`: magic `04 22 4D 18`, linked 64 KiB blocks) and zstd as one
//! zstd frame. Decompressor state and buffers live as long as the reader, so decoding a packet
//! allocates nothing once the buffers have grown to the largest packet.

use std::io::{self, Read, Write};

use super::header::Compression;

/// Largest decompressed packet accepted (DV writes packets of a few hundred KiB at most); a
/// limit keeps a corrupt or hostile size from exhausting memory.
pub const MAX_PACKET_BYTES: u64 = 1 << 30;

/// The compressed bytes of the current packet, read by the LZ4 frame decoder. Owning the bytes
/// here lets one `FrameDecoder` (and its 64 KiB window buffers) serve every packet.
#[derive(Default)]
struct PacketSource {
    bytes: Vec<u8>,
    pos: usize,
}

impl Read for PacketSource {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let n = rest.len().min(buf.len());
        buf[..n].copy_from_slice(&rest[..n]);
        self.pos += n;
        Ok(n)
    }
}

/// Walks an LZ4 frame's block structure and checks that it ends with its end mark (and content
/// checksum, when flagged) exactly at the end of `bytes`. lz4_flex's `FrameDecoder` reports a
/// frame cut at a block boundary as a clean end, which would hide a truncated packet.
fn lz4_frame_is_complete(bytes: &[u8]) -> Result<(), String> {
    let cut = || "the LZ4 frame is cut short".to_owned();
    let flg = *bytes.get(4).ok_or_else(cut)?;
    // magic (4), FLG, BD, optional content size (8) and dictionary id (4), header checksum.
    let mut pos =
        4 + 2 + if flg & 0x08 != 0 { 8 } else { 0 } + if flg & 0x01 != 0 { 4 } else { 0 } + 1;
    let block_checksum = if flg & 0x10 != 0 { 4 } else { 0 };
    loop {
        let word = bytes
            .get(pos..pos + 4)
            .and_then(|w| w.first_chunk::<4>())
            .ok_or_else(cut)?;
        let size = u32::from_le_bytes(*word) & 0x7FFF_FFFF;
        pos += 4;
        if size == 0 {
            break;
        }
        pos += size as usize + block_checksum;
    }
    pos += if flg & 0x04 != 0 { 4 } else { 0 };
    match pos.cmp(&bytes.len()) {
        std::cmp::Ordering::Equal => Ok(()),
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
    lz4: lz4_flex::frame::FrameDecoder<PacketSource>,
    zstd: Option<zstd::bulk::Decompressor<'static>>,
    out: Vec<u8>,
}

impl Decompressor {
    /// A decompressor for `compression`.
    pub fn new(compression: Compression) -> Self {
        Self {
            compression,
            lz4: lz4_flex::frame::FrameDecoder::new(PacketSource::default()),
            zstd: None,
            out: Vec::new(),
        }
    }

    /// The buffer to fill with the next packet's (compressed) body; cleared.
    pub fn input(&mut self) -> &mut Vec<u8> {
        let src = self.lz4.get_mut();
        src.bytes.clear();
        src.pos = 0;
        &mut src.bytes
    }

    /// Decompresses the bytes put into [`Self::input`] and returns the packet's flatbuffer.
    pub fn decompress(&mut self) -> Result<&[u8], String> {
        match self.compression {
            Compression::None => Ok(&self.lz4.get_ref().bytes),
            Compression::Lz4 | Compression::Lz4High => {
                self.out.clear();
                (&mut self.lz4)
                    .take(MAX_PACKET_BYTES + 1)
                    .read_to_end(&mut self.out)
                    .map_err(|e| e.to_string())?;
                let src = self.lz4.get_ref();
                // lz4_flex takes a frame cut at a block boundary as complete: check the framing.
                lz4_frame_is_complete(&src.bytes)?;
                if src.pos != src.bytes.len() {
                    return Err(format!(
                        "{} bytes left over after the LZ4 frame",
                        src.bytes.len() - src.pos
                    ));
                }
                self.check_size()?;
                Ok(&self.out)
            }
            Compression::Zstd | Compression::ZstdHigh => {
                self.out.clear();
                let input = &self.lz4.get_ref().bytes;
                let size = zstd::zstd_safe::get_frame_content_size(input)
                    .map_err(|_| "not a zstd frame (bad frame header)".to_owned())?;
                match size {
                    Some(size) if size <= MAX_PACKET_BYTES => {
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
                    Some(size) => {
                        return Err(format!(
                            "frame declares {size} bytes, more than the {MAX_PACKET_BYTES} accepted"
                        ));
                    }
                    None => {
                        // Frames written without a content size: stream them, bounded.
                        zstd::stream::read::Decoder::with_buffer(input.as_slice())
                            .map_err(|e| e.to_string())?
                            .take(MAX_PACKET_BYTES + 1)
                            .read_to_end(&mut self.out)
                            .map_err(|e| e.to_string())?;
                        self.check_size()?;
                    }
                }
                Ok(&self.out)
            }
        }
    }

    fn check_size(&self) -> Result<(), String> {
        if self.out.len() as u64 > MAX_PACKET_BYTES {
            Err(format!(
                "decompresses to more than the {MAX_PACKET_BYTES} bytes accepted"
            ))
        } else {
            Ok(())
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
    fn garbage_is_an_error() {
        for c in [Compression::Lz4, Compression::Zstd] {
            let mut d = Decompressor::new(c);
            d.input().extend_from_slice(b"definitely not compressed");
            assert!(d.decompress().is_err(), "{c}");
        }
    }
}
