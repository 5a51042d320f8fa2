//! Recordings through event filters (`evtac_filters`), `hot-pixels=auto` learned first from the
//! recording itself, as [`crate::sensor_stats`] finds hot pixels: the one place that turns SPECs
//! and a recording into a running [`Chain`], for the CLI, the datasets the experiments open,
//! `evtac import` and Python alike.

use std::path::Path;

use evtac_events::{Event, Resolution};
use evtac_filters::{Chain, Filter, FilterSpec};
use evtac_formats::StreamSelection;

use crate::sensor_stats::{self, StatsError};

/// What the filters learned from one recording: the hot pixels `hot-pixels=auto` removes, when
/// it is among them. Builds the chain for that recording, as many times as needed.
#[derive(Debug, Clone, PartialEq)]
pub struct Learned {
    hot_pixels: Option<Vec<(u16, u16)>>,
}

impl Learned {
    /// Learned from the recording at `path` (the streams `streams` picks), read again only
    /// when `specs` learn; `sensor` is the sensor's size when the file does not state it.
    pub fn from_file(
        path: &Path,
        streams: &StreamSelection,
        sensor: Option<Resolution>,
        specs: &[FilterSpec],
    ) -> Result<Self, StatsError> {
        let hot_pixels = match specs.iter().any(FilterSpec::learns) {
            true => Some(sensor_stats::learn_hot_pixels(path, streams, sensor)?),
            false => None,
        };
        Ok(Self { hot_pixels })
    }

    /// Learned from `events`, read from `path` on `sensor`.
    pub fn from_events(
        path: &Path,
        sensor: Resolution,
        specs: &[FilterSpec],
        events: &[Event],
    ) -> Result<Self, StatsError> {
        let hot_pixels = match specs.iter().any(FilterSpec::learns) {
            true => Some(sensor_stats::learn_hot_pixels_of(path, events, sensor)?),
            false => None,
        };
        Ok(Self { hot_pixels })
    }

    /// How many hot pixels `hot-pixels=auto` learned, if it is among the filters.
    pub fn hot_pixels(&self) -> Option<usize> {
        self.hot_pixels.as_ref().map(Vec::len)
    }

    /// A fresh chain of `specs` for the recording at `path` on `sensor`, or the SPEC that does
    /// not fit it.
    pub fn chain(
        &self,
        path: &Path,
        sensor: Resolution,
        specs: &[FilterSpec],
    ) -> Result<Chain, StatsError> {
        Chain::build_with(specs, sensor, self.hot_pixels.as_deref()).map_err(|source| {
            StatsError::Filter {
                path: path.to_path_buf(),
                source,
            }
        })
    }
}

/// [`sensor_stats::measure_streams`] of the recording at `path` through `specs`, in order (the
/// IMU as it is): what a recording filtered by them would show. `hot-pixels=auto` is learned
/// first, from the unfiltered recording (two more passes).
pub fn measure(
    path: &Path,
    streams: &StreamSelection,
    specs: &[FilterSpec],
    on_bytes: impl FnMut(u64),
) -> Result<sensor_stats::SensorStats, StatsError> {
    let learned = Learned::from_file(path, streams, None, specs)?;
    let chain = |sensor| learned.chain(path, sensor, specs);
    sensor_stats::measure_through(path, streams, None, chain, on_bytes)
}

/// `events`, read from `path` on `sensor`, through `specs` (the same events when there are
/// none), with the chain that filtered them (its counts) and what it learned.
pub fn filter_events(
    path: &Path,
    sensor: Resolution,
    specs: &[FilterSpec],
    events: Vec<Event>,
) -> Result<(Vec<Event>, Chain, Learned), StatsError> {
    let learned = Learned::from_events(path, sensor, specs, &events)?;
    let mut chain = learned.chain(path, sensor, specs)?;
    if specs.is_empty() {
        return Ok((events, chain, learned));
    }
    let mut kept = Vec::with_capacity(events.len());
    chain.retain(&events, &mut kept);
    Ok((kept, chain, learned))
}

/// Each filter's name and the events it removed, first to last.
pub type Removed = Vec<(&'static str, u64)>;

/// What each filter of `chain` removed ([`Removed`]).
pub fn removed(chain: &Chain) -> Removed {
    chain
        .filters()
        .iter()
        .map(|f| (f.name(), f.removed()))
        .collect()
}

/// Rewrites the recording at `path` (any format evtac writes, kept) with its events through
/// `specs`, IMU samples and triggers as they are; the new file replaces the old one only once
/// complete. Returns each filter's removed count and the events kept. `hot-pixels=auto` learns
/// from the file first.
pub fn filter_in_place(path: &Path, specs: &[FilterSpec]) -> Result<(Removed, u64), StatsError> {
    let streams = StreamSelection::default();
    let mut reader = evtac_formats::open_with(path, &streams)?;
    let sensor = reader
        .resolution()
        .ok_or_else(|| StatsError::NoResolution(path.to_path_buf()))?;
    let learned = Learned::from_file(path, &streams, Some(sensor), specs)?;
    let mut chain = learned.chain(path, sensor, specs)?;
    let mut writer = evtac_formats::EventWriter::create(path, Some(sensor), reader.source())?;
    let (mut kept, mut written) = (Vec::new(), 0u64);
    while let Some(chunk) = reader.next_chunk()? {
        kept.clear();
        chain.retain(chunk.events, &mut kept);
        writer.write_events(&kept)?;
        writer.write_imu(chunk.imu)?;
        writer.write_triggers(chunk.triggers)?;
        written += kept.len() as u64;
    }
    writer.finish()?;
    Ok((removed(&chain), written))
}

/// A filtering capture for the simulator (`evtac simulate --filter`): each recording's events
/// through `specs`, from its first event, as [`filter_events`] filters them.
#[derive(Debug, Clone, PartialEq)]
pub struct FilteringCapture {
    /// The filters, in order.
    pub specs: Vec<FilterSpec>,
}

impl evtac_sim::Capture for FilteringCapture {
    fn save(
        &self,
        name: &str,
        resolution: Resolution,
        events: Vec<Event>,
    ) -> Result<Vec<Event>, String> {
        filter_events(Path::new(name), resolution, &self.specs, events)
            .map(|(kept, _, _)| kept)
            .map_err(|e| e.to_string())
    }

    fn describe(&self) -> Vec<String> {
        self.specs.iter().map(|f| f.to_string()).collect()
    }
}
