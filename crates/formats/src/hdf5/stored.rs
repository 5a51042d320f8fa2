//! The file's bytes, for reading a contiguous dataset's window straight into a reused buffer.
//!
//! `hdf5-pure`'s row-window read returns a fresh `Vec` per window, so every slice of every
//! column paid for new pages (the kernel clearing them) besides the copy from the file. A
//! contiguous, unfiltered dataset is one run of bytes at an address the layout message gives;
//! its windows are read here, at that address, into the caller's buffer, as h5py reads them
//! into a numpy array. Chunked (and so every compressed) dataset is still read by `hdf5-pure`,
//! which knows its chunk index and filters.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::sync::Arc;

/// Where the file's bytes are: open on disk, or held in memory.
#[derive(Debug)]
pub(super) enum FileBytes {
    /// A file on disk, read with a seek and a read per window.
    Disk(File),
    /// A file held in memory (shared with `hdf5-pure`'s reader).
    Memory(Shared),
}

impl FileBytes {
    /// Fills `out` with the bytes at `offset`; the caller checked that they lie inside the file.
    pub(super) fn read_at(&mut self, offset: u64, out: &mut [u8]) -> std::io::Result<()> {
        match self {
            Self::Disk(file) => {
                file.seek(SeekFrom::Start(offset))?;
                file.read_exact(out)
            }
            Self::Memory(Shared(bytes)) => {
                let window = usize::try_from(offset)
                    .ok()
                    .and_then(|start| bytes.get(start..start.checked_add(out.len())?))
                    .ok_or_else(|| {
                        std::io::Error::new(
                            std::io::ErrorKind::UnexpectedEof,
                            format!("bytes {offset}.. lie past the end of the file"),
                        )
                    })?;
                out.copy_from_slice(window);
                Ok(())
            }
        }
    }
}

/// A file's bytes in memory, shared between `hdf5-pure`'s reader (through a `Cursor`) and the
/// direct reads.
#[derive(Debug, Clone)]
pub(super) struct Shared(pub(super) Arc<[u8]>);

impl AsRef<[u8]> for Shared {
    fn as_ref(&self) -> &[u8] {
        &self.0
    }
}
