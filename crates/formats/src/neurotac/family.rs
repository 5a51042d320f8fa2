//! The NeuroTac lab's pickles behind the format traits: recognised by a pickle's opening (or an
//! NPY array of Python objects), read whole, since a pickle must be parsed whole, and handed
//! out in chunks like the streaming readers'.

use std::path::{Path, PathBuf};

use crate::check::{CheckError, EventCheck};
use crate::family::{Extension, Family, FormatReader, Open, Opened};
use crate::{Chunk, Error, Event, Format, ImuSample, Resolution, Trigger};

/// The NeuroTac family.
pub(crate) struct Neurotac;

impl Family for Neurotac {
    fn formats(&self) -> &'static [Format] {
        &[Format::Neurotac]
    }

    fn extensions(&self) -> &'static [Extension] {
        &[
            Extension {
                extension: "pickle",
                format: Format::Neurotac,
                signature: None,
            },
            Extension {
                extension: "pkl",
                format: Format::Neurotac,
                signature: None,
            },
        ]
    }

    /// Before NPY: an NPY array of Python objects is a NeuroTac file, not an event array.
    fn sniff(&self, _path: &Path, head: &[u8]) -> Option<Result<Format, Error>> {
        crate::neurotac::sniff(head).then_some(Ok(Format::Neurotac))
    }

    fn open(&self, at: &Open<'_>) -> Result<Opened, Error> {
        let Open { path, len, .. } = *at;
        let file = crate::neurotac::read_pair(path).map_err(|error| Error::Neurotac {
            path: path.to_path_buf(),
            error: Box::new(error),
        })?;
        Ok(Opened {
            note: Some(file.note()),
            ..Opened::plain(MemoryEvents::new(
                path.to_path_buf(),
                file.events,
                Some(file.resolution),
                len,
            ))
        })
    }
}

/// A recording read whole, handed out in chunks like the streaming readers'.
struct MemoryEvents {
    path: PathBuf,
    events: Vec<Event>,
    /// IMU samples, in time order.
    imu: Vec<ImuSample>,
    /// Triggers, in time order.
    triggers: Vec<Trigger>,
    /// The next event, IMU sample and trigger to hand out.
    next: usize,
    next_imu: usize,
    next_trigger: usize,
    /// Checks events against the file's sensor size (or a declared one).
    check: EventCheck,
    /// Bytes of the files, for positions: all read at once.
    len: u64,
}

impl MemoryEvents {
    /// Events per chunk, as the file readers hand them out.
    const CHUNK: usize = 1 << 16;

    fn new(path: PathBuf, events: Vec<Event>, resolution: Option<Resolution>, len: u64) -> Self {
        Self {
            path,
            events,
            imu: Vec::new(),
            triggers: Vec::new(),
            next: 0,
            next_imu: 0,
            next_trigger: 0,
            check: EventCheck::new(resolution),
            len,
        }
    }

    /// The next chunk: up to [`Self::CHUNK`] events, with the IMU samples and triggers up to
    /// the last of them (all that remain with the last events), so that a range read, which
    /// stops at the first chunk whose events pass the range's end, misses none.
    fn next_checked(&mut self) -> Result<Option<Chunk<'_>>, CheckError> {
        let done = self.next >= self.events.len();
        if done && self.next_imu >= self.imu.len() && self.next_trigger >= self.triggers.len() {
            return Ok(None);
        }
        let end = (self.next + Self::CHUNK).min(self.events.len());
        let events = &self.events[self.next..end];
        self.check.check(events)?;
        self.next = end;
        let upto = match events.last() {
            Some(last) if end < self.events.len() => last.t,
            _ => i64::MAX,
        };
        let imu_end = self.next_imu + self.imu[self.next_imu..].partition_point(|s| s.t <= upto);
        let trigger_end =
            self.next_trigger + self.triggers[self.next_trigger..].partition_point(|t| t.t <= upto);
        let chunk = Chunk {
            events,
            imu: &self.imu[self.next_imu..imu_end],
            triggers: &self.triggers[self.next_trigger..trigger_end],
        };
        self.next_imu = imu_end;
        self.next_trigger = trigger_end;
        Ok(Some(chunk))
    }
}

impl FormatReader for MemoryEvents {
    fn next_chunk(&mut self) -> Result<Option<Chunk<'_>>, Error> {
        let path = self.path.clone();
        self.next_checked()
            .map_err(|error| Error::Event { path, error })
    }

    fn resolution(&self) -> Option<Resolution> {
        self.check.resolution()
    }

    fn set_resolution(&mut self, resolution: Resolution) -> Result<(), Error> {
        self.check.set_resolution(Some(resolution));
        Ok(())
    }

    fn position(&self) -> u64 {
        if self.next > 0 { self.len } else { 0 }
    }
}
