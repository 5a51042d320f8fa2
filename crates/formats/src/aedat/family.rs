//! AEDAT 4.0 behind the format traits: the file's streams chosen by a [`StreamSelection`], its
//! events checked against the event stream's size, a time range read through the data table,
//! and LZ4-compressed files written with a data table.

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use crate::aedat::{AedatError, AedatReader, AedatWriter, MAGIC, WriterConfig};
use crate::check::EventCheck;
use crate::family::{
    Create, Extension, Family, FormatReader, FormatWriter, Open, Opened, Ranged, Sunk,
};
use crate::{Chunk, Error, Event, Format, ImuSample, Resolution, Trigger};

/// The AEDAT 4.0 family.
pub(crate) struct Aedat4;

const SIGNATURE: Option<&str> = Some("the AEDAT 4.0 magic `#!AER-DAT4.0\\r\\n`");

impl Family for Aedat4 {
    fn formats(&self) -> &'static [Format] {
        &[Format::Aedat4]
    }

    fn extensions(&self) -> &'static [Extension] {
        &[
            Extension {
                extension: "aedat4",
                format: Format::Aedat4,
                signature: SIGNATURE,
            },
            // AEDAT 3.1 and 2.0 files are `.aedat` too, but recognised by their headers; an
            // `.aedat` output is written as AEDAT 4.0, as DV does.
            Extension {
                extension: "aedat",
                format: Format::Aedat4,
                signature: SIGNATURE,
            },
        ]
    }

    fn sniff(&self, _path: &Path, head: &[u8]) -> Option<Result<Format, Error>> {
        head.starts_with(MAGIC).then_some(Ok(Format::Aedat4))
    }

    fn has_streams(&self) -> bool {
        true
    }

    fn open(&self, at: &Open<'_>) -> Result<Opened, Error> {
        let Open {
            path, selection, ..
        } = *at;
        let error = aedat_error(path);
        let mut r = AedatReader::open(path).map_err(error)?;
        let chosen = selection
            .resolve(r.header())
            .map_err(|error| Error::Streams {
                path: path.to_path_buf(),
                error,
            })?;
        r.select_streams(&chosen);
        let header = r.header();
        let event_stream = chosen.events.and_then(|id| header.stream(id));
        let source = match event_stream {
            Some(s) => s.source.clone(),
            None => r.source().map(str::to_string),
        };
        // The event stream's size, which the events are checked against.
        let resolution = event_stream.and_then(|s| s.resolution);
        Ok(Opened {
            source,
            ..Opened::plain(Reader {
                path: path.to_path_buf(),
                inner: r,
                check: EventCheck::new(resolution),
            })
        })
    }

    fn writes(&self, format: Format) -> bool {
        format == Format::Aedat4
    }

    fn create(&self, to: Create<'_>) -> Option<Result<Box<dyn FormatWriter>, Error>> {
        let Create {
            path,
            file,
            resolution,
            source_name,
            ..
        } = to;
        let Some(resolution) = resolution else {
            return Some(Err(Error::MissingResolution {
                path: path.to_path_buf(),
            }));
        };
        let config = WriterConfig::new(resolution, source_name.unwrap_or("evtac"));
        Some(
            AedatWriter::new_seekable(file, config)
                .map(|inner| {
                    Box::new(Writer {
                        path: path.to_path_buf(),
                        inner,
                    }) as Box<dyn FormatWriter>
                })
                .map_err(aedat_error(path)),
        )
    }
}

fn aedat_error(path: &Path) -> impl Fn(AedatError) -> Error + '_ {
    |error| Error::Aedat {
        path: path.to_path_buf(),
        error,
    }
}

/// An AEDAT4 file being read. The AEDAT4 reader does not check events itself (its packets are
/// decoded stream by stream), so the check is here.
struct Reader {
    path: PathBuf,
    inner: AedatReader<BufReader<File>>,
    check: EventCheck,
}

impl FormatReader for Reader {
    fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error> {
        let chunk = self.inner.next_chunk().map_err(aedat_error(&self.path))?;
        let Some(chunk) = chunk else { return Ok(None) };
        self.check
            .check(chunk.events)
            .map_err(|error| Error::Event {
                path: self.path.clone(),
                error,
            })?;
        Ok(Some(Chunk {
            events: chunk.events,
            imu: chunk.imu,
            triggers: chunk.triggers,
        }))
    }

    fn resolution(&self) -> Option<Resolution> {
        self.check.resolution()
    }

    fn set_resolution(&mut self, resolution: Resolution) -> Result<(), Error> {
        self.check.set_resolution(Some(resolution));
        Ok(())
    }

    fn position(&self) -> u64 {
        self.inner.offset()
    }

    fn select_range(&mut self, from: i64, to: i64) -> Result<Ranged, Error> {
        // The range starts a new stream of events: time may start below the last one seen.
        self.check = EventCheck::new(self.check.resolution());
        self.inner
            .select_range(from, to)
            .map(Ranged::Exact)
            .map_err(aedat_error(&self.path))
    }

    fn triggers_only(&mut self) {
        self.inner.triggers_only();
    }

    fn imu_only(&mut self) {
        self.inner.imu_only();
    }
}

/// An AEDAT4 file being written: events, IMU samples and triggers.
struct Writer {
    path: PathBuf,
    inner: AedatWriter<Sunk>,
}

impl FormatWriter for Writer {
    fn write_events(&mut self, events: &[Event]) -> Result<(), Error> {
        self.inner
            .write_events(events)
            .map_err(aedat_error(&self.path))
    }

    fn stores_imu_and_triggers(&self) -> bool {
        true
    }

    fn write_imu(&mut self, samples: &[ImuSample]) -> Result<(), Error> {
        self.inner
            .write_imu(samples)
            .map_err(aedat_error(&self.path))
    }

    fn write_triggers(&mut self, triggers: &[Trigger]) -> Result<(), Error> {
        self.inner
            .write_triggers(triggers)
            .map_err(aedat_error(&self.path))
    }

    fn finish(self: Box<Self>) -> Result<Sunk, Error> {
        let path = self.path;
        self.inner.finish().map_err(aedat_error(&path))
    }
}
