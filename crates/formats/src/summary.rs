//! What a recording holds, read in one streaming pass: format, sensor, event and IMU counts,
//! time spans, IMU rate, triggers, for AEDAT4 files every stream on its own, and for ROS bags
//! every topic. `evtac info`
//! prints it; `evtac check` compares its time spans with the motion windows of a dataset's
//! manifest.
//!
//! An AEDAT4 file is summarised stream by stream, every stream decoded; the top-level counts
//! are those of the streams a [`StreamSelection`] picks, so a two-camera file is never reported
//! as one camera. When it cannot pick (several cameras, none chosen) the top level is empty and
//! [`Summary::selection`] says why.

use std::path::Path;

use serde::Serialize;

use crate::StreamSelection;
use crate::aedat::AedatReader;
use crate::check::EventCheck;
use crate::{Error, EventReader, Format, Resolution};

/// One stream of an AEDAT4 file (`evtac info` lists them all).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StreamSummary {
    /// The stream id packets carry.
    pub id: i32,
    /// Its type identifier (`EVTS`, `IMUS`, `TRIG`, `FRME`, ...).
    #[serde(rename = "type")]
    pub type_identifier: String,
    /// Its output name (`events`, `imu`, ...), when the file gives one.
    pub name: Option<String>,
    /// The camera it comes from, when the file says.
    pub source: Option<String>,
    /// Sensor width (event streams).
    pub width: Option<u16>,
    /// Sensor height (event streams).
    pub height: Option<u16>,
    /// Elements decoded (events, IMU samples or triggers; 0 for undecoded kinds).
    pub count: u64,
    /// ON events (event streams).
    pub on_events: u64,
    /// First element's timestamp (us).
    pub first_t_us: Option<i64>,
    /// Last element's timestamp (us).
    pub last_t_us: Option<i64>,
}

/// A recording's summary (also `evtac info --json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Format name (`AEDAT4`, `AEDAT3.1`, `AEDAT2`, `EVT2`, `EVT21`, `EVT3`, `CSV`, `NPY`).
    pub format: String,
    /// Camera the file names, if any.
    pub source: Option<String>,
    /// Sensor width, if the file states it.
    pub width: Option<u16>,
    /// Sensor height, if the file states it.
    pub height: Option<u16>,
    /// Number of events.
    pub events: u64,
    /// Number of ON (positive) events.
    pub on_events: u64,
    /// First event timestamp (us).
    pub first_t_us: Option<i64>,
    /// Last event timestamp (us).
    pub last_t_us: Option<i64>,
    /// Number of IMU samples.
    pub imu_samples: u64,
    /// Mean IMU rate over the IMU time span (Hz).
    pub imu_rate_hz: Option<f64>,
    /// First IMU timestamp (us).
    pub first_imu_t_us: Option<i64>,
    /// Last IMU timestamp (us).
    pub last_imu_t_us: Option<i64>,
    /// Number of triggers.
    pub triggers: u64,
    /// Every stream of an AEDAT4 file (empty for the other formats, which hold one of each).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub streams: Vec<StreamSummary>,
    /// Every topic of a ROS bag, with its message type and count (empty for the other
    /// formats).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub topics: Vec<crate::ros::TopicInfo>,
    /// Why the top-level counts are empty although the file has streams: several cameras (or
    /// event topics) and none chosen (the streams' own rows still count everything).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub selection: Option<String>,
    /// What the counts do not say about the file (a NeuroTac pickle's index order, missing
    /// polarity and millisecond times).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl Summary {
    /// The summary of a `format` file with nothing read yet: no counts, times, streams or notes.
    fn empty(format: Format) -> Self {
        Summary {
            format: format.name().to_string(),
            source: None,
            width: None,
            height: None,
            events: 0,
            on_events: 0,
            first_t_us: None,
            last_t_us: None,
            imu_samples: 0,
            imu_rate_hz: None,
            first_imu_t_us: None,
            last_imu_t_us: None,
            triggers: 0,
            streams: Vec::new(),
            topics: Vec::new(),
            selection: None,
            note: None,
        }
    }

    /// Reads the rest of `reader` chunk by chunk (bounded memory) and summarises it;
    /// `on_position` sees the reader's byte position after each chunk (for a progress bar).
    pub fn read(reader: &mut EventReader, mut on_position: impl FnMut(u64)) -> Result<Self, Error> {
        let mut s = Summary {
            source: reader.source().map(str::to_string),
            width: reader.resolution().map(|r| r.width),
            height: reader.resolution().map(|r| r.height),
            topics: reader.topics().to_vec(),
            note: reader.note().map(str::to_string),
            ..Summary::empty(reader.format())
        };
        while let Some(chunk) = reader.next_chunk()? {
            if let (Some(first), Some(last)) = (chunk.events.first(), chunk.events.last()) {
                s.first_t_us.get_or_insert(first.t);
                s.last_t_us = Some(last.t);
            }
            s.events += chunk.events.len() as u64;
            // A sum rather than `filter().count()`: branch-free, so the compiler vectorises it.
            s.on_events += chunk
                .events
                .iter()
                .map(|e| u64::from(e.polarity))
                .sum::<u64>();
            if let (Some(first), Some(last)) = (chunk.imu.first(), chunk.imu.last()) {
                s.first_imu_t_us.get_or_insert(first.t);
                s.last_imu_t_us = Some(last.t);
            }
            s.imu_samples += chunk.imu.len() as u64;
            s.triggers += chunk.triggers.len() as u64;
            on_position(reader.position());
        }
        s.set_imu_rate();
        Ok(s)
    }

    fn set_imu_rate(&mut self) {
        if let (Some(first), Some(last)) = (self.first_imu_t_us, self.last_imu_t_us)
            && last > first
        {
            // Samples per second over the span between the first and the last sample.
            self.imu_rate_hz = Some((self.imu_samples - 1) as f64 / ((last - first) as f64 * 1e-6));
        }
    }

    /// Opens the recording at `path` (any format evtac reads) and summarises it.
    pub fn of_file(path: impl AsRef<Path>) -> Result<Self, Error> {
        Self::of_file_with(path, &StreamSelection::default(), None, |_| {})
    }

    /// Summarises the recording at `path`, every stream of an AEDAT4 file on its own and the
    /// streams `selection` picks at the top level; `on_position` sees the byte position as the
    /// read goes. A declared `sensor` is checked against the size the file states (for AEDAT4,
    /// the chosen event stream's), and the events against it where the file states none. The
    /// file is recognised once and opened once.
    pub fn of_file_with(
        path: impl AsRef<Path>,
        selection: &StreamSelection,
        sensor: Option<Resolution>,
        on_position: impl FnMut(u64),
    ) -> Result<Self, Error> {
        let path = path.as_ref();
        let format = Format::detect(path)?;
        if format == Format::Aedat4 {
            return Self::of_aedat(path, selection, sensor, on_position);
        }
        match crate::reader::open_as(path, format, selection) {
            Ok(mut reader) => {
                if let Some(sensor) = sensor {
                    reader.set_resolution(sensor)?;
                }
                Self::read(&mut reader, on_position)
            }
            // A bag with several event topics and none chosen: the summary lists its topics
            // and says why it counts nothing (naming a topic it lacks stays an error).
            Err(Error::Streams { error, .. })
                if matches!(format, Format::RosBag | Format::Mcap)
                    && *selection == StreamSelection::default() =>
            {
                Ok(Self {
                    topics: crate::ros::topics(path)?,
                    selection: Some(error.reason),
                    ..Self::empty(format)
                })
            }
            Err(e) => Err(e),
        }
    }

    fn of_aedat(
        path: &Path,
        selection: &StreamSelection,
        sensor: Option<Resolution>,
        mut on_position: impl FnMut(u64),
    ) -> Result<Self, Error> {
        let aedat = |error| Error::Aedat {
            path: path.to_path_buf(),
            error,
        };
        let mut reader = AedatReader::open(path).map_err(aedat)?;
        let header = reader.header().clone();
        let chosen = match selection.resolve(&header) {
            Ok(chosen) => Ok(chosen),
            // Naming a stream the file lacks is the user's mistake; not choosing among several
            // cameras is not, for a summary: it lists them all.
            Err(error) if *selection != StreamSelection::default() => {
                return Err(Error::Streams {
                    path: path.to_path_buf(),
                    error,
                });
            }
            Err(error) => Err(error.reason),
        };
        let mut rows: Vec<StreamSummary> = header
            .streams
            .iter()
            .map(|info| StreamSummary {
                id: info.id,
                type_identifier: info.type_identifier.clone(),
                name: info.name.clone(),
                source: info.source.clone(),
                width: info.resolution.map(|r| r.width),
                height: info.resolution.map(|r| r.height),
                count: 0,
                on_events: 0,
                first_t_us: None,
                last_t_us: None,
            })
            .collect();
        // A declared sensor must be the chosen event stream's, and checks its events when the
        // stream states no size.
        let chosen_events = chosen.as_ref().ok().and_then(|c| c.events);
        if let Some(declared) = sensor
            && let Some(found) = chosen_events
                .and_then(|id| header.stream(id))
                .and_then(|s| s.resolution)
            && found != declared
        {
            return Err(Error::ResolutionMismatch {
                path: path.to_path_buf(),
                declared,
                found,
            });
        }
        // Each event stream's events checked against its own sensor.
        let mut checks: Vec<EventCheck> = header
            .streams
            .iter()
            .map(|i| {
                let declared = sensor.filter(|_| chosen_events == Some(i.id));
                EventCheck::new(i.resolution.or(declared))
            })
            .collect();
        while let Some(chunk) = reader.next_chunk().map_err(aedat)? {
            let Some(k) = header.streams.iter().position(|i| i.id == chunk.stream_id) else {
                continue;
            };
            checks[k]
                .check(chunk.events)
                .map_err(|error| Error::Event {
                    path: path.to_path_buf(),
                    error,
                })?;
            let row = &mut rows[k];
            // A packet holds one stream, so one kind: at most one of these is non-empty.
            let (n, first, last) = match (chunk.events, chunk.imu, chunk.triggers) {
                (e, _, _) if !e.is_empty() => {
                    (e.len(), e.first().map(|e| e.t), e.last().map(|e| e.t))
                }
                (_, i, _) if !i.is_empty() => {
                    (i.len(), i.first().map(|s| s.t), i.last().map(|s| s.t))
                }
                (_, _, t) => (t.len(), t.first().map(|t| t.t), t.last().map(|t| t.t)),
            };
            if let (Some(first), Some(last)) = (first, last) {
                row.first_t_us.get_or_insert(first);
                row.last_t_us = Some(last);
            }
            row.count += n as u64;
            row.on_events += chunk.events.iter().filter(|e| e.polarity).count() as u64;
            on_position(reader.offset());
        }
        let row_of = |id: Option<i32>| id.and_then(|id| rows.iter().find(|r| r.id == id));
        let (events, imu, triggers, note) = match chosen {
            Ok(c) => (row_of(c.events), row_of(c.imu), row_of(c.triggers), None),
            Err(note) => (None, None, None, Some(note)),
        };
        let mut s = Summary {
            format: Format::Aedat4.name().to_string(),
            source: match (events, &note) {
                (Some(r), _) => r.source.clone(),
                (None, None) => header.source().map(str::to_string),
                (None, Some(_)) => None,
            },
            width: events.and_then(|r| r.width),
            height: events.and_then(|r| r.height),
            events: events.map_or(0, |r| r.count),
            on_events: events.map_or(0, |r| r.on_events),
            first_t_us: events.and_then(|r| r.first_t_us),
            last_t_us: events.and_then(|r| r.last_t_us),
            imu_samples: imu.map_or(0, |r| r.count),
            imu_rate_hz: None,
            first_imu_t_us: imu.and_then(|r| r.first_t_us),
            last_imu_t_us: imu.and_then(|r| r.last_t_us),
            triggers: triggers.map_or(0, |r| r.count),
            streams: Vec::new(),
            topics: Vec::new(),
            selection: note,
            note: None,
        };
        s.set_imu_rate();
        s.streams = rows;
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Event, EventWriter, ImuSample, Resolution, Trigger};

    #[test]
    fn summarises_spans_counts_and_rate() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.aedat4");
        let mut w = EventWriter::create(&path, Some(Resolution::new(64, 48)), None).unwrap();
        let events: Vec<Event> = (0..10)
            .map(|i| Event {
                t: 100 + i * 10,
                x: 1,
                y: 2,
                polarity: i % 2 == 0,
            })
            .collect();
        w.write_events(&events).unwrap();
        let imu: Vec<ImuSample> = (0..5)
            .map(|i| ImuSample {
                t: i * 1_000,
                ..ImuSample::default()
            })
            .collect();
        w.write_imu(&imu).unwrap();
        w.write_triggers(&[Trigger { t: 150, kind: 1 }]).unwrap();
        w.finish().unwrap();
        let s = Summary::of_file(&path).unwrap();
        assert_eq!((s.width, s.height), (Some(64), Some(48)));
        assert_eq!((s.events, s.on_events), (10, 5));
        assert_eq!((s.first_t_us, s.last_t_us), (Some(100), Some(190)));
        assert_eq!((s.first_imu_t_us, s.last_imu_t_us), (Some(0), Some(4_000)));
        assert_eq!(s.imu_rate_hz, Some(1000.0));
        assert_eq!(s.triggers, 1);
    }
}
