//! `evtac info`: summarise an event recording (format, sensor, event and IMU counts, time span).

use std::path::PathBuf;

use anyhow::Context;
use evtac_events::Resolution;
use evtac_formats::StreamSelection;
use evtac_formats::Summary;

/// Arguments of `evtac info`.
#[derive(Debug, clap::Args)]
pub struct Args {
    // The help is built from the one phrase of readable formats (see `crate::formats`).
    #[arg(help = concat!(
        "The recording to summarise (any format evtac reads: ",
        crate::formats::readable_formats!(),
        ")"
    ))]
    pub file: PathBuf,
    /// Print the summary as one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub streams: crate::streams::StreamArgs,
    #[command(flatten)]
    pub sensor: crate::sensor::SensorArgs,
}

/// Reads the whole file in chunks (with a byte progress bar on a terminal) and summarises it:
/// every stream of an AEDAT4 file, and the chosen ones at the top level. A declared `sensor`
/// is checked against the size the file states, and every event against it.
pub fn summarise(
    path: &std::path::Path,
    streams: &StreamSelection,
    sensor: Option<Resolution>,
) -> anyhow::Result<Summary> {
    let len = std::fs::metadata(path)
        .with_context(|| path.display().to_string())?
        .len();
    let bar = crate::progress::bytes(len, "reading");
    let on_position = |position| bar.set_position(position);
    let summary = Summary::of_file_with(path, streams, sensor, on_position)?;
    bar.finish_and_clear();
    Ok(summary)
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
    if let Some(note) = &s.note {
        out += &format!("note:        {note}\n");
    }
    if let Some(why) = &s.selection {
        out += &format!(
            "note:        {why}; the counts above are empty, the streams below are whole\n"
        );
    }
    if !s.topics.is_empty() {
        out += "topics:\n";
        for t in &s.topics {
            out += &format!(
                "  {}: {}, {} messages\n",
                t.name, t.message_type, t.messages
            );
        }
    }
    if s.streams.len() > 1 {
        out += "streams:\n";
        for r in &s.streams {
            let size = match (r.width, r.height) {
                (Some(w), Some(h)) => format!(" {w}x{h}"),
                _ => String::new(),
            };
            out += &format!(
                "  id {}: {} `{}` from {}{size}: {} elements, {}\n",
                r.id,
                r.type_identifier,
                r.name.as_deref().unwrap_or("-"),
                r.source.as_deref().unwrap_or("-"),
                r.count,
                span(r.first_t_us, r.last_t_us),
            );
        }
    }
    out
}

/// Runs `evtac info`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let summary = summarise(&args.file, &args.streams.selection(), args.sensor.sensor)?;
    if args.json {
        let text = serde_json::to_string_pretty(&summary).context("serialising the summary")?;
        println!("{text}");
    } else {
        print!("{}", render(&args.file, &summary));
    }
    Ok(())
}
