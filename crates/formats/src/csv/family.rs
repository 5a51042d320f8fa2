//! `t,x,y,p` CSV behind the format traits: recognised by its `.csv` extension (text has no
//! signature), read and written.

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use crate::csv::{CsvError, CsvReader, CsvWriter};
use crate::family::{Create, Decode, Extension, Family, FormatWriter, Named, Open, Opened, Sunk};
use crate::{Chunk, Error, Event, Format, Resolution};

/// The CSV family.
pub(crate) struct Csv;

impl Family for Csv {
    fn formats(&self) -> &'static [Format] {
        &[Format::Csv]
    }

    fn extensions(&self) -> &'static [Extension] {
        &[Extension {
            extension: "csv",
            format: Format::Csv,
            signature: None,
        }]
    }

    /// By the extension alone, so it is tried after every format with a signature.
    fn sniff(&self, path: &Path, _head: &[u8]) -> Option<Result<Format, Error>> {
        (crate::family::extension(path) == "csv").then_some(Ok(Format::Csv))
    }

    fn open(&self, at: &Open<'_>) -> Result<Opened, Error> {
        let Open { path, .. } = *at;
        let r = CsvReader::from_path(path).map_err(csv_error(path))?;
        let note = r.headerless().then(|| {
            "no header line: the columns were read as t,x,y,p (microseconds, column, row, \
             polarity)"
                .to_string()
        });
        Ok(Opened {
            note,
            ..Opened::plain(Named {
                path: path.to_path_buf(),
                inner: r,
                wrap: |path, error| Error::Csv { path, error },
            })
        })
    }

    fn writes(&self, format: Format) -> bool {
        format == Format::Csv
    }

    fn create(&self, to: Create<'_>) -> Option<Result<Box<dyn FormatWriter>, Error>> {
        let Create { path, file, .. } = to;
        Some(
            CsvWriter::new(file)
                .map(|inner| {
                    Box::new(Writer {
                        path: path.to_path_buf(),
                        inner,
                    }) as Box<dyn FormatWriter>
                })
                .map_err(csv_error(path)),
        )
    }
}

fn csv_error(path: &Path) -> impl Fn(CsvError) -> Error + '_ {
    |error| Error::Csv {
        path: path.to_path_buf(),
        error,
    }
}

impl Decode for CsvReader<BufReader<File>> {
    type Error = CsvError;

    fn decode(&mut self) -> Result<Option<Chunk<'_>>, CsvError> {
        Ok(self.next_chunk()?.map(Chunk::of_events))
    }

    crate::family::decode_by_inherent_methods!();
}

/// A CSV event file being written (events only: a CSV event file has no place for IMU samples
/// or triggers).
struct Writer {
    path: PathBuf,
    inner: CsvWriter<Sunk>,
}

impl FormatWriter for Writer {
    fn write_events(&mut self, events: &[Event]) -> Result<(), Error> {
        self.inner
            .write_events(events)
            .map_err(csv_error(&self.path))
    }

    fn finish(self: Box<Self>) -> Result<Sunk, Error> {
        let path = self.path;
        self.inner.finish().map_err(csv_error(&path))
    }
}
