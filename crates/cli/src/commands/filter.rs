//! `evtac filter`: a recording through event filters (`evtac_filters`: dv-processing's noise,
//! polarity, region and mask filters exactly, a refractory period, hot pixels and the dome's
//! disc), in the order
//! given, from any format evtac reads to any it writes. IMU samples and triggers pass untouched;
//! each filter's removed events are printed.
//!
//! The filters are built for the recording's sensor before anything is written, so a SPEC that
//! does not fit (a region outside the sensor) leaves no output; outputs appear only once
//! complete ([`evtac_events::output`]), and an output that is the input is refused.

use anyhow::bail;
use evtac_events::output::refuse_input;
use evtac_filters::Filter;
use evtac_formats::EventWriter;

/// Arguments of `evtac filter`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Examples:\n  evtac filter raw.aedat4 clean.aedat4 --filter background-activity=10ms\n  \
                        evtac filter raw.aedat4 clean.npy --filter refractory=1ms --filter \
                        circle=120,120,110"
)]
pub struct Args {
    #[command(flatten)]
    pub files: crate::rewrite::RewriteArgs,
    #[command(flatten)]
    pub filters: crate::filtering::FilterArgs,
    #[command(flatten)]
    pub sensor: crate::sensor::SensorArgs,
    #[command(flatten)]
    pub streams: crate::streams::StreamArgs,
}

/// What a filtering did: events read and written, and each filter's removed count in order.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Counts {
    /// Events read.
    pub events_in: u64,
    /// Events written.
    pub events_out: u64,
    /// Each filter's name and the events it removed.
    pub removed: Vec<(&'static str, u64)>,
}

/// Runs `evtac filter`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let counts = filter(&args)?;
    args.filters.say_removed(&counts.removed);
    args.files.say_written(counts.events_out, counts.events_in);
    Ok(())
}

/// Filters `args.files.input` into `args.files.output` as `evtac filter` does.
pub fn filter(args: &Args) -> anyhow::Result<Counts> {
    if args.filters.filters.is_empty() {
        bail!("no filter: give at least one --filter SPEC (evtac filter --help lists them)");
    }
    refuse_input(&args.files.output, &[&args.files.input])?;
    let mut reader = evtac_formats::open_with(&args.files.input, &args.streams.selection())?;
    if let Some(resolution) = args.sensor.sensor {
        reader.set_resolution(resolution)?;
    }
    let Some(sensor) = reader.resolution() else {
        bail!(
            "{} is {} and does not store the sensor size: pass --sensor WIDTHxHEIGHT",
            args.files.input.display(),
            reader.format()
        );
    };
    let mut chain = args.filters.chain(&args.files.input, sensor)?;
    let mut writer = EventWriter::create(&args.files.output, Some(sensor), reader.source())?;
    let bar = crate::progress::bytes(reader.file_len(), "filtering");
    let mut kept = Vec::new();
    let mut counts = Counts::default();
    while let Some(chunk) = reader.next_chunk()? {
        kept.clear();
        chain.retain(chunk.events, &mut kept);
        writer.write_events(&kept)?;
        writer.write_imu(chunk.imu)?;
        writer.write_triggers(chunk.triggers)?;
        counts.events_in += chunk.events.len() as u64;
        counts.events_out += kept.len() as u64;
        bar.set_position(reader.position());
    }
    bar.finish_and_clear();
    writer.finish()?;
    counts.removed = crate::filtering::removed(&chain);
    Ok(counts)
}
