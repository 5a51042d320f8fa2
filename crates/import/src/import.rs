//! A recording session in, a dataset folder out (`evtac import`): one AEDAT4 per row of the
//! robot's log ([`RobotLog`]), holding the session's events, IMU samples and triggers from
//! [`ImportConfig::pre_us`] before the motion's onset (or from the end of the motion before it,
//! when that is later, so that the labels' stationary segment never holds another motion) to
//! [`ImportConfig::post_us`] after its end (inclusive), on the session's clock; the manifest; the
//! no-contact recording (a file, or a time range of the session) and the calibration when given.
//! Several recordings, each with its own log ([`Part`]: sessions of one protocol, or a folder
//! of per-trial files), make one dataset with [`import_parts`].
//!
//! A session's trials are cut in one sequential pass over it, each chunk streamed into the
//! trials it overlaps, each closed once every stream has passed its end (a trial whose data
//! trails by more than `KEEP_OPEN_US`, a minute, is cut again by a time-range read), so no
//! index is loaded per trial and every packet is read once. With `--sync trigger` the
//! triggers are read first, in a pass of their own ([`crate::sync`] says why one pass cannot
//! do it in bounded memory). Everything is written into a
//! temporary folder beside the output, checked with [`crate::check`] (a motion outside the
//! recording, a session without IMU, a lead-in too short for the labels are errors naming the
//! log's line), and renamed at the end: a failed import leaves nothing behind.

use crate::check::{self, Problem};
use crate::inputs::{Inputs, MaskSource};
use crate::robot_log::RobotLog;
use evtac_events::IoError;
use evtac_events::layout::{CALIBRATION_FILE, NO_CONTACT_FILE};
use evtac_events::manifest::{Manifest, TrialMeta};
use evtac_formats::{EventWriter, RangeIndex};
use evtac_labels::{CalibrationSource, LabelSource};
use std::path::{Path, PathBuf};

/// Kept before each motion's onset by default, ms: the static representation's default decay
/// time (1 s, `evtac_repr::StaticConfig`), so that its potentials at onset are those of a still
/// sensor as in the simulated trials, and well over the labels' 150 ms still lead-in.
pub const DEFAULT_PRE_MS: u64 = 1000;

/// Kept after each motion's end by default, ms: the simulated trials' still tail, which keeps
/// the edge of the labels' zero-phase filter out of the motion.
pub const DEFAULT_POST_MS: u64 = 300;

/// Where the no-contact recording comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NoContact {
    /// A recording of its own (any format evtac reads).
    File(PathBuf),
    /// The time range `[from, to)` of the session, microseconds on its clock.
    Range(i64, i64),
}

/// What an import writes besides the trials.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportConfig {
    /// Kept before each onset, us.
    pub pre_us: i64,
    /// Kept after each motion's end, us.
    pub post_us: i64,
    /// The no-contact recording, if any.
    pub no_contact: Option<NoContact>,
    /// The calibration file (`calibration.json` content), if any.
    pub calibration: Option<PathBuf>,
    /// Where the dataset's labels will come from: the IMU (every recording must hold one), or
    /// the commanded motion (recordings without IMU accepted; written to
    /// `label_source.json`).
    pub labels: LabelSource,
    /// Event filters every written recording (each trial and the no-contact recording) goes
    /// through, each file on its own from its first event (a trial's `pre_us` before the onset
    /// gives the filters their history); IMU and triggers untouched. None: the events as
    /// recorded.
    pub filters: Vec<evtac_filters::FilterSpec>,
}

/// Errors of an import; nothing is left in the output folder after any of them.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    /// The output folder exists already.
    #[error("{}: exists already (an import writes a new folder)", .0.display())]
    Exists(PathBuf),
    /// A file could not be written or renamed.
    #[error(transparent)]
    Io(#[from] IoError),
    /// The session or the no-contact recording could not be read, or a trial not written.
    #[error(transparent)]
    Recording(#[from] evtac_formats::Error),
    /// The calibration file is not a calibration.
    #[error("--calibration: {0}")]
    Calibration(evtac_labels::Error),
    /// The label source could not be written.
    #[error("--labels: {0}")]
    LabelSource(evtac_labels::Error),
    /// The manifest could not be written.
    #[error(transparent)]
    Manifest(#[from] evtac_events::manifest::ManifestError),
    /// A written recording could not go through the filters.
    #[error(transparent)]
    Filter(#[from] crate::sensor_stats::StatsError),
    /// The imported trials do not make a usable dataset; each line names the log's line.
    #[error("{} problem(s) with the imported trials:\n{}", .0.len(), .0.join("\n"))]
    Problems(Vec<String>),
}

/// What an import did.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportSummary {
    /// The dataset folder written.
    pub out: PathBuf,
    /// Trials written.
    pub trials: usize,
    /// Events written over all trials.
    pub events: u64,
    /// How the session's ranges were found (the first trial's; the same file for all).
    pub index: Option<RangeIndex>,
    /// Each filter's name and the events it removed over every written recording, in order
    /// (empty without filters); `events` counts what they kept.
    pub removed: Vec<(&'static str, u64)>,
}

/// One recording and the log of the motions to cut from it.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The recording (a session, or one trial's file).
    pub session: PathBuf,
    /// Its motions, on its clock.
    pub log: RobotLog,
}

/// Imports `session` cut by `log` into the new folder `out`; `on_trial` is called after each
/// trial is written.
pub fn import_session(
    session: &Path,
    log: &RobotLog,
    out: &Path,
    config: &ImportConfig,
    on_trial: &(dyn Fn() + Sync),
) -> Result<ImportSummary, ImportError> {
    let part = Part {
        session: session.to_path_buf(),
        log: log.clone(),
    };
    import_parts(std::slice::from_ref(&part), out, config, on_trial)
}

/// Imports every part (several sessions, or a folder of per-trial files, each cut by its own
/// log) into the one new folder `out`, trials in the parts' order; a no-contact range is of the
/// first part's recording. Trial names must differ across the parts.
pub fn import_parts(
    parts: &[Part],
    out: &Path,
    config: &ImportConfig,
    on_trial: &(dyn Fn() + Sync),
) -> Result<ImportSummary, ImportError> {
    let mut seen = std::collections::HashMap::new();
    let mut repeated = Vec::new();
    for part in parts {
        for (line, t) in &part.log.rows {
            let here = format!("{}:{line}", part.log.path.display());
            if let Some(first) = seen.insert(t.trial.clone(), here.clone()) {
                repeated.push(format!(
                    "{here}: column `trial`: `{}` is also {first} (trial names name the files: \
                     each must be unique across the logs; `evtac import --trial-prefix` puts a \
                     prefix per session before them)",
                    t.trial
                ));
            }
        }
    }
    if !repeated.is_empty() {
        return Err(ImportError::Problems(repeated));
    }
    if out.exists() {
        return Err(ImportError::Exists(out.to_path_buf()));
    }
    let name = out
        .file_name()
        .map_or_else(|| "import".into(), |n| n.to_string_lossy().into_owned());
    let tmp = out.with_file_name(format!(".{name}.import-{}", std::process::id()));
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).map_err(IoError::at(&tmp))?;
    }
    std::fs::create_dir_all(&tmp).map_err(IoError::at(&tmp))?;
    let result = write_all(parts, &tmp, config, on_trial).and_then(|mut summary| {
        std::fs::rename(&tmp, out).map_err(IoError::at(out))?;
        summary.out = out.to_path_buf();
        Ok(summary)
    });
    if result.is_err() {
        // Best effort: the error being returned matters more than a failed clean-up.
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}

/// What [`copy_range`] or [`cut_session`] wrote into one file.
#[derive(Debug, Default)]
struct Copied {
    events: u64,
    imu: u64,
    index: Option<RangeIndex>,
    /// Written again by a range read (an element came after its file was closed); read by the
    /// tests, which check that trailing streams do not cause it.
    #[cfg_attr(not(test), allow(dead_code))]
    redone: bool,
}

/// Copies `[from, to)` of `source` (everything when `None`) into the AEDAT4 file `dest`,
/// chunk by chunk.
fn copy_range(
    source: &Path,
    range: Option<(i64, i64)>,
    dest: &Path,
) -> Result<Copied, ImportError> {
    let mut reader = evtac_formats::open(source)?;
    let index = match range {
        Some((from, to)) => Some(reader.select_range(from, to)?),
        None => None,
    };
    let mut writer = EventWriter::create(dest, reader.resolution(), reader.source())?;
    let (mut events, mut imu) = (0u64, 0u64);
    while let Some(chunk) = reader.next_chunk()? {
        writer.write_events(chunk.events)?;
        writer.write_imu(chunk.imu)?;
        writer.write_triggers(chunk.triggers)?;
        events += chunk.events.len() as u64;
        imu += chunk.imu.len() as u64;
    }
    writer.finish()?;
    Ok(Copied {
        events,
        imu,
        index,
        redone: false,
    })
}

/// One file cut from a session: its elements with `from <= t < to`.
struct Cut {
    from: i64,
    to: i64,
    dest: PathBuf,
}

/// How long a cut's file stays open at most after the latest time read (in any stream) passes
/// its end, us. A cut is closed as soon as each of the events, IMU and triggers has passed its
/// end (each stream's time never goes back, so nothing more can fall into it); this bounds the
/// wait for a stream that has stopped or that the recording does not have (a minute of trials
/// open at once: a few dozen files' buffers). A recorder writes each stream's packets as they fill: DV's trail
/// by about a packet's span (10 ms), but a packet closed by its span only when the stream's
/// next element comes (evtac's writer: a trigger packet is written at the next trigger, a
/// trial later) trails by as long as the stream is quiet. An element that trails by more than
/// this is not lost: its cut is written again by a range read, which loads the data table.
const KEEP_OPEN_US: i64 = 60_000_000;

/// The part of `elements` (sorted by time) with `from <= t < to`.
fn within<T>(elements: &[T], t: impl Fn(&T) -> i64, from: i64, to: i64) -> &[T] {
    let start = elements.partition_point(|e| t(e) < from);
    let end = start + elements[start..].partition_point(|e| t(e) < to);
    &elements[start..end]
}

/// Cuts every range of `cuts` out of `source` in one pass over the file, each chunk written into
/// the cuts it overlaps: memory holds a chunk and the few cuts open at a time (those whose end
/// a stream has not passed yet, within [`KEEP_OPEN_US`]), never an index or the session, and every packet
/// is read once however many trials there are. Writes exactly what [`copy_range`] of each
/// range writes (the same elements, in the same order): a cut that receives an element after
/// it was closed is rewritten with [`copy_range`]. `on_cut(k)` is called as `cuts[k]` is done.
fn cut_session(
    source: &Path,
    cuts: &[Cut],
    on_cut: &dyn Fn(usize),
) -> Result<Vec<Copied>, ImportError> {
    let mut copied: Vec<Copied> = cuts.iter().map(|_| Copied::default()).collect();
    if cuts.is_empty() {
        return Ok(copied);
    }
    let mut order: Vec<usize> = (0..cuts.len()).collect();
    order.sort_by_key(|&k| (cuts[k].from, k));
    let mut reader = evtac_formats::open(source)?;
    let (resolution, name) = (reader.resolution(), reader.source().map(str::to_owned));
    let create = |k: usize| EventWriter::create(&cuts[k].dest, resolution, name.as_deref());
    // Cuts open for writing (in `order`), the next one to open, the closed ones, and the latest
    // end among the closed ones (a chunk starting after it cannot touch them).
    let mut open: Vec<(usize, EventWriter)> = Vec::new();
    let mut next = 0;
    let mut closed: Vec<usize> = Vec::new();
    let mut closed_to = i64::MIN;
    let mut redo = vec![false; cuts.len()];
    let mut latest = i64::MIN;
    // Per stream (events, IMU, triggers), the latest time read, `None` before its first.
    let mut stream_latest: [Option<i64>; 3] = [None; 3];
    while let Some(chunk) = reader.next_chunk()? {
        let firsts = [
            chunk.events.first().map(|e| e.t),
            chunk.imu.first().map(|s| s.t),
            chunk.triggers.first().map(|t| t.t),
        ];
        let lasts = [
            chunk.events.last().map(|e| e.t),
            chunk.imu.last().map(|s| s.t),
            chunk.triggers.last().map(|t| t.t),
        ];
        let (Some(lo), Some(hi)) = (
            firsts.into_iter().flatten().min(),
            lasts.into_iter().flatten().max(),
        ) else {
            continue;
        };
        while let Some(&k) = order.get(next).filter(|&&k| cuts[k].from <= hi) {
            open.push((k, create(k)?));
            next += 1;
        }
        for (k, writer) in &mut open {
            let Cut { from, to, .. } = cuts[*k];
            let events = within(chunk.events, |e| e.t, from, to);
            let imu = within(chunk.imu, |s| s.t, from, to);
            writer.write_events(events)?;
            writer.write_imu(imu)?;
            writer.write_triggers(within(chunk.triggers, |t| t.t, from, to))?;
            copied[*k].events += events.len() as u64;
            copied[*k].imu += imu.len() as u64;
        }
        if lo < closed_to {
            for &k in &closed {
                let Cut { from, to, .. } = cuts[k];
                if !within(chunk.events, |e| e.t, from, to).is_empty()
                    || !within(chunk.imu, |s| s.t, from, to).is_empty()
                    || !within(chunk.triggers, |t| t.t, from, to).is_empty()
                {
                    redo[k] = true;
                }
            }
        }
        latest = latest.max(hi);
        for (stream, last) in stream_latest.iter_mut().zip(lasts) {
            *stream = (*stream).max(last);
        }
        // The earliest of the streams: every later element is at or after it (a stream not
        // read yet may still bring anything, its first packet trailing like the others).
        let passed = stream_latest
            .iter()
            .try_fold(i64::MAX, |m, s| s.map(|s| m.min(s)))
            .unwrap_or(i64::MIN);
        let mut i = 0;
        while i < open.len() {
            let k = open[i].0;
            if cuts[k].to <= passed || cuts[k].to.saturating_add(KEEP_OPEN_US) <= latest {
                open.remove(i).1.finish()?;
                closed.push(k);
                closed_to = closed_to.max(cuts[k].to);
                on_cut(k);
            } else {
                i += 1;
            }
        }
    }
    for (k, writer) in open {
        writer.finish()?;
        on_cut(k);
    }
    // Ranges the recording never reached: empty files, as a range read writes them.
    for &k in &order[next..] {
        create(k)?.finish()?;
        on_cut(k);
    }
    for (k, cut) in cuts.iter().enumerate().filter(|(k, _)| redo[*k]) {
        copied[k] = Copied {
            redone: true,
            ..copy_range(source, Some((cut.from, cut.to)), &cut.dest)?
        };
    }
    Ok(copied)
}

fn write_all(
    parts: &[Part],
    dir: &Path,
    config: &ImportConfig,
    on_trial: &(dyn Fn() + Sync),
) -> Result<ImportSummary, ImportError> {
    let mut summary = ImportSummary {
        out: dir.to_path_buf(),
        trials: parts.iter().map(|p| p.log.rows.len()).sum(),
        events: 0,
        index: None,
        removed: Vec::new(),
    };
    let no_contact = dir.join(NO_CONTACT_FILE);
    let mut outside = Vec::new();
    for (p, Part { session, log }) in parts.iter().enumerate() {
        let mut cuts: Vec<Cut> = log
            .rows
            .iter()
            .zip(log.previous_ends())
            .map(|((_, t), previous_end)| {
                let from = t.motion_start_us.saturating_sub(config.pre_us);
                let from = previous_end.map_or(from, |end| from.max(end));
                // Up to and including `post_us` after the end.
                let to = t
                    .motion_end_us
                    .saturating_add(config.post_us)
                    .saturating_add(1);
                Cut {
                    from,
                    to,
                    dest: dir.join(&t.file),
                }
            })
            .collect();
        // The no-contact range of the first session is cut in the same pass.
        if let (0, Some(NoContact::Range(from, to))) = (p, &config.no_contact) {
            cuts.push(Cut {
                from: *from,
                to: *to,
                dest: no_contact.clone(),
            });
        }
        let rows = log.rows.len();
        let copied = cut_session(session, &cuts, &|k| {
            if k < rows {
                on_trial();
            }
        })?;
        for (((line, t), cut), copied) in log.rows.iter().zip(&cuts).zip(&copied) {
            if copied.events == 0 && copied.imu == 0 {
                outside.push(format!(
                    "{}:{line}: column `motion_start_us` (trial `{}`): {} holds nothing from \
                     {} to {} us: the motion lies outside the recording (check the times \
                     and --clock-offset-us)",
                    log.path.display(),
                    t.trial,
                    session.display(),
                    cut.from,
                    cut.to
                ));
            }
            summary.events += copied.events;
            summary.index = summary.index.take().or(copied.index.clone());
        }
    }
    if !outside.is_empty() {
        return Err(ImportError::Problems(outside));
    }
    if let Some(NoContact::File(path)) = &config.no_contact {
        copy_range(path, None, &no_contact)?;
    }
    if !config.filters.is_empty() {
        summary.events = 0;
        let trials = parts
            .iter()
            .flat_map(|p| p.log.rows.iter().map(|(_, t)| &t.file));
        let files: Vec<PathBuf> = trials.map(|f| dir.join(f)).collect();
        for (k, file) in files
            .iter()
            .chain(no_contact.is_file().then_some(&no_contact))
            .enumerate()
        {
            let (removed, kept) = crate::filtering::filter_in_place(file, &config.filters)?;
            if k < files.len() {
                summary.events += kept;
            }
            if summary.removed.is_empty() {
                summary.removed = removed;
            } else {
                for (sum, (_, n)) in summary.removed.iter_mut().zip(removed) {
                    sum.1 += n;
                }
            }
        }
    }
    if config.labels != LabelSource::Imu {
        config.labels.write(dir).map_err(ImportError::LabelSource)?;
    }
    if let Some(path) = &config.calibration {
        let dest = dir.join(CALIBRATION_FILE);
        std::fs::copy(path, &dest).map_err(IoError::at(path))?;
        evtac_labels::read_calibration(dir).map_err(ImportError::Calibration)?;
    }
    // The manifest's rows in the parts' order, each with where it came from.
    let rows: Vec<Source> = parts
        .iter()
        .flat_map(|p| {
            p.log.rows.iter().map(move |(line, t)| Source {
                log: &p.log.path,
                line: *line,
                session: &p.session,
                trial: t,
            })
        })
        .collect();
    let manifest = Manifest {
        trials: rows.iter().map(|r| r.trial.clone()).collect(),
    };
    manifest.write(dir)?;
    // What was not given is not checked here: `evtac check` and the commands that read the
    // dataset ask for it.
    let inputs = Inputs {
        calibration: if config.calibration.is_some() {
            CalibrationSource::File
        } else {
            CalibrationSource::Identity
        },
        mask: if config.no_contact.is_some() {
            MaskSource::NoContact
        } else {
            MaskSource::Unmasked
        },
        filters: Vec::new(),
    };
    let report = check::check(dir, &inputs, &|_| {});
    if !report.problems.is_empty() {
        return Err(ImportError::Problems(
            report
                .problems
                .iter()
                .map(|p| in_log_terms(p, &rows, dir))
                .collect(),
        ));
    }
    Ok(summary)
}

/// Where a manifest row came from: its log's line and the recording it was cut from.
struct Source<'a> {
    log: &'a Path,
    line: usize,
    session: &'a Path,
    trial: &'a TrialMeta,
}

/// A problem of the imported dataset in the terms of the import's inputs: a trial's problem
/// names its log's line (the manifest keeps the logs' order), a file written from a session
/// names the file.
fn in_log_terms(p: &Problem, rows: &[Source], dir: &Path) -> String {
    let field = p.field.as_deref().unwrap_or("-");
    // Manifest line n (after the header on line 1) is row n - 2.
    let row = p
        .line
        .and_then(|l| l.checked_sub(2))
        .and_then(|i| rows.get(i));
    match row {
        Some(r) => format!(
            "{}:{}: column `{field}` (trial `{}`, cut from {}): {} ({})",
            r.log.display(),
            r.line,
            r.trial.trial,
            r.session.display(),
            p.problem,
            p.fix
        ),
        None => format!(
            "{}: {} ({})",
            p.file.strip_prefix(dir).unwrap_or(&p.file).display(),
            p.problem,
            p.fix
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_events::{Event, ImuSample, Resolution, Trigger};

    /// Writes a 3 s session: events every 100 us, IMU every 1250 us, a trigger every 1.2 s;
    /// with `trailing`, all the IMU and triggers after all the events (streams trailing by up
    /// to 3 s), else interleaved every 10 ms as a recorder writes them.
    fn session(path: &Path, trailing: bool) {
        let events: Vec<Event> = (0..30_000)
            .map(|i| Event {
                t: i * 100,
                x: (i % 64) as u16,
                y: (i % 48) as u16,
                polarity: i % 3 == 0,
            })
            .collect();
        let imu: Vec<ImuSample> = (0..2_400)
            .map(|i| ImuSample {
                t: i * 1250 + 7,
                accelerometer: [0.0, 0.0, 1.0],
                gyroscope: [i as f32, 0.0, 0.0],
                temperature: 30.0,
            })
            .collect();
        // Every 1.2 s: the writer closes a trigger packet at the next trigger, so in the
        // interleaved file each trigger trails the events by 1.2 s, as in a simulated session.
        let triggers: Vec<Trigger> = (0..3)
            .map(|i| Trigger {
                t: i * 1_200_000 + 3,
                kind: 1,
            })
            .collect();
        let mut w = EventWriter::create(path, Some(Resolution::new(64, 48)), Some("cam")).unwrap();
        if trailing {
            w.write_events(&events).unwrap();
            w.write_imu(&imu).unwrap();
            w.write_triggers(&triggers).unwrap();
        } else {
            for slice in 0..300 {
                let (a, b) = (slice * 10_000, (slice + 1) * 10_000);
                w.write_events(within(&events, |e| e.t, a, b)).unwrap();
                w.write_imu(within(&imu, |s| s.t, a, b)).unwrap();
                w.write_triggers(within(&triggers, |t| t.t, a, b)).unwrap();
            }
        }
        w.finish().unwrap();
    }

    #[test]
    fn one_pass_cuts_equal_range_reads() {
        let dir = tempfile::tempdir().unwrap();
        for trailing in [false, true] {
            let source = dir.path().join(format!("session-{trailing}.aedat4"));
            session(&source, trailing);
            // Overlapping, nested, out of order, empty and beyond the end.
            let ranges = [
                (400_000, 1_300_000),
                (0, 250_001),
                (1_200_000, 1_250_000),
                (1_000_000, 2_999_901),
                (5_000_000, 6_000_000),
                (2_000_000, 2_000_001),
            ];
            let cuts: Vec<Cut> = ranges
                .iter()
                .enumerate()
                .map(|(k, &(from, to))| Cut {
                    from,
                    to,
                    dest: dir.path().join(format!("cut-{trailing}-{k}.aedat4")),
                })
                .collect();
            let copied = cut_session(&source, &cuts, &|_| {}).unwrap();
            if !trailing {
                // Streams that trail (the triggers) keep a cut open: nothing is read twice.
                assert!(copied.iter().all(|c| !c.redone), "a cut was redone");
            }
            for (cut, copied) in cuts.iter().zip(&copied) {
                let expected = dir.path().join("expected.aedat4");
                let by_range = copy_range(&source, Some((cut.from, cut.to)), &expected).unwrap();
                assert_eq!(
                    (copied.events, copied.imu),
                    (by_range.events, by_range.imu),
                    "{}",
                    cut.dest.display()
                );
                assert!(
                    std::fs::read(&cut.dest).unwrap() == std::fs::read(&expected).unwrap(),
                    "{} differs from the range read",
                    cut.dest.display()
                );
            }
        }
    }
}
