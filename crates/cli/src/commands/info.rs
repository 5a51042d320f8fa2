//! `evtac info`: summarise an event recording (format, sensor, event and IMU counts, time span).

use std::path::PathBuf;

use anyhow::Context;
use serde::Serialize;

/// Arguments of `evtac info`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The recording to summarise (AEDAT 4.0/3.1/2.0, EVT 2.0/2.1/3.0 raw, CSV or NPY).
    pub file: PathBuf,
    /// Print the summary as one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// What `evtac info` reports (also its JSON output).
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

/// Reads the whole file in chunks (with a byte progress bar on a terminal) and summarises it.
pub fn summarise(path: &std::path::Path) -> anyhow::Result<Summary> {
    let mut reader = evtac_events::open(path)?;
    let bar = crate::progress::bytes(reader.file_len(), "reading");
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
        bar.set_position(reader.position());
    }
    bar.finish_and_clear();
    if let (Some(first), Some(last)) = (s.first_imu_t_us, s.last_imu_t_us)
        && last > first
    {
        // Samples per second over the span between the first and the last sample.
        s.imu_rate_hz = Some((s.imu_samples - 1) as f64 / ((last - first) as f64 * 1e-6));
    }
    Ok(s)
}

fn or_dash<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map_or_else(|| "-".to_string(), |v| v.to_string())
}

/// The human-readable summary.
fn render(path: &std::path::Path, s: &Summary) -> String {
    let resolution = match (s.width, s.height) {
        (Some(w), Some(h)) => format!("{w}x{h}"),
        _ => "not stated by the file".to_string(),
    };
    let span = |a: Option<i64>, b: Option<i64>| match (a, b) {
        (Some(a), Some(b)) => format!("{a} .. {b} us ({:.3} s)", (b - a) as f64 * 1e-6),
        _ => "-".to_string(),
    };
    let on_fraction = if s.events > 0 {
        format!(" ({:.2}% ON)", 100.0 * s.on_events as f64 / s.events as f64)
    } else {
        String::new()
    };
    let mut out = format!(
        "file:        {}\nformat:      {}\nsource:      {}\nresolution:  {resolution}\n\
         events:      {}\nON events:   {}{on_fraction}\nevent time:  {}\n",
        path.display(),
        s.format,
        or_dash(s.source.as_deref()),
        s.events,
        s.on_events,
        span(s.first_t_us, s.last_t_us),
    );
    out += &format!(
        "IMU samples: {}{}\nIMU time:    {}\n",
        s.imu_samples,
        s.imu_rate_hz
            .map_or_else(String::new, |r| format!(" ({r:.1} Hz)")),
        span(s.first_imu_t_us, s.last_imu_t_us),
    );
    if s.triggers > 0 {
        out += &format!("triggers:    {}\n", s.triggers);
    }
    out
}

/// Runs `evtac info`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let summary = summarise(&args.file)?;
    if args.json {
        let text = serde_json::to_string_pretty(&summary).context("serialising the summary")?;
        println!("{text}");
    } else {
        print!("{}", render(&args.file, &summary));
    }
    Ok(())
}
