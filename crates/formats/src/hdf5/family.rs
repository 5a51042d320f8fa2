//! HDF5 behind the format traits: recognised by the HDF5 signature, one dataset per event field,
//! read only; a time range found through `ms_to_idx` where the file has it.

use std::path::{Path, PathBuf};

use crate::family::{Extension, Family, FormatReader, Open, Opened, Ranged};
use crate::hdf5::{Hdf5Error, Hdf5Reader};
use crate::{Chunk, Error, Format, RangeIndex, Resolution, ScanReason};

/// The HDF5 family.
pub(crate) struct Hdf5;

const SIGNATURE: Option<&str> = Some("the HDF5 signature `\\x89HDF\\r\\n\\x1a\\n`");

impl Family for Hdf5 {
    fn formats(&self) -> &'static [Format] {
        &[Format::Hdf5]
    }

    fn extensions(&self) -> &'static [Extension] {
        &[
            Extension {
                extension: "h5",
                format: Format::Hdf5,
                signature: SIGNATURE,
            },
            Extension {
                extension: "hdf5",
                format: Format::Hdf5,
                signature: SIGNATURE,
            },
        ]
    }

    fn sniff(&self, _path: &Path, head: &[u8]) -> Option<Result<Format, Error>> {
        head.starts_with(b"\x89HDF\r\n\x1a\n")
            .then_some(Ok(Format::Hdf5))
    }

    fn open(&self, at: &Open<'_>) -> Result<Opened, Error> {
        let Open { path, len, .. } = *at;
        let r = Hdf5Reader::open(path).map_err(hdf5_error(path))?;
        Ok(Opened {
            note: Some(r.note()),
            ..Opened::plain(Reader {
                path: path.to_path_buf(),
                inner: r,
                len,
            })
        })
    }
}

fn hdf5_error(path: &Path) -> impl Fn(Hdf5Error) -> Error + '_ {
    |error| Error::Hdf5 {
        path: path.to_path_buf(),
        error: Box::new(error),
    }
}

struct Reader {
    path: PathBuf,
    inner: Hdf5Reader,
    /// The file's size, which progress is scaled to (elements are counted, not bytes: chunks
    /// and filters hide the bytes).
    len: u64,
}

impl FormatReader for Reader {
    fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error> {
        let chunk = self.inner.next_chunk().map_err(hdf5_error(&self.path))?;
        Ok(chunk.map(Chunk::of_events))
    }

    fn resolution(&self) -> Option<Resolution> {
        self.inner.resolution()
    }

    /// A size the file states is checked by the caller; a file without one may still rule a
    /// size out (its `sensor_resolution` attribute aside, see [`Hdf5Reader::accepts`]).
    fn set_resolution(&mut self, resolution: Resolution) -> Result<(), Error> {
        if !self.inner.accepts(resolution)
            && let Some(found) = self.inner.resolution()
        {
            return Err(Error::ResolutionMismatch {
                path: self.path.clone(),
                declared: resolution,
                found,
            });
        }
        self.inner.set_resolution(resolution);
        Ok(())
    }

    fn position(&self) -> u64 {
        (self.len as f64 * self.inner.position() as f64 / self.inner.len().max(1) as f64) as u64
    }

    fn select_range(&mut self, from: i64, to: i64) -> Result<Ranged, Error> {
        let index = self
            .inner
            .select_range(from, to)
            .map_err(hdf5_error(&self.path))?;
        Ok(Ranged::Narrowed(index.unwrap_or(RangeIndex::Scan(
            ScanReason::NotIndexed {
                format: "HDF5 (without ms_to_idx)",
            },
        ))))
    }
}
