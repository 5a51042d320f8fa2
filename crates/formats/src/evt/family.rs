//! Prophesee EVT 2.0, 2.1 and 3.0 behind the format traits: recognised by their `%` text
//! header, whose `evt` line gives the version, read only.

use std::fs::File;
use std::path::Path;

use crate::evt::{EvtError, EvtReader, EvtVersion};
use crate::family::{Decode, Extension, Family, Named, Open, Opened};
use crate::{Chunk, Error, Format, Resolution};

/// The EVT family.
pub(crate) struct Evt;

impl Family for Evt {
    fn formats(&self) -> &'static [Format] {
        &[Format::Evt2, Format::Evt21, Format::Evt3]
    }

    fn extensions(&self) -> &'static [Extension] {
        &[Extension {
            extension: "raw",
            format: Format::Evt3,
            signature: Some("a `%` EVT text header line"),
        }]
    }

    fn sniff(&self, path: &Path, head: &[u8]) -> Option<Result<Format, Error>> {
        if !head.starts_with(b"%") {
            return None;
        }
        // The version needs the whole header, which the EVT reader parses.
        let opened = File::open(path)
            .map_err(|error| Error::Io {
                path: path.to_path_buf(),
                error,
            })
            .and_then(|file| EvtReader::new(file).map_err(evt_error(path)));
        Some(opened.map(|r| match r.header().version {
            EvtVersion::Evt2 => Format::Evt2,
            EvtVersion::Evt21 => Format::Evt21,
            EvtVersion::Evt3 => Format::Evt3,
        }))
    }

    fn open(&self, at: &Open<'_>) -> Result<Opened, Error> {
        let Open { path, .. } = *at;
        let r = EvtReader::from_path(path).map_err(evt_error(path))?;
        Ok(Opened {
            source: r.header().source(),
            ..Opened::plain(Named {
                path: path.to_path_buf(),
                inner: r,
                wrap: |path, error| Error::Evt { path, error },
            })
        })
    }
}

fn evt_error(path: &Path) -> impl Fn(EvtError) -> Error + '_ {
    |error| Error::Evt {
        path: path.to_path_buf(),
        error,
    }
}

impl Decode for EvtReader<File> {
    type Error = EvtError;

    fn decode(&mut self) -> Result<Option<Chunk<'_>>, EvtError> {
        Ok(self.next_chunk()?.map(|c| Chunk {
            events: c.events,
            imu: &[],
            triggers: c.triggers,
        }))
    }

    crate::family::decode_by_inherent_methods!();
}
