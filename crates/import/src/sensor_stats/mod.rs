//! What a recording says about its sensor, in the simulator's terms (`evtac stats`): the event
//! rate over time and, from the stretches at rest ([`rest`]), each pixel's background rate, the
//! ON fraction that splits it into the simulator's leak and shot noise, the hot pixels
//! ([`pixels`]), and the IMU's noise, bias and resolution ([`imu`]). [`fit`] turns them into a
//! simulator parameter file, so that simulated data has the recorded sensor's noise.
//!
//! Two streaming passes over the file: the events per bin first (which bins are at rest is only
//! known once every bin is counted), then the pixels and IMU samples that lie at rest. Memory is
//! two counters per pixel and one entry per 50 ms bin, however long the recording.
//!
//! ```no_run
//! let stats = evtac_import::sensor_stats::measure("no_contact.aedat4".as_ref(), |_| {})?;
//! let fitted = evtac_import::sensor_stats::fit::fit(&stats, Default::default());
//! println!("{} fields measured", fitted.measured.len());
//! # Ok::<(), evtac_import::sensor_stats::StatsError>(())
//! ```

pub mod fit;
pub mod imu;
pub mod pixels;
pub mod rest;

use evtac_formats::StreamSelection;
use std::path::{Path, PathBuf};

use evtac_events::Resolution;
use evtac_filters::Filter;
use serde::Serialize;

use imu::{ImuAccumulator, ImuStats};
use pixels::{Background, HotPixel, PixelCounts};
use rest::{BIN_US, RateBin};

/// A recording `evtac stats` cannot measure.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StatsError {
    /// The recording could not be read.
    #[error(transparent)]
    Recording(#[from] evtac_formats::Error),
    /// The file does not state the sensor's size, which the per-pixel rates divide by.
    #[error(
        "{}: the file does not state the sensor's size (the per-pixel rates need it; convert \
         it to AEDAT4 with `evtac convert --width W --height H`)",
        .0.display()
    )]
    NoResolution(PathBuf),
    /// The recording holds no events.
    #[error("{}: holds no events", .0.display())]
    NoEvents(PathBuf),
    /// A filter that does not fit the recording's sensor.
    #[error("{}: {source}", .path.display())]
    Filter {
        /// The recording.
        path: PathBuf,
        /// What does not fit.
        source: evtac_filters::Error,
    },
    /// `hot-pixels=auto` on a recording with no stretch at rest to learn them from.
    #[error(
        "{}: hot-pixels=auto learns the hot pixels from the stretches at rest, and the recording \
         has none (no 150 ms without motion); learn them from a rest recording with `evtac stats \
         REST --hot-pixels MASK.npy` and give `hot-pixels=MASK.npy`",
        .0.display()
    )]
    NothingToLearn(PathBuf),
}

/// What [`measure`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorStats {
    /// The recording.
    pub path: PathBuf,
    /// Its sensor's size.
    pub resolution: Resolution,
    /// Events.
    pub events: u64,
    /// ON events.
    pub on_events: u64,
    /// From the first to the last event, s.
    pub duration_s: f64,
    /// The events per [`BIN_US`] bin from the first event, the last bin partial.
    pub bins: Vec<RateBin>,
    /// Most events a bin at rest may hold, if any bin is full.
    pub rest_limit: Option<u64>,
    /// Time at rest, s.
    pub rest_s: f64,
    /// The ordinary pixels at rest, if any time is.
    pub background: Option<Background>,
    /// The hot pixels (none without rest).
    pub hot: Vec<HotPixel>,
    /// The IMU, if the recording has samples and some of them lie at rest.
    pub imu: Option<ImuStats>,
}

impl SensorStats {
    /// The event rate over time as CSV: one row per bin (start in seconds from the first event,
    /// events and ON events per second, whether at rest).
    pub fn rates_csv(&self) -> String {
        let mut out = String::from("start_s,events_per_s,on_per_s,rest\n");
        let t0 = self.bins.first().map_or(0, |b| b.start_us);
        let per_s = 1e6 / BIN_US as f64;
        for b in &self.bins {
            out += &format!(
                "{:.3},{},{},{}\n",
                (b.start_us - t0) as f64 * 1e-6,
                b.events as f64 * per_s,
                b.on as f64 * per_s,
                u8::from(b.rest)
            );
        }
        out
    }
}

/// Measures the recording at `path` (any format evtac reads that states its sensor's size);
/// `on_bytes` sees the bytes read so far over both passes (twice the file's length in all).
pub fn measure(path: &Path, on_bytes: impl FnMut(u64)) -> Result<SensorStats, StatsError> {
    measure_streams(path, &StreamSelection::default(), on_bytes)
}

/// [`measure`] on the streams `streams` picks of an AEDAT4 file with several cameras.
pub fn measure_streams(
    path: &Path,
    streams: &StreamSelection,
    on_bytes: impl FnMut(u64),
) -> Result<SensorStats, StatsError> {
    let none = |_| Ok(evtac_filters::Chain::new(Vec::new()));
    measure_through(path, streams, None, none, on_bytes)
}

/// [`measure_streams`] of the recording's events through the chain `chain` builds for its
/// sensor, afresh for each pass so that both see the same events (the IMU as it is): what a
/// recording filtered so would show. [`crate::filtering::measure`] builds it from SPECs.
/// `sensor` is the sensor's size for a file that does not state it (NPY, CSV); the file's own
/// wins when it does.
pub fn measure_through(
    path: &Path,
    streams: &StreamSelection,
    sensor: Option<Resolution>,
    chain: impl Fn(Resolution) -> Result<evtac_filters::Chain, StatsError>,
    mut on_bytes: impl FnMut(u64),
) -> Result<SensorStats, StatsError> {
    let mut reader = evtac_formats::open_with(path, streams)?;
    let resolution = reader
        .resolution()
        .or(sensor)
        .ok_or_else(|| StatsError::NoResolution(path.to_path_buf()))?;
    let (mut filter, mut kept) = (chain(resolution)?, Vec::new());
    let len = reader.file_len();
    let mut binned = Binned::default();
    while let Some(chunk) = reader.next_chunk()? {
        kept.clear();
        filter.retain(chunk.events, &mut kept);
        kept.iter().for_each(|e| binned.add(e));
        on_bytes(reader.position());
    }
    let rest = binned
        .finish()
        .ok_or_else(|| StatsError::NoEvents(path.to_path_buf()))?;
    let at_rest = |t: i64| rest.at_rest(t);

    let mut reader = evtac_formats::open_with(path, streams)?;
    let mut filter = chain(resolution)?;
    let mut counts = PixelCounts::new(resolution);
    let mut imu = ImuAccumulator::default();
    while let Some(chunk) = reader.next_chunk()? {
        kept.clear();
        filter.retain(chunk.events, &mut kept);
        for e in kept.iter().filter(|e| at_rest(e.t)) {
            counts.add(e);
        }
        for s in chunk.imu {
            imu.add(s, at_rest(s.t));
        }
        on_bytes(len + reader.position());
    }
    let rest_s = rest.rest_s();
    let (background, hot) = match pixels::split(&counts, rest_s) {
        Some((background, hot)) => (Some(background), hot),
        None => (None, Vec::new()),
    };
    Ok(SensorStats {
        path: path.to_path_buf(),
        resolution,
        events: rest.bins.iter().map(|b| b.events).sum(),
        on_events: rest.bins.iter().map(|b| b.on).sum(),
        duration_s: (rest.last - rest.t0) as f64 * 1e-6,
        bins: rest.bins,
        rest_limit: rest.limit,
        rest_s,
        background,
        hot,
        imu: imu.finish(),
    })
}

/// The hot pixels (column, row) of the recording at `path` that `hot-pixels=auto` removes: those
/// [`measure_streams`] finds (two passes over the file), or an error when it has no stretch at
/// rest to learn them from. `sensor` is the sensor's size for a file that does not state it.
pub fn learn_hot_pixels(
    path: &Path,
    streams: &StreamSelection,
    sensor: Option<Resolution>,
) -> Result<Vec<(u16, u16)>, StatsError> {
    let none = |_| Ok(evtac_filters::Chain::new(Vec::new()));
    let stats = measure_through(path, streams, sensor, none, |_| {})?;
    let hot = (stats.rest_s > 0.0).then_some(stats.hot);
    pixels_of(path, hot)
}

/// [`learn_hot_pixels`] from `events` already read from `path` ([`hot_pixels`]).
pub fn learn_hot_pixels_of(
    path: &Path,
    events: &[evtac_events::Event],
    resolution: Resolution,
) -> Result<Vec<(u16, u16)>, StatsError> {
    pixels_of(path, hot_pixels(events, resolution))
}

fn pixels_of(path: &Path, hot: Option<Vec<HotPixel>>) -> Result<Vec<(u16, u16)>, StatsError> {
    let hot = hot.ok_or_else(|| StatsError::NothingToLearn(path.to_path_buf()))?;
    Ok(hot.iter().map(|h| (h.x, h.y)).collect())
}

/// The hot pixels (column, row) of `events` on a `resolution` sensor, as [`measure`] finds them
/// in a file: counted over the stretches at rest, told from the background by the Poisson tail
/// ([`pixels::split`]). `None` when no stretch is at rest, so there is nothing to tell them by.
/// `hot-pixels=auto` removes these.
pub fn hot_pixels(events: &[evtac_events::Event], resolution: Resolution) -> Option<Vec<HotPixel>> {
    let mut binned = Binned::default();
    events.iter().for_each(|e| binned.add(e));
    let rest = binned.finish()?;
    let mut counts = PixelCounts::new(resolution);
    for e in events.iter().filter(|e| rest.at_rest(e.t)) {
        counts.add(e);
    }
    let rest_s = rest.rest_s();
    pixels::split(&counts, rest_s).map(|(_, hot)| hot)
}

/// The first pass: events and ON events per [`BIN_US`] bin from the first event.
#[derive(Default)]
struct Binned {
    bins: Vec<RateBin>,
    t0: Option<i64>,
    last: i64,
}

impl Binned {
    fn add(&mut self, e: &evtac_events::Event) {
        let start = *self.t0.get_or_insert(e.t);
        let k = ((e.t - start) / BIN_US) as usize;
        while self.bins.len() <= k {
            let start_us = start + self.bins.len() as i64 * BIN_US;
            self.bins.push(RateBin {
                start_us,
                events: 0,
                on: 0,
                rest: false,
            });
        }
        self.bins[k].events += 1;
        self.bins[k].on += u64::from(e.polarity);
        self.last = e.t;
    }

    /// The bins with those at rest marked, `None` without events.
    fn finish(mut self) -> Option<RestBins> {
        let t0 = self.t0?;
        let limit = rest::mark_rest(&mut self.bins);
        Some(RestBins {
            bins: self.bins,
            t0,
            last: self.last,
            limit,
        })
    }
}

/// The bins once counted, those at rest marked ([`rest::mark_rest`]).
struct RestBins {
    bins: Vec<RateBin>,
    t0: i64,
    last: i64,
    limit: Option<u64>,
}

impl RestBins {
    fn at_rest(&self, t: i64) -> bool {
        t >= self.t0
            && usize::try_from((t - self.t0) / BIN_US)
                .ok()
                .and_then(|k| self.bins.get(k))
                .is_some_and(|b| b.rest)
    }

    fn rest_s(&self) -> f64 {
        self.bins.iter().filter(|b| b.rest).count() as f64 * BIN_US as f64 * 1e-6
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_events::Event;

    #[test]
    fn hot_pixels_in_memory_are_the_busy_ones_at_rest() {
        // Two seconds of one event a pixel every 100 ms on a 16x16 sensor, and pixel (3, 5)
        // firing every millisecond: every bin looks alike, so all are at rest.
        let resolution = Resolution::new(16, 16);
        let mut events = Vec::new();
        for t in (0..2_000_000i64).step_by(1_000) {
            let k = (t / 1_000) as u16;
            if k.is_multiple_of(2) {
                let p = (k / 2) % 256;
                events.push(Event {
                    t,
                    x: p % 16,
                    y: p / 16,
                    polarity: k.is_multiple_of(4),
                });
            }
            events.push(Event {
                t,
                x: 3,
                y: 5,
                polarity: true,
            });
        }
        let hot = hot_pixels(&events, resolution).unwrap();
        assert_eq!(hot.iter().map(|h| (h.x, h.y)).collect::<Vec<_>>(), [(3, 5)]);
        assert_eq!(hot_pixels(&[], resolution), None);
        let err = learn_hot_pixels_of(Path::new("rest.aedat4"), &[], resolution).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("rest.aedat4: hot-pixels=auto learns"),
            "{err}"
        );
    }
}
