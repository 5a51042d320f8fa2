//! `evtac convert`: any readable event file to AEDAT4, CSV or NPY (by the output's extension),
//! optionally cut to a time range, cropped to a centered region and with the IMU written to a
//! CSV file. AEDAT4 outputs keep the IMU samples and triggers.
//!
//! An output that is the input (by path or through a link) is refused before anything is
//! opened, and outputs appear only once complete ([`evtac_events::output`]): a conversion that
//! fails half-way leaves no file that looks valid.
//!
//! A time range (`--from-us`, `--to-us`) is read through an AEDAT4 input's data table, so
//! cutting a trial out of a long session reads only that trial's packets; when the table is
//! missing or damaged the whole file is scanned, with one warning saying why.

use std::path::PathBuf;

use anyhow::{Context, bail};
use evtac_events::output::{OutputFile, refuse_input};
use evtac_events::{Resolution, Roi};
use evtac_formats::EventWriter;
use evtac_formats::csv::ImuCsvWriter;

/// Arguments of `evtac convert`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub files: crate::rewrite::RewriteArgs,
    /// Also write the IMU samples to this CSV file (t,ax,ay,az,gx,gy,gz,temperature).
    #[arg(long, value_name = "IMU_OUT.csv")]
    pub imu: Option<PathBuf>,
    #[command(flatten)]
    pub sensor: crate::sensor::SensorArgs,
    /// Keep only the centered WIDTHxHEIGHT region: events outside are dropped, coordinates are
    /// shifted into it, and the output's resolution is the region's.
    #[arg(long, value_name = "WxH")]
    pub roi: Option<Resolution>,
    /// Keep only events, IMU samples and triggers at or after this time, in microseconds on the
    /// file's own clock (as `evtac info` prints it); default: the start of the file.
    #[arg(long, value_name = "US", allow_hyphen_values = true)]
    pub from_us: Option<i64>,
    /// Keep only what comes before this time (excluded), in microseconds on the file's clock;
    /// default: the end of the file. An AEDAT4 input with a data table is read only where the
    /// range lies.
    #[arg(long, value_name = "US", allow_hyphen_values = true)]
    pub to_us: Option<i64>,
    #[command(flatten)]
    pub streams: crate::streams::StreamArgs,
}

/// What a conversion wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counts {
    /// Events read.
    pub events_in: u64,
    /// Events written (after the crop).
    pub events_out: u64,
    /// IMU samples read.
    pub imu: u64,
    /// Triggers read.
    pub triggers: u64,
}

/// Runs `evtac convert`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let counts = convert(&args)?;
    args.files.say_written(counts.events_out, counts.events_in);
    Ok(())
}

/// Converts `args.files.input` to `args.files.output` as `evtac convert` does.
pub fn convert(args: &Args) -> anyhow::Result<Counts> {
    refuse_input(&args.files.output, &[&args.files.input])?;
    if let Some(imu) = &args.imu {
        refuse_input(imu, &[&args.files.input, &args.files.output])?;
    }
    let mut reader = evtac_formats::open_with(&args.files.input, &args.streams.selection())?;
    if let Some(resolution) = args.sensor.sensor {
        reader.set_resolution(resolution)?;
    }
    if args.from_us.is_some() || args.to_us.is_some() {
        let (from, to) = (
            args.from_us.unwrap_or(i64::MIN),
            args.to_us.unwrap_or(i64::MAX),
        );
        if from >= to {
            bail!(
                "{}: --from-us {from} is not before --to-us {to}: the time range [from, to) is empty",
                args.files.input.display()
            );
        }
        let index = reader.select_range(from, to)?;
        if let Some(reason) = index.fallback() {
            eprintln!(
                "warning: {}: {reason}; reading the whole file to find the range",
                args.files.input.display()
            );
        }
    }
    let Some(sensor) = reader.resolution() else {
        bail!(
            "{} is {} and does not store the sensor size: pass --sensor WIDTHxHEIGHT",
            args.files.input.display(),
            reader.format()
        );
    };
    let roi = match args.roi {
        Some(size) => Roi::centered(sensor, size)
            .with_context(|| format!("--roi {size} does not fit inside the {sensor} sensor"))?,
        None => Roi::full(sensor),
    };
    let mut writer = EventWriter::create(&args.files.output, Some(roi.size), reader.source())?;
    let mut imu_writer = match &args.imu {
        Some(path) => Some((
            ImuCsvWriter::new(
                OutputFile::buffered(path)
                    .with_context(|| format!("creating {}", path.display()))?,
            )
            .with_context(|| format!("writing {}", path.display()))?,
            path,
        )),
        None => None,
    };
    let bar = crate::progress::bytes(reader.file_len(), "converting");
    let mut cropped = Vec::new();
    let mut counts = Counts::default();
    while let Some(chunk) = reader.next_chunk()? {
        roi.crop_into(chunk.events, &mut cropped);
        writer.write_events(&cropped)?;
        writer.write_imu(chunk.imu)?;
        writer.write_triggers(chunk.triggers)?;
        if let Some((w, path)) = &mut imu_writer {
            w.write_imu(chunk.imu)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        counts.events_in += chunk.events.len() as u64;
        counts.events_out += cropped.len() as u64;
        counts.imu += chunk.imu.len() as u64;
        counts.triggers += chunk.triggers.len() as u64;
        bar.set_position(reader.position());
    }
    bar.finish_and_clear();
    let stores_imu = writer.stores_imu();
    let stores_triggers = writer.stores_triggers();
    writer.finish()?;
    if let Some((w, path)) = imu_writer {
        let file = w
            .finish()
            .with_context(|| format!("writing {}", path.display()))?;
        OutputFile::commit_buffered(file).with_context(|| format!("writing {}", path.display()))?;
    }
    if counts.imu > 0 && !stores_imu && args.imu.is_none() {
        eprintln!(
            "note: {} IMU samples were not written ({} files hold events only); use --imu FILE.csv",
            counts.imu,
            writer_format_name(&args.files.output)
        );
    }
    if counts.triggers > 0 && !stores_triggers {
        eprintln!(
            "note: {} triggers were not written ({} files hold events only); write .aedat4 to keep them",
            counts.triggers,
            writer_format_name(&args.files.output)
        );
    }
    Ok(counts)
}

fn writer_format_name(path: &std::path::Path) -> &'static str {
    evtac_formats::Format::for_writing(path).map_or("these", |f| f.name())
}
