//! AEDAT 3.1 and 2.0 behind the format traits: recognised by their `#!AER-DAT` header line
//! (another version is an error naming it), read only.

use std::fs::File;
use std::path::Path;

use crate::aedat_legacy::{self, LegacyError, LegacyReader, Version};
use crate::family::{Decode, Extension, Family, Named, Open, Opened};
use crate::{Chunk, Error, Format, Resolution};

/// The AEDAT 3.1 / 2.0 family.
pub(crate) struct Legacy;

impl Family for Legacy {
    fn formats(&self) -> &'static [Format] {
        &[Format::Aedat2, Format::Aedat31]
    }

    /// None of its own: `.aedat` files are AEDAT 4.0's (see `aedat/family.rs`) until their
    /// header says otherwise.
    fn extensions(&self) -> &'static [Extension] {
        &[]
    }

    fn sniff(&self, path: &Path, head: &[u8]) -> Option<Result<Format, Error>> {
        aedat_legacy::sniff(head).map(|version| match version {
            Ok(Version::Aedat2) => Ok(Format::Aedat2),
            Ok(Version::Aedat31) => Ok(Format::Aedat31),
            Err(version) => Err(Error::AedatLegacy {
                path: path.to_path_buf(),
                error: LegacyError::UnsupportedVersion { version },
            }),
        })
    }

    fn open(&self, at: &Open<'_>) -> Result<Opened, Error> {
        let Open { path, .. } = *at;
        let wrap = |path, error| Error::AedatLegacy { path, error };
        let r = LegacyReader::from_path(path).map_err(|e| wrap(path.to_path_buf(), e))?;
        Ok(Opened {
            source: r.header().camera.clone(),
            ..Opened::plain(Named {
                path: path.to_path_buf(),
                inner: r,
                wrap,
            })
        })
    }
}

impl Decode for LegacyReader<File> {
    type Error = LegacyError;

    fn decode(&mut self) -> Result<Option<Chunk<'_>>, LegacyError> {
        Ok(self.next_chunk()?.map(|c| Chunk {
            events: c.events,
            imu: c.imu,
            triggers: c.triggers,
        }))
    }

    crate::family::decode_by_inherent_methods!();

    /// AEDAT 2.0 holds only events. AEDAT 3.1 stores one packet per event type: cAER writes
    /// the polarity, IMU and special packets of a *packet container* one after another, each
    /// spanning the container's interval (libcaer's `PacketContainerInterval`, 10 ms by
    /// default, at most a few hundred ms in any setup seen), so an IMU packet may follow a
    /// polarity packet that already ends past the range. One second covers that with a wide
    /// margin and costs one second of decoding per range read.
    fn lag_us(&self) -> i64 {
        match self.header().version {
            Version::Aedat31 => 1_000_000,
            Version::Aedat2 => 0,
        }
    }
}
