//! A recording session in, a dataset folder out (`evtac import`): one AEDAT4 per row of the
//! robot's log ([`RobotLog`]), holding the session's events, IMU samples and triggers from
//! [`ImportConfig::pre_us`] before the motion's onset (or from the end of the motion before it,
//! when that is later, so that the labels' stationary segment never holds another motion) to
//! [`ImportConfig::post_us`] after its end (inclusive), on the session's clock; the manifest; the
//! no-contact recording (a file, or a time range of the session) and the calibration when given.
//! Several recordings, each with its own log ([`Part`]: sessions of one protocol, or a folder
//! of per-trial files), make one dataset with [`import_parts`].
//!
//! Each trial is cut with a time-range read, through the AEDAT4 data table when the session has
//! one (only the packets in the range are decoded), and streamed chunk by chunk, so memory stays
//! bounded however long the session. Everything is written into a temporary folder beside the
//! output, checked with [`crate::check`] (a motion outside the recording, a session without IMU,
//! a lead-in too short for the labels are errors naming the log's line), and renamed at the end:
//! a failed import leaves nothing behind.

use crate::check::{self, Problem};
use crate::inputs::{Inputs, MaskSource};
use crate::io::IoError;
use crate::robot_log::RobotLog;
use evtac_events::layout::{CALIBRATION_FILE, NO_CONTACT_FILE};
use evtac_events::manifest::{Manifest, TrialMeta};
use evtac_events::{EventWriter, RangeIndex};
use evtac_labels::CalibrationSource;
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
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImportConfig {
    /// Kept before each onset, us.
    pub pre_us: i64,
    /// Kept after each motion's end, us.
    pub post_us: i64,
    /// The no-contact recording, if any.
    pub no_contact: Option<NoContact>,
    /// The calibration file (`calibration.json` content), if any.
    pub calibration: Option<PathBuf>,
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
    Recording(#[from] evtac_events::Error),
    /// The calibration file is not a calibration.
    #[error("--calibration: {0}")]
    Calibration(evtac_labels::Error),
    /// The manifest could not be written.
    #[error(transparent)]
    Manifest(#[from] evtac_events::manifest::ManifestError),
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
                     each must be unique across the logs)",
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

/// What [`copy_range`] wrote.
struct Copied {
    events: u64,
    imu: u64,
    index: Option<RangeIndex>,
}

/// Copies `[from, to)` of `source` (everything when `None`) into the AEDAT4 file `dest`,
/// chunk by chunk.
fn copy_range(
    source: &Path,
    range: Option<(i64, i64)>,
    dest: &Path,
) -> Result<Copied, ImportError> {
    let mut reader = evtac_events::open(source)?;
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
    Ok(Copied { events, imu, index })
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
    };
    let mut outside = Vec::new();
    for Part { session, log } in parts {
        for ((line, t), previous_end) in log.rows.iter().zip(log.previous_ends()) {
            let from = t.motion_start_us.saturating_sub(config.pre_us);
            let from = previous_end.map_or(from, |end| from.max(end));
            // Up to and including `post_us` after the end.
            let to = t
                .motion_end_us
                .saturating_add(config.post_us)
                .saturating_add(1);
            let copied = copy_range(session, Some((from, to)), &dir.join(&t.file))?;
            if copied.events == 0 && copied.imu == 0 {
                outside.push(format!(
                    "{}:{line}: column `motion_start_us` (trial `{}`): {} holds nothing from \
                     {from} to {to} us: the motion lies outside the recording (check the times \
                     and --clock-offset-us)",
                    log.path.display(),
                    t.trial,
                    session.display()
                ));
            }
            summary.events += copied.events;
            summary.index = summary.index.or(copied.index);
            on_trial();
        }
    }
    if !outside.is_empty() {
        return Err(ImportError::Problems(outside));
    }
    let no_contact = dir.join(NO_CONTACT_FILE);
    match (&config.no_contact, parts.first()) {
        (Some(NoContact::File(path)), _) => {
            copy_range(path, None, &no_contact)?;
        }
        (Some(NoContact::Range(from, to)), Some(first)) => {
            copy_range(&first.session, Some((*from, *to)), &no_contact)?;
        }
        _ => {}
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
    };
    let report = check::check(dir, inputs, &|_| {});
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
