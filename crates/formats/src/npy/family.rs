//! NPY and NPZ behind the format traits: NPY recognised by its magic (read and written), NPZ by
//! a zip archive named `.npz` (read only; a zip may hold anything else).

use std::fs::File;
use std::path::{Path, PathBuf};

use crate::family::{
    Create, Decode, Extension, Family, FormatReader, FormatWriter, Named, Open, Opened, Sunk,
};
use crate::npy::npz::{NpzError, NpzReader};
use crate::npy::{MAGIC, NpyError, NpyReader, NpyWriter};
use crate::{Chunk, Error, Event, Format, Resolution};

/// The NPY family, with numpy's zip of NPY arrays.
pub(crate) struct Npy;

impl Family for Npy {
    fn formats(&self) -> &'static [Format] {
        &[Format::Npy, Format::Npz]
    }

    fn extensions(&self) -> &'static [Extension] {
        &[
            Extension {
                extension: "npy",
                format: Format::Npy,
                signature: Some("the NPY magic `\\x93NUMPY`"),
            },
            Extension {
                extension: "npz",
                format: Format::Npz,
                signature: Some("the zip magic `PK\\x03\\x04`"),
            },
        ]
    }

    fn sniff(&self, path: &Path, head: &[u8]) -> Option<Result<Format, Error>> {
        if head.starts_with(MAGIC) {
            return Some(Ok(Format::Npy));
        }
        let zip = head.starts_with(b"PK\x03\x04") || head.starts_with(b"PK\x05\x06");
        (zip && crate::family::extension(path) == "npz").then_some(Ok(Format::Npz))
    }

    fn open(&self, at: &Open<'_>) -> Result<Opened, Error> {
        let Open {
            path, format, len, ..
        } = *at;
        let path_buf = path.to_path_buf();
        if format == Format::Npz {
            let r = NpzReader::from_path(path).map_err(|error| Error::Npz {
                path: path_buf.clone(),
                error: Box::new(error),
            })?;
            return Ok(Opened {
                note: Some(r.note()),
                ..Opened::plain(NpzSource {
                    path: path_buf,
                    inner: r,
                    len,
                })
            });
        }
        let r = NpyReader::from_path(path).map_err(npy_error(path))?;
        Ok(Opened::plain(Named {
            path: path_buf,
            inner: r,
            wrap: |path, error| Error::Npy { path, error },
        }))
    }

    fn writes(&self, format: Format) -> bool {
        format == Format::Npy
    }

    fn create(&self, to: Create<'_>) -> Option<Result<Box<dyn FormatWriter>, Error>> {
        let Create {
            path, format, file, ..
        } = to;
        (format == Format::Npy).then(|| {
            NpyWriter::new(file)
                .map(|inner| {
                    Box::new(Writer {
                        path: path.to_path_buf(),
                        inner,
                    }) as Box<dyn FormatWriter>
                })
                .map_err(npy_error(path))
        })
    }
}

fn npy_error(path: &Path) -> impl Fn(NpyError) -> Error + '_ {
    |error| Error::Npy {
        path: path.to_path_buf(),
        error,
    }
}

impl Decode for NpyReader<File> {
    type Error = NpyError;

    fn decode(&mut self) -> Result<Option<Chunk<'_>>, NpyError> {
        Ok(self.next_chunk()?.map(Chunk::of_events))
    }

    crate::family::decode_by_inherent_methods!();
}

struct NpzSource {
    path: PathBuf,
    inner: NpzReader<File>,
    /// The archive's size, which progress is scaled to (members are inflated, so bytes read
    /// say little).
    len: u64,
}

impl FormatReader for NpzSource {
    fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error> {
        let path = &self.path;
        let chunk = self.inner.next_chunk().map_err(|error| match error {
            // A check failure reads as it does for every other format.
            NpzError::Event(error) => Error::Event {
                path: path.clone(),
                error,
            },
            error => Error::Npz {
                path: path.clone(),
                error: Box::new(error),
            },
        })?;
        Ok(chunk.map(Chunk::of_events))
    }

    fn resolution(&self) -> Option<Resolution> {
        self.inner.resolution()
    }

    fn set_resolution(&mut self, resolution: Resolution) -> Result<(), Error> {
        self.inner.set_resolution(resolution);
        Ok(())
    }

    fn position(&self) -> u64 {
        (self.len as f64 * self.inner.progress()) as u64
    }
}

/// An NPY event file being written (events only).
struct Writer {
    path: PathBuf,
    inner: NpyWriter<Sunk>,
}

impl FormatWriter for Writer {
    fn write_events(&mut self, events: &[Event]) -> Result<(), Error> {
        self.inner
            .write_events(events)
            .map_err(npy_error(&self.path))
    }

    fn finish(self: Box<Self>) -> Result<Sunk, Error> {
        let path = self.path;
        self.inner.finish().map_err(npy_error(&path))
    }
}
