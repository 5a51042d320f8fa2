//! What a recording holds, read in one streaming pass: format, sensor, event and IMU counts,
//! time spans, IMU rate, triggers. `evtac info` prints it; `evtac check` compares its time spans
//! with the motion windows of a dataset's manifest.

use std::path::Path;

use serde::Serialize;

use crate::{Error, EventReader};

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
}

impl Summary {
    /// Reads the rest of `reader` chunk by chunk (bounded memory) and summarises it;
    /// `on_position` sees the reader's byte position after each chunk (for a progress bar).
    pub fn read(reader: &mut EventReader, mut on_position: impl FnMut(u64)) -> Result<Self, Error> {
        let mut s = Summary {
            format: reader.format().name().to_string(),
            source: reader.source().map(str::to_string),
            width: reader.resolution().map(|r| r.width),
            height: reader.resolution().map(|r| r.height),
            events: 0,
            on_events: 0,
            first_t_us: None,
            last_t_us: None,
            imu_samples: 0,
            imu_rate_hz: None,
            first_imu_t_us: None,
            last_imu_t_us: None,
            triggers: 0,
        };
        while let Some(chunk) = reader.next_chunk()? {
            if let (Some(first), Some(last)) = (chunk.events.first(), chunk.events.last()) {
                s.first_t_us.get_or_insert(first.t);
                s.last_t_us = Some(last.t);
            }
            s.events += chunk.events.len() as u64;
            s.on_events += chunk.events.iter().filter(|e| e.polarity).count() as u64;
            if let (Some(first), Some(last)) = (chunk.imu.first(), chunk.imu.last()) {
                s.first_imu_t_us.get_or_insert(first.t);
                s.last_imu_t_us = Some(last.t);
            }
            s.imu_samples += chunk.imu.len() as u64;
            s.triggers += chunk.triggers.len() as u64;
            on_position(reader.position());
        }
        if let (Some(first), Some(last)) = (s.first_imu_t_us, s.last_imu_t_us)
            && last > first
        {
            // Samples per second over the span between the first and the last sample.
            s.imu_rate_hz = Some((s.imu_samples - 1) as f64 / ((last - first) as f64 * 1e-6));
        }
        Ok(s)
    }

    /// Opens the recording at `path` (any format evtac reads) and summarises it.
    pub fn of_file(path: impl AsRef<Path>) -> Result<Self, Error> {
        Self::read(&mut crate::open(path)?, |_| {})
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
