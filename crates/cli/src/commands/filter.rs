//! `evtac filter`: a recording through event filters (`evtac_filters`: dv-processing's noise,
//! polarity, region and mask filters exactly, a refractory period, hot pixels and the dome's
//! disc), in the order
//! given, from any format evtac reads to any it writes. IMU samples and triggers pass untouched;
//! each filter's removed events are printed.
//!
//! The filters are built for the recording's sensor before anything is written, so a SPEC that
//! does not fit (a region outside the sensor) leaves no output; outputs appear only once
//! complete ([`evtac_events::output`]), and an output that is the input is refused.

use std::sync::mpsc;

use anyhow::bail;
use evtac_events::output::refuse_input;
use evtac_events::{Event, ImuSample, Trigger};
use evtac_filters::{Chain, Filter};
use evtac_formats::{EventReader, EventWriter};

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
///
/// Reading, filtering and writing each run on a thread of their own, a batch apart: on an
/// AEDAT4 LZ4 recording written to NPY the three take comparable times (decompression and
/// checks; the filter; encoding plus the kernel copying the output into the page cache), so
/// on two cores the whole costs about half their sum rather than all of it (see
/// docs/performance.md, "Event filters").
pub fn filter(args: &Args) -> anyhow::Result<Counts> {
    if args.filters.filters.is_empty() {
        bail!("no filter: give at least one --filter SPEC (evtac filter --help lists them)");
    }
    refuse_input(&args.files.output, &[&args.files.input])?;
    let streams = args.streams.selection();
    let mut reader = evtac_formats::open_with(&args.files.input, &streams)?;
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
    let chain = args.filters.chain(&args.files.input, &streams, sensor)?;
    let mut writer = EventWriter::create(&args.files.output, Some(sensor), reader.source())?;
    let bar = crate::progress::bytes(reader.file_len(), "filtering");
    let mut counts = Counts::default();
    let chain = pipeline(reader, chain, |batch| {
        writer.write_events(&batch.kept)?;
        writer.write_imu(&batch.imu)?;
        writer.write_triggers(&batch.triggers)?;
        counts.events_in += batch.events.len() as u64;
        counts.events_out += batch.kept.len() as u64;
        bar.set_position(batch.position);
        Ok(())
    })?;
    bar.finish_and_clear();
    writer.finish()?;
    counts.removed = crate::filtering::removed(&chain);
    Ok(counts)
}

/// Batches close once they hold about this many events: an AEDAT4 packet holds a few
/// thousand, and handing each over on its own would cost two wake-ups per packet.
const BATCH_EVENTS: usize = 1 << 16;

/// Batches in flight: one at each of the three stages and one queued between; more would only
/// hold memory, since the slowest stage sets the pace.
const BATCHES: usize = 4;

/// Consecutive chunks of the recording, copied out of the reader's buffers so that they can
/// cross to other threads (`events`, `imu`, `triggers`, the reader's `position` after them),
/// and the events the chain kept of them.
#[derive(Default)]
struct Batch {
    events: Vec<Event>,
    imu: Vec<ImuSample>,
    triggers: Vec<Trigger>,
    position: u64,
    kept: Vec<Event>,
}

/// A batch on its way, or the error that ended the reading.
type Passed = anyhow::Result<Batch>;

/// Reads `reader` to its end on one thread, filters it through `chain` on another and hands
/// `write` each filtered batch, in order, on this one; returns the chain (with its counts) once
/// all three are done. The first error of any stage ends them all and is returned. Batches go
/// round (read, filter, write, back to be read into again), so memory stays bounded by
/// [`BATCHES`] and nothing is allocated once they have grown to size.
fn pipeline(
    mut reader: EventReader,
    mut chain: Chain,
    mut write: impl FnMut(&Batch) -> anyhow::Result<()>,
) -> anyhow::Result<Chain> {
    let (read_tx, read_rx) = mpsc::sync_channel::<Passed>(1);
    let (filtered_tx, filtered_rx) = mpsc::sync_channel::<Passed>(1);
    let (back_tx, back_rx) = mpsc::channel::<Batch>();
    for _ in 0..BATCHES {
        back_tx
            .send(Batch::default())
            .expect("the receiver is here");
    }
    // `move`: the closure owns `back_tx` and `filtered_rx`, so an early return drops them, and
    // the other stages, waiting for a buffer or sending to a receiver that is gone, end rather
    // than the scope waiting for them forever. Each stage ends when its input ends.
    std::thread::scope(move |scope| {
        scope.spawn(move || {
            while let Ok(mut batch) = back_rx.recv() {
                let (more, batch) = match read_batch(&mut reader, &mut batch) {
                    Ok(more) => (more, Ok(batch)),
                    Err(e) => (false, Err(e.into())),
                };
                if read_tx.send(batch).is_err() || !more {
                    return;
                }
            }
        });
        let filtering = scope.spawn(move || {
            for batch in read_rx {
                let batch = batch.map(|mut batch| {
                    batch.kept.clear();
                    chain.retain(&batch.events, &mut batch.kept);
                    batch
                });
                if filtered_tx.send(batch).is_err() {
                    break;
                }
            }
            chain
        });
        for batch in filtered_rx {
            let batch = batch?;
            write(&batch)?;
            // The reading thread may have finished: a buffer it no longer wants is dropped.
            let _ = back_tx.send(batch);
        }
        Ok(filtering
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
    })
}

/// Reads chunks into `batch` (emptied first) until it holds [`BATCH_EVENTS`] events, or ends
/// with IMU samples or triggers, or the file ends; whether there may be more to read.
fn read_batch(reader: &mut EventReader, batch: &mut Batch) -> Result<bool, evtac_formats::Error> {
    batch.events.clear();
    batch.imu.clear();
    batch.triggers.clear();
    let more = loop {
        let Some(chunk) = reader.next_chunk()? else {
            break false;
        };
        batch.events.extend_from_slice(chunk.events);
        batch.imu.extend_from_slice(chunk.imu);
        batch.triggers.extend_from_slice(chunk.triggers);
        // A batch ends after IMU samples or triggers, so the writer sees the streams in the
        // order it would have chunk by chunk (a batch's events, then its IMU samples and
        // triggers).
        if !chunk.imu.is_empty() || !chunk.triggers.is_empty() || batch.events.len() >= BATCH_EVENTS
        {
            break true;
        }
    };
    batch.position = reader.position();
    Ok(more)
}

#[cfg(test)]
mod tests {
    use evtac_events::Resolution;
    use evtac_filters::FilterSpec;
    use evtac_formats::aedat::{AedatWriter, Compression, WriterConfig};

    use super::*;

    const SENSOR: Resolution = Resolution {
        width: 32,
        height: 24,
    };

    /// An AEDAT4 file of several batches' events, with an IMU sample every 10 000 events.
    fn recording(dir: &std::path::Path) -> (std::path::PathBuf, Vec<Event>, Vec<ImuSample>) {
        let events: Vec<Event> = (0..3 * BATCH_EVENTS as i64 + 123)
            .map(|i| Event {
                t: 1_000_000 + i * 3,
                x: (i * 7 % 32) as u16,
                y: (i * 5 % 24) as u16,
                polarity: i % 3 == 0,
            })
            .collect();
        let imu: Vec<ImuSample> = (0..events.len() as i64 / 10_000)
            .map(|k| ImuSample {
                t: 1_000_000 + k * 30_000,
                ..ImuSample::default()
            })
            .collect();
        let path = dir.join("in.aedat4");
        let config = WriterConfig {
            resolution: SENSOR,
            source_name: "test".into(),
            compression: Compression::Lz4,
        };
        let mut w = AedatWriter::create(&path, config).unwrap();
        for (k, part) in events.chunks(10_000).enumerate() {
            w.write_events(part).unwrap();
            w.write_imu(imu.get(k..k + 1).unwrap_or_default()).unwrap();
        }
        w.finish().unwrap();
        (path, events, imu)
    }

    fn chain() -> Chain {
        let specs: Vec<FilterSpec> = ["polarity=on", "background-activity=50us"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        Chain::build(&specs, SENSOR).unwrap()
    }

    #[test]
    fn the_pipeline_writes_what_the_chain_keeps_in_order_and_counts() {
        let dir = tempfile::tempdir().unwrap();
        let (path, events, imu) = recording(dir.path());
        let mut expected = Vec::new();
        let mut whole = chain();
        whole.retain(&events, &mut expected);
        let (mut kept, mut imu_out, mut batches) = (Vec::new(), Vec::new(), 0);
        let reader = evtac_formats::open(&path).unwrap();
        let piped = pipeline(reader, chain(), |batch| {
            kept.extend_from_slice(&batch.kept);
            imu_out.extend_from_slice(&batch.imu);
            batches += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!(kept, expected);
        assert_eq!(imu_out, imu);
        assert!(batches > 3, "{batches} batches");
        assert_eq!(piped.removed(), whole.removed());
        assert_eq!(
            crate::filtering::removed(&piped),
            crate::filtering::removed(&whole)
        );
    }

    #[test]
    fn a_read_error_or_a_write_error_ends_every_stage_and_is_returned() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _, _) = recording(dir.path());
        // Cut in the middle of the packets: the reader fails part-way.
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.path().join("cut.aedat4");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let reader = evtac_formats::open(&cut).unwrap();
        let mut written = 0;
        let result = pipeline(reader, chain(), |_| {
            written += 1;
            Ok(())
        });
        assert!(result.is_err());
        assert!(written > 0, "the batches before the damage were written");
        // The writer failing on the first batch stops the reading and filtering threads too
        // (the call returns rather than waiting for them).
        let reader = evtac_formats::open(&path).unwrap();
        let result = pipeline(reader, chain(), |_| anyhow::bail!("disk full"));
        assert_eq!(result.unwrap_err().to_string(), "disk full");
    }
}
