//! The whole-file API for writing: [`EventWriter`] writes events (and, for AEDAT4, IMU samples
//! and triggers) to a file whose extension picks the format, whole or not at all.

use std::path::{Path, PathBuf};

use evtac_events::output::OutputFile;

use crate::family::FormatWriter;
use crate::registry;
use crate::{Error, Event, Format, ImuSample, Resolution, Trigger};

/// Writes events (and, for AEDAT4, IMU samples and triggers) to a file whose extension picks the
/// format: `.aedat4`, `.csv` or `.npy`.
///
/// The file is written under a temporary name beside `path` and appears under `path` only when
/// [`finish`](Self::finish) succeeds ([`OutputFile`]); a writer dropped before, or a failed
/// finish, leaves no output (and an earlier file of that name untouched).
pub struct EventWriter {
    path: PathBuf,
    format: Format,
    sink: Box<dyn FormatWriter>,
}

impl std::fmt::Debug for EventWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EventWriter")
            .field("path", &self.path)
            .field("format", &self.format)
            .finish_non_exhaustive()
    }
}

impl EventWriter {
    /// Creates the file at `path`. AEDAT4 needs the sensor `resolution` and stores
    /// `source_name` (default `evtac`) with LZ4 compression; CSV and NPY store neither.
    pub fn create(
        path: impl AsRef<Path>,
        resolution: Option<Resolution>,
        source_name: Option<&str>,
    ) -> Result<Self, Error> {
        let path = path.as_ref().to_path_buf();
        let format = registry::for_writing(&path)?;
        let family = registry::family(format);
        // A family that refuses (AEDAT4 without a sensor size) drops the temporary file, which
        // removes it: nothing is written.
        let file = OutputFile::buffered(&path).map_err(|error| Error::Io {
            path: path.clone(),
            error,
        })?;
        let to = crate::family::Create {
            path: &path,
            format,
            file,
            resolution,
            source_name,
        };
        let sink = match family.create(to) {
            Some(sink) => sink?,
            None => return Err(Error::NotWritable { path, format }),
        };
        Ok(Self { path, format, sink })
    }

    /// The format being written.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Whether IMU samples are stored (AEDAT4 only).
    pub fn stores_imu(&self) -> bool {
        self.sink.stores_imu_and_triggers()
    }

    /// Whether triggers are stored (AEDAT4 only).
    pub fn stores_triggers(&self) -> bool {
        self.sink.stores_imu_and_triggers()
    }

    /// Appends events.
    pub fn write_events(&mut self, events: &[Event]) -> Result<(), Error> {
        self.sink.write_events(events)
    }

    /// Appends IMU samples when the format stores them ([`stores_imu`](Self::stores_imu));
    /// CSV and NPY event files have no place for them and ignore them.
    pub fn write_imu(&mut self, samples: &[ImuSample]) -> Result<(), Error> {
        self.sink.write_imu(samples)
    }

    /// Appends triggers when the format stores them ([`stores_triggers`](Self::stores_triggers));
    /// CSV and NPY event files have no place for them and ignore them.
    pub fn write_triggers(&mut self, triggers: &[Trigger]) -> Result<(), Error> {
        self.sink.write_triggers(triggers)
    }

    /// Finishes the file (buffered packets, data table, NPY record count), flushes it and
    /// renames it to its final name.
    pub fn finish(self) -> Result<(), Error> {
        let sunk = self.sink.finish()?;
        OutputFile::commit_buffered(sunk).map_err(|error| Error::Io {
            path: self.path,
            error,
        })
    }
}
