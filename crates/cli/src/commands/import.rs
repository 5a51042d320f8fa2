//! `evtac import`: a recording session and the robot's log of its motions in (or without a log,
//! the motions found in its gyroscope: `evtac_import::motions`), a dataset folder out (one
//! AEDAT4 per trial, `trials.csv`, and the no-contact recording and calibration when given),
//! written into a temporary folder and renamed at the end. The work is
//! `evtac_import::import`'s.

use anyhow::Context;
use evtac_events::Trigger;
use evtac_events::layout::{CALIBRATION_FILE, LABEL_SOURCE_FILE, NO_CONTACT_FILE};
use evtac_import::import::{
    DEFAULT_POST_MS, DEFAULT_PRE_MS, ImportConfig, NoContact, Part, import_parts,
};
use evtac_import::inputs::{IDENTITY_CALIBRATION_FLAG, NO_MASK_FLAG};
use evtac_import::motions::{self, FoundMotion};
use evtac_import::robot_log::RobotLog;
use evtac_import::sync::{Sync, synchronise};
use evtac_import::trial_folder::{split_by_file, trial_files};
use evtac_labels::LabelSource;
use evtac_labels::geometry::Calibration;
use std::path::{Path, PathBuf};

/// How `evtac import` puts the log on the recording's clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SyncMode {
    /// Recording time = robot time + --clock-offset-us.
    Offset,
    /// The k-th trigger (of --trigger-kind) marks the k-th motion's onset: one offset per row.
    Trigger,
    /// The offset that best aligns the gyroscope's rate magnitude with the log's commanded
    /// rate (reported with the fit's residual).
    Imu,
}

/// Arguments of `evtac import`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The session recordings (AEDAT4 with a data table is read fastest; any format evtac
    /// reads), or folders of per-trial files (their .aedat4/.aedat/.bag/.mcap files, a log's
    /// rows cut from the file named after their trial): all go into one dataset.
    #[arg(required = true, num_args = 1.., value_name = "SESSION")]
    pub sessions: Vec<PathBuf>,
    /// The robot's log: a CSV with the manifest's columns except file and truth, one row per
    /// motion (trial, direction_deg, speed_deg_s, depth_mm, total_deg, motion_start_us,
    /// motion_end_us; optionally stop_start_us, stop_end_us, stop_deg, group). Without it the
    /// motions are found in the gyroscope (needs --calibration and --depth-mm) and listed for
    /// review in DIR/motions.csv. With several sessions, one --log per session, in the same
    /// order.
    #[arg(long, value_name = "LOG.csv")]
    pub log: Vec<PathBuf>,
    /// Without --log: the indentation depth written for every motion, mm (the gyroscope cannot
    /// see it).
    #[arg(long, value_name = "MM", conflicts_with = "log")]
    pub depth_mm: Option<f64>,
    /// Without --log: directions are rounded to multiples of this, degrees (0: not rounded).
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "DEG",
        conflicts_with = "log"
    )]
    pub direction_step_deg: f64,
    /// Without --log: speeds are rounded to multiples of this, deg/s (0: not rounded).
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "DEG_S",
        conflicts_with = "log"
    )]
    pub speed_step_deg_s: f64,
    /// Without --log: total tilts are rounded to multiples of this, degrees (0: not rounded).
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "DEG",
        conflicts_with = "log"
    )]
    pub total_step_deg: f64,
    /// Put this before the trial names of each session (one per session, in order; e.g.
    /// `--trial-prefix s0_ --trial-prefix s1_`), for sessions whose logs reuse names.
    #[arg(long, value_name = "PREFIX")]
    pub trial_prefix: Vec<String>,
    /// The dataset folder to write (must not exist).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// How the log's times are put on the recording's clock: offset (add --clock-offset-us),
    /// trigger (the k-th trigger marks the k-th motion's onset) or imu (the offset that best
    /// aligns the gyroscope with the commanded rate).
    #[arg(long, value_enum, default_value_t = SyncMode::Offset)]
    pub sync: SyncMode,
    /// Added to the log's times to put them on the recording's clock, microseconds (for a log
    /// on the robot's clock; --sync offset).
    #[arg(
        long,
        default_value_t = 0,
        allow_negative_numbers = true,
        value_name = "N"
    )]
    pub clock_offset_us: i64,
    /// The trigger type code that marks a motion's onset with --sync trigger (DV: 1 external
    /// rising edge, 2 falling edge, 3 pulse).
    #[arg(long, default_value_t = Trigger::RISING_EDGE, value_name = "CODE")]
    pub trigger_kind: i8,
    /// Kept before each motion's onset, ms (cut at the previous motion's end).
    #[arg(long, default_value_t = DEFAULT_PRE_MS)]
    pub pre_ms: u64,
    /// Kept after each motion's end, ms.
    #[arg(long, default_value_t = DEFAULT_POST_MS)]
    pub post_ms: u64,
    /// A recording of the sensor without contact (for the static representation's mask).
    #[arg(long, value_name = "FILE", conflicts_with = "no_contact_range")]
    pub no_contact: Option<PathBuf>,
    /// The time range A..B of the (first) session in which the sensor is out of contact,
    /// written as the no-contact recording. With units (`0s..2s`, `500ms..1500ms`,
    /// `0us..2000000us`) the times count from the recording's first event; plain numbers are
    /// microseconds on the recording's clock, as `evtac info` prints them.
    #[arg(long, value_name = "A..B", value_parser = parse_range)]
    pub no_contact_range: Option<TimeRange>,
    /// The IMU-to-sensor rotation (a calibration.json), copied into the dataset.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
    /// Where the dataset's labels come from: imu (the paper's: the gyroscope, integrated; every
    /// recording must hold an IMU) or commanded (the robot's commanded motion from the log's
    /// times, for recordings without an IMU: AEDAT 2.0, EVT raw, CSV, NPY, NPZ, HDF5, the lab's
    /// pickles; written to
    /// label_source.json, so every command labels the dataset this way).
    #[arg(long, value_enum, default_value_t = LabelsArg::Imu, value_name = "SOURCE")]
    pub labels: LabelsArg,
    // Every written recording (each trial, the no-contact recording) goes through these, each
    // file on its own from its first event (the trial's --pre-ms gives them their history).
    #[command(flatten)]
    pub filter: crate::filtering::FilterArgs,
}

/// `--labels`: [`LabelSource`] on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LabelsArg {
    /// From the IMU's gyroscope (the paper's labels).
    Imu,
    /// From the robot's commanded motion (recordings without an IMU).
    Commanded,
}

impl From<LabelsArg> for LabelSource {
    fn from(a: LabelsArg) -> Self {
        match a {
            LabelsArg::Imu => LabelSource::Imu,
            LabelsArg::Commanded => LabelSource::Commanded,
        }
    }
}

/// Where a log-free import lists what it found, in the dataset folder.
const REVIEW_FILE: &str = "motions.csv";

/// What a log-free import needs: the calibration, and how motions are found and rounded.
fn find_config(args: &Args) -> anyhow::Result<(Calibration, motions::FindConfig)> {
    let calibration_path = args.calibration.as_ref().context(
        "without --log, --calibration is needed: the tilt's direction is read in the sensor frame",
    )?;
    let depth_mm = args.depth_mm.context(
        "without --log, --depth-mm is needed: the gyroscope cannot see the indentation depth",
    )?;
    let calibration = evtac_labels::read_calibration_file(calibration_path)?;
    let config = motions::FindConfig {
        direction_step_deg: args.direction_step_deg,
        speed_step_deg_s: args.speed_step_deg_s,
        total_step_deg: args.total_step_deg,
        ..motions::FindConfig::new(depth_mm)
    };
    Ok((calibration, config))
}

/// The motions in the gyroscope of `file`, read as the search goes (memory bounded by the
/// longest motion, not the session).
fn found_motions(
    file: &Path,
    (calibration, config): &(Calibration, motions::FindConfig),
) -> anyhow::Result<Vec<FoundMotion>> {
    Ok(motions::find_motions_in(file, calibration, config)?.found)
}

/// The motions found in `file`, as a table.
fn print_found(file: &Path, found: &[FoundMotion]) {
    println!(
        "{} motions found in the gyroscope of {}:",
        found.len(),
        file.display()
    );
    println!("trial  onset_us              duration_s  direction  speed  total  review");
    for m in found {
        let t = &m.meta;
        println!(
            "{}  {:<20}  {:>10.3}  {:>9}  {:>5}  {:>5}  {}",
            t.trial,
            t.motion_start_us,
            (t.motion_end_us - t.motion_start_us) as f64 * 1e-6,
            t.direction_deg,
            t.speed_deg_s,
            t.total_deg,
            motions::review_note(m)
        );
    }
}

/// Motions found in the gyroscope, each with the recording it was found in.
type Found = Vec<(PathBuf, FoundMotion)>;

/// The recordings and logs to import: each session with its log (put on its clock by --sync),
/// each folder split by its log's trials, or without logs the motions found in every file
/// (returned for review too).
fn parts(args: &Args, sync: Sync) -> anyhow::Result<(Vec<Part>, Found)> {
    anyhow::ensure!(
        args.trial_prefix.is_empty() || args.trial_prefix.len() == args.sessions.len(),
        "{} sessions and {} --trial-prefix: give one per session, in the same order",
        args.sessions.len(),
        args.trial_prefix.len()
    );
    let (mut parts, found) = parts_unprefixed(args, sync)?;
    if !args.trial_prefix.is_empty() {
        for part in &mut parts {
            let k = args
                .sessions
                .iter()
                .position(|s| part.session == *s || part.session.starts_with(s))
                .context("a part of no session")?;
            part.log.prefix_trials(&args.trial_prefix[k]);
        }
    }
    Ok((parts, found))
}

fn parts_unprefixed(args: &Args, sync: Sync) -> anyhow::Result<(Vec<Part>, Found)> {
    let mut parts = Vec::new();
    let mut found_all = Vec::new();
    if args.log.is_empty() {
        anyhow::ensure!(
            args.sync == SyncMode::Offset && args.clock_offset_us == 0,
            "--sync and --clock-offset-us put a log on the recording's clock: without --log \
             the motions are found on it"
        );
        let config = find_config(args)?;
        // A session's motions are numbered on across the sessions (m0000, m0001, ...); a
        // folder's files are trials, each named after its file, and a file without a motion
        // (the no-contact recording) is passed over.
        let mut numbered = 0;
        for session in &args.sessions {
            let in_folder = session.is_dir();
            let files = if in_folder {
                trial_files(session, true)?
            } else {
                vec![session.clone()]
            };
            for file in files {
                let mut found = found_motions(&file, &config)?;
                if found.is_empty() && in_folder {
                    println!(
                        "{}: no motion in its gyroscope, passed over",
                        file.display()
                    );
                    continue;
                }
                anyhow::ensure!(
                    !found.is_empty(),
                    "{}: no motion found in its gyroscope (a tilt of at least {} deg/s for {} \
                     ms, with gravity turning)",
                    file.display(),
                    config.1.threshold_deg_s,
                    config.1.min_motion_us / 1000
                );
                if in_folder {
                    let stem = file.file_stem().unwrap_or_default().to_string_lossy();
                    motions::name_after(&mut found, &stem);
                } else {
                    motions::number_from(&mut found, numbered);
                    numbered += found.len();
                }
                print_found(&file, &found);
                parts.push(Part {
                    session: file.clone(),
                    log: motions::as_log(&file, &found),
                });
                found_all.extend(found.into_iter().map(|m| (file.clone(), m)));
            }
        }
        return Ok((parts, found_all));
    }
    anyhow::ensure!(
        args.log.len() == args.sessions.len(),
        "{} sessions and {} logs: give one --log per session, in the same order (or none, to \
         find the motions in the gyroscope)",
        args.sessions.len(),
        args.log.len()
    );
    for (session, log) in args.sessions.iter().zip(&args.log) {
        if session.is_dir() {
            anyhow::ensure!(
                args.sync == SyncMode::Offset,
                "{}: a folder of trials is cut on each file's clock: --sync {} is for a session",
                session.display(),
                clap::ValueEnum::to_possible_value(&args.sync)
                    .map_or_else(String::new, |v| v.get_name().to_string())
            );
            let log = RobotLog::read_per_trial(log, args.clock_offset_us)?;
            parts.extend(split_by_file(&log, &trial_files(session, false)?)?);
            continue;
        }
        let synced = synchronise(session, RobotLog::read(log, 0)?, sync)?;
        if let (SyncMode::Trigger, Some([lo, median, hi])) = (args.sync, synced.offset_range()) {
            eprintln!(
                "{}: clock offsets from the triggers: median {median} us, {lo} .. {hi} us over \
                 {} rows",
                session.display(),
                synced.offsets.len()
            );
        }
        if let (Some(residual), Some([_, offset, _])) =
            (synced.residual_deg_s, synced.offset_range())
        {
            eprintln!(
                "{}: clock offset from the IMU: {offset} us (gyroscope rate vs the commanded \
                 rate: {residual:.3} deg/s RMS)",
                session.display()
            );
        }
        parts.push(Part {
            session: session.clone(),
            log: synced.log,
        });
    }
    Ok((parts, found_all))
}

/// A time range as given: microseconds on the recording's clock, or (with units) from the
/// recording's first event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimeRange {
    /// Start, microseconds.
    pub from: i64,
    /// End, microseconds.
    pub to: i64,
    /// Whether both count from the recording's first event.
    pub from_start: bool,
}

impl TimeRange {
    /// The range on the recording's clock, for a recording whose first event is at `start`.
    fn on_clock(self, start: impl FnOnce() -> anyhow::Result<i64>) -> anyhow::Result<(i64, i64)> {
        if !self.from_start {
            return Ok((self.from, self.to));
        }
        let start = start()?;
        Ok((start + self.from, start + self.to))
    }
}

/// One bound: `(value, with a unit)` in microseconds.
fn parse_time(s: &str) -> Option<(i64, bool)> {
    let s = s.trim();
    let (number, scale) = if let Some(n) = s.strip_suffix("us") {
        (n, Some(1.0))
    } else if let Some(n) = s.strip_suffix("ms") {
        (n, Some(1e3))
    } else if let Some(n) = s.strip_suffix('s') {
        (n, Some(1e6))
    } else {
        (s, None)
    };
    match scale {
        None => number.parse::<i64>().ok().map(|v| (v, false)),
        Some(scale) => {
            let v: f64 = number.trim().parse().ok()?;
            let us = (v * scale).round();
            (us.is_finite() && us.abs() < 9e18).then_some((us as i64, true))
        }
    }
}

fn parse_range(s: &str) -> Result<TimeRange, String> {
    let bad = || {
        format!(
            "`{s}` is not a range A..B with A < B: microseconds on the recording's clock \
             (1605537493900000..1605537495900000), or with units from its first event (0s..2s)"
        )
    };
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let ((from, unit_a), (to, unit_b)) = (
        parse_time(a).ok_or_else(bad)?,
        parse_time(b).ok_or_else(bad)?,
    );
    if unit_a != unit_b {
        return Err(format!(
            "`{s}`: give both ends with units (from the recording's first event) or both as \
             plain microseconds (on its clock)"
        ));
    }
    if from < to {
        Ok(TimeRange {
            from,
            to,
            from_start: unit_a,
        })
    } else {
        Err(bad())
    }
}

/// The time of the first event of `session`.
fn first_event_us(session: &std::path::Path) -> anyhow::Result<i64> {
    let mut reader = evtac_formats::open(session)?;
    while let Some(chunk) = reader.next_chunk()? {
        if let Some(e) = chunk.events.first() {
            return Ok(e.t);
        }
    }
    anyhow::bail!(
        "{}: no events, so no start to count --no-contact-range from",
        session.display()
    )
}

/// Runs `evtac import`.
pub fn run(args: Args) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.sync == SyncMode::Offset || args.clock_offset_us == 0,
        "--clock-offset-us is for --sync offset: --sync {} finds the offsets itself",
        clap::ValueEnum::to_possible_value(&args.sync)
            .map_or_else(String::new, |v| v.get_name().to_string())
    );
    let sync = match args.sync {
        SyncMode::Offset => Sync::Offset(args.clock_offset_us),
        SyncMode::Trigger => Sync::Trigger(args.trigger_kind),
        SyncMode::Imu => Sync::Imu,
    };
    let (parts, found) = parts(&args, sync)?;
    let config = ImportConfig {
        pre_us: i64::try_from(args.pre_ms)
            .ok()
            .and_then(|ms| ms.checked_mul(1000))
            .context("--pre-ms is too large")?,
        post_us: i64::try_from(args.post_ms)
            .ok()
            .and_then(|ms| ms.checked_mul(1000))
            .context("--post-ms is too large")?,
        no_contact: match (&args.no_contact, args.no_contact_range) {
            (Some(file), _) => Some(NoContact::File(file.clone())),
            (None, Some(range)) => {
                let (a, b) = range.on_clock(|| first_event_us(&args.sessions[0]))?;
                Some(NoContact::Range(a, b))
            }
            (None, None) => None,
        },
        calibration: args.calibration.clone(),
        labels: args.labels.into(),
        filters: args.filter.filters.clone(),
    };
    let trials = parts.iter().map(|p| p.log.rows.len()).sum::<usize>();
    let sources = args
        .sessions
        .iter()
        .map(|s| s.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let bar = crate::progress::bar(trials as u64, "trials");
    let summary = import_parts(&parts, &args.out, &config, &|| bar.inc(1))
        .with_context(|| format!("importing {sources}"))?;
    bar.finish_and_clear();
    if let Some(reason) = summary.index.as_ref().and_then(|i| i.fallback()) {
        eprintln!("note: the recordings were read from their start for every trial: {reason}");
    }
    args.filter.say_removed(&summary.removed);
    println!(
        "imported {} trials ({} events) from {sources} into {}",
        summary.trials,
        summary.events,
        summary.out.display()
    );
    if !found.is_empty() {
        let review = summary.out.join(REVIEW_FILE);
        crate::outputs::write_text(&review, &motions::review_csv(&found))?;
        println!("the motions as found, for review: {}", review.display());
    }
    if config.labels == LabelSource::Commanded {
        println!(
            "labels: from the commanded motion (the log's times), not from an IMU: written to {}",
            summary.out.join(LABEL_SOURCE_FILE).display()
        );
    } else if config.calibration.is_none() {
        println!(
            "no calibration given: add {}, or pass --{IDENTITY_CALIBRATION_FLAG} to the commands \
             that read the dataset",
            summary.out.join(CALIBRATION_FILE).display()
        );
    }
    if config.no_contact.is_none() {
        println!(
            "no no-contact recording given: add {}, or pass --{NO_MASK_FLAG} to the commands \
             that read the dataset",
            summary.out.join(NO_CONTACT_FILE).display()
        );
    }
    Ok(())
}
