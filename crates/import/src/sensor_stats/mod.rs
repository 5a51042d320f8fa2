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
    mut on_bytes: impl FnMut(u64),
) -> Result<SensorStats, StatsError> {
    let mut reader = evtac_formats::open_with(path, streams)?;
    let resolution = reader
        .resolution()
        .ok_or_else(|| StatsError::NoResolution(path.to_path_buf()))?;
    let len = reader.file_len();
    let (mut bins, mut t0, mut last) = (Vec::<RateBin>::new(), None, 0);
    while let Some(chunk) = reader.next_chunk()? {
        for e in chunk.events {
            let start = *t0.get_or_insert(e.t);
            let k = ((e.t - start) / BIN_US) as usize;
            while bins.len() <= k {
                let start_us = start + bins.len() as i64 * BIN_US;
                bins.push(RateBin {
                    start_us,
                    events: 0,
                    on: 0,
                    rest: false,
                });
            }
            bins[k].events += 1;
            bins[k].on += u64::from(e.polarity);
            last = e.t;
        }
        on_bytes(reader.position());
    }
    let t0 = t0.ok_or_else(|| StatsError::NoEvents(path.to_path_buf()))?;
    let rest_limit = rest::mark_rest(&mut bins);
    let at_rest = |t: i64| {
        t >= t0
            && usize::try_from((t - t0) / BIN_US)
                .ok()
                .and_then(|k| bins.get(k))
                .is_some_and(|b| b.rest)
    };

    let mut reader = evtac_formats::open_with(path, streams)?;
    let mut counts = PixelCounts::new(resolution);
    let mut imu = ImuAccumulator::default();
    while let Some(chunk) = reader.next_chunk()? {
        for e in chunk.events.iter().filter(|e| at_rest(e.t)) {
            counts.add(e);
        }
        for s in chunk.imu {
            imu.add(s, at_rest(s.t));
        }
        on_bytes(len + reader.position());
    }
    let rest_s = bins.iter().filter(|b| b.rest).count() as f64 * BIN_US as f64 * 1e-6;
    let (background, hot) = match pixels::split(&counts, rest_s) {
        Some((background, hot)) => (Some(background), hot),
        None => (None, Vec::new()),
    };
    Ok(SensorStats {
        path: path.to_path_buf(),
        resolution,
        events: bins.iter().map(|b| b.events).sum(),
        on_events: bins.iter().map(|b| b.on).sum(),
        duration_s: (last - t0) as f64 * 1e-6,
        bins,
        rest_limit,
        rest_s,
        background,
        hot,
        imu: imu.finish(),
    })
}
