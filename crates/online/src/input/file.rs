//! A recording on disk, streamed in the chunks its reader decodes (`evtac_formats::open`).

use super::{ChunkInfo, EventSource, InputError, Next};
use crate::Notice;
use evtac_events::{Event, Resolution};
use evtac_formats::EventReader;
use evtac_formats::StreamSelection;
use std::path::Path;

/// Streams the events of an AEDAT 4.0/3.1/2.0, EVT 2.0/2.1/3.0, CSV or NPY file (IMU samples and
/// triggers are skipped).
#[derive(Debug)]
pub struct FileSource {
    reader: EventReader,
    name: String,
}

impl FileSource {
    /// Opens `path` (the streams `streams` picks of an AEDAT4 file with several); `sensor`
    /// declares the sensor size for formats that do not store it (CSV, NPY) and must match the
    /// file's own otherwise.
    pub fn open(
        path: &Path,
        sensor: Option<Resolution>,
        streams: &StreamSelection,
    ) -> Result<Self, InputError> {
        let name = path.display().to_string();
        let events = |source| InputError::Events {
            input: name.clone(),
            source,
        };
        let mut reader = evtac_formats::open_with(path, streams).map_err(events)?;
        if let Some(sensor) = sensor {
            reader.set_resolution(sensor).map_err(events)?;
        }
        Ok(Self { reader, name })
    }

    /// The sensor size: the file's own, or the one declared.
    pub fn resolution(&self) -> Option<Resolution> {
        self.reader.resolution()
    }
}

impl EventSource for FileSource {
    fn next_chunk(&mut self, out: &mut Vec<Event>, _notify: &mut dyn FnMut(Notice)) -> Next {
        out.clear();
        let chunk = self
            .reader
            .next_chunk()
            .map_err(|source| InputError::Events {
                input: self.name.clone(),
                source,
            })?;
        Ok(chunk.map(|c| {
            out.extend_from_slice(c.events);
            ChunkInfo::default()
        }))
    }
}
