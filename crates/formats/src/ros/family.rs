//! ROS bags behind the format traits: ROS 1 `.bag` files (the `#ROSBAG V` line) and ROS 2 MCAP
//! (the MCAP magic, or a rosbag2 folder), their event and IMU topics chosen by a
//! [`StreamSelection`], read only.

use std::path::{Path, PathBuf};

use crate::family::{Extension, Family, FormatReader, Open, Opened};
use crate::ros::{BagEvents, MCAP_MAGIC};
use crate::{Chunk, Error, Format, Resolution};

/// The ROS bag family.
pub(crate) struct Ros;

impl Family for Ros {
    fn formats(&self) -> &'static [Format] {
        &[Format::RosBag, Format::Mcap]
    }

    fn extensions(&self) -> &'static [Extension] {
        &[
            Extension {
                extension: "bag",
                format: Format::RosBag,
                signature: Some("the ROS 1 bag line `#ROSBAG V2.0`"),
            },
            Extension {
                extension: "mcap",
                format: Format::Mcap,
                signature: Some("the MCAP magic `\\x89MCAP0\\r\\n`"),
            },
        ]
    }

    fn sniff(&self, _path: &Path, head: &[u8]) -> Option<Result<Format, Error>> {
        // Any `#ROSBAG V` line: the reader names a version other than 2.0.
        if head.starts_with(b"#ROSBAG V") {
            return Some(Ok(Format::RosBag));
        }
        head.starts_with(MCAP_MAGIC).then_some(Ok(Format::Mcap))
    }

    fn sniff_folder(&self, path: &Path) -> Option<Result<Format, Error>> {
        Some(crate::ros::detect_folder(path))
    }

    fn has_streams(&self) -> bool {
        true
    }

    /// A rosbag2 folder's size is its files'.
    fn len(&self, path: &Path) -> Result<u64, Error> {
        crate::ros::bag_len(path)
    }

    fn open(&self, at: &Open<'_>) -> Result<Opened, Error> {
        let Open {
            path,
            format,
            selection,
            len,
        } = *at;
        let bag = crate::ros::read(path, format, selection)?;
        Ok(Opened {
            reader: Box::new(Reader {
                path: path.to_path_buf(),
                inner: bag.events,
                len,
            }),
            source: None,
            note: Some(bag.note),
            topics: bag.topics,
        })
    }
}

struct Reader {
    path: PathBuf,
    inner: BagEvents,
    /// The bag's size, which progress is scaled to (messages are decoded from chunks already
    /// read, so bytes read say little).
    len: u64,
}

impl FormatReader for Reader {
    fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error> {
        let path = &self.path;
        self.inner.next_chunk().map_err(|error| Error::Ros {
            path: path.clone(),
            error: Box::new(error),
        })
    }

    fn resolution(&self) -> Option<Resolution> {
        self.inner.resolution()
    }

    /// A bag whose messages state a size was checked by the caller; one that states none takes
    /// this one.
    fn set_resolution(&mut self, resolution: Resolution) -> Result<(), Error> {
        self.inner.set_resolution(resolution);
        Ok(())
    }

    fn position(&self) -> u64 {
        (self.len as f64 * self.inner.progress()) as u64
    }
}
