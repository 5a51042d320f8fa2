//! One member of an NPZ (zip) archive, read as a stream of its own beside the others.
//!
//! Why not the `zip` crate's member reader: it borrows the archive mutably, so one member can
//! be open at a time, and an archive of one array per field had to be read whole, column after
//! column, before the first event could be built (four columns widened to `i64` and an event
//! vector: 5 M events touched 300 MB, whose page faults were most of the read). Here the crate
//! still parses the central directory and each member's local header (and refuses encrypted
//! members and compression methods it cannot read); each member is then read from its data
//! offset by a [`Member`] of its own over the shared source, stored bytes straight into the
//! caller's buffer and deflated ones through the same `flate2` decoder the crate uses, so the
//! four columns advance together a chunk at a time.
//!
//! The member's CRC-32 is still checked, as the crate checks it: over the bytes actually
//! produced, when the member ends. A member that is shorter or longer than its declared size,
//! or whose checksum differs, is an I/O error at its end (the NPY reader above reads to the end
//! of every member, to find trailing data, so no member goes unchecked).

use std::io::{self, Read, Seek, SeekFrom};
use std::sync::{Arc, Mutex};

use zip::CompressionMethod;

/// The archive's source, shared by the members read from it: the reader and its position
/// (kept so that consecutive reads of one member do not seek). A mutex, never contended (the
/// members are read in turn), because readers are sent to other threads.
pub(crate) type Shared<R> = Arc<Mutex<(R, u64)>>;

/// Where a member's data lies and what it must decode to, from the archive's directory.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Entry {
    /// Offset of the first data byte in the archive.
    pub start: u64,
    /// Bytes of stored or compressed data.
    pub compressed: u64,
    /// Bytes once decompressed (the NPY file).
    pub size: u64,
    /// The CRC-32 of those bytes.
    pub crc: u32,
    /// Whether the data are deflated (else stored).
    pub deflated: bool,
}

impl Entry {
    /// The directory entry of the member `name` (`Err`: the crate's reason it cannot be read).
    pub(crate) fn of<R: Read + Seek>(
        archive: &mut zip::ZipArchive<R>,
        name: &str,
    ) -> Result<Self, zip::result::ZipError> {
        // `by_name` parses the local header (to find the data) and refuses what the crate
        // cannot read: encryption, and compression methods other than the ones compiled in.
        let file = archive.by_name(name)?;
        let deflated = match file.compression() {
            CompressionMethod::Stored => false,
            CompressionMethod::Deflated => true,
            // Unreachable with the crate's features (it refuses the methods it lacks), but
            // a new method must not be read as stored bytes.
            _ => {
                return Err(zip::result::ZipError::UnsupportedArchive(
                    "compression method other than stored or deflated",
                ));
            }
        };
        Ok(Self {
            start: file.data_start(),
            compressed: file.compressed_size(),
            size: file.size(),
            crc: file.crc32(),
            deflated,
        })
    }
}

/// The raw (stored or compressed) bytes of one member, read at its own position.
struct Raw<R> {
    source: Shared<R>,
    pos: u64,
    end: u64,
}

impl<R: Read + Seek> Read for Raw<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let want = buf
            .len()
            .min(usize::try_from(self.end - self.pos).unwrap_or(usize::MAX));
        if want == 0 {
            return Ok(0);
        }
        let mut shared = match self.source.lock() {
            Ok(shared) => shared,
            // A panic while the lock was held left the position unknown: seek again.
            Err(poisoned) => {
                let mut shared = poisoned.into_inner();
                shared.1 = u64::MAX;
                shared
            }
        };
        let (source, at) = &mut *shared;
        if *at != self.pos {
            source.seek(SeekFrom::Start(self.pos))?;
            *at = self.pos;
        }
        let n = loop {
            match source.read(&mut buf[..want]) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                other => break other?,
            }
        };
        if n == 0 {
            return Err(io::Error::new(
                io::ErrorKind::UnexpectedEof,
                format!(
                    "the archive ends at byte {}, inside the member's data (which run to byte {})",
                    self.pos, self.end
                ),
            ));
        }
        self.pos += n as u64;
        *at = self.pos;
        Ok(n)
    }
}

/// The stored or deflated data of a member.
enum Body<R> {
    Stored(Raw<R>),
    Deflated(Box<flate2::read::DeflateDecoder<Raw<R>>>),
}

/// One member's decompressed bytes (the NPY file it holds), checked against its declared size
/// and CRC-32 when it ends.
pub(crate) struct Member<R> {
    body: Body<R>,
    entry: Entry,
    crc: crc32fast::Hasher,
    /// Bytes produced so far.
    produced: u64,
}

impl<R> std::fmt::Debug for Member<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Member")
            .field("entry", &self.entry)
            .field("produced", &self.produced)
            .finish_non_exhaustive()
    }
}

impl<R: Read + Seek> Member<R> {
    /// The member at `entry` of the archive in `source`.
    pub(crate) fn new(source: Shared<R>, entry: Entry) -> Self {
        let raw = Raw {
            source,
            pos: entry.start,
            end: entry.start.saturating_add(entry.compressed),
        };
        let body = if entry.deflated {
            Body::Deflated(Box::new(flate2::read::DeflateDecoder::new(raw)))
        } else {
            Body::Stored(raw)
        };
        Self {
            body,
            entry,
            crc: crc32fast::Hasher::new(),
            produced: 0,
        }
    }

    /// The member's declared decompressed size.
    pub(crate) fn size(&self) -> u64 {
        self.entry.size
    }

    /// Checks the member at its end: every declared byte produced, and the checksum.
    fn finish(&self) -> io::Result<()> {
        if self.produced != self.entry.size {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "the member's data end after {} bytes, but the archive declares {}",
                    self.produced, self.entry.size
                ),
            ));
        }
        let crc = self.crc.clone().finalize();
        if crc != self.entry.crc {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "the member's CRC-32 is {crc:08x} but the archive records {:08x}: the \
                     archive is damaged",
                    self.entry.crc
                ),
            ));
        }
        Ok(())
    }
}

impl<R: Read + Seek> Read for Member<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        let n = match &mut self.body {
            Body::Stored(raw) => raw.read(buf)?,
            Body::Deflated(d) => d.read(buf)?,
        };
        if n == 0 {
            self.finish()?;
            return Ok(0);
        }
        self.produced += n as u64;
        if self.produced > self.entry.size {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "the member's data run past the {} bytes the archive declares",
                    self.entry.size
                ),
            ));
        }
        self.crc.update(&buf[..n]);
        Ok(n)
    }
}
