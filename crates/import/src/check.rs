//! A dataset validated before hours of training (`evtac check`). Every problem is listed, not
//! only the first, each as a [`Problem`]: the file, the line of `trials.csv`, the field, what is
//! wrong and how to fix it.
//!
//! What is checked:
//! - `trials.csv`: the header (missing, unknown or reordered columns), every cell's type
//!   ([`Manifest::parse_rows`]), and the ranges: speed and total tilt above zero, a depth not
//!   below zero, a motion window that ends after it starts, stop columns all set or all empty
//!   with the stop inside the motion and its angle between zero and the total;
//! - every trial recording (and truth file) present and readable to its end
//!   ([`evtac_formats::Summary`]), on a sensor no smaller than the crop;
//! - each recording's event and IMU time spans cover its motion window and the still lead-in
//!   the labels need before it ([`LabelConfig::still_lead_in_us`]), with IMU samples at the rate
//!   the labels' bias needs ([`LabelConfig::min_imu_rate_hz`]) unless the dataset is labelled
//!   from the commanded motion (`label_source.json`, [`LabelSource`]);
//! - `calibration.json` (a rotation; not for labels from the commanded motion) and
//!   `no_contact.aedat4` (readable, with events) present, unless opted out ([`Inputs`]);
//! - Experiment 3's groups: `seen` or `unseen`, on every row or none, one group per speed or per
//!   depth.

use crate::inputs::{IDENTITY_CALIBRATION_FLAG, Inputs, MaskSource, NO_MASK_FLAG};
use evtac_events::layout::{MANIFEST_FILE, NO_CONTACT_FILE};
use evtac_events::manifest::{COLUMNS, Manifest, ManifestError, TrialMeta};
use evtac_formats::Summary;
use evtac_labels::{CalibrationSource, LabelConfig, LabelSource};
use evtac_repr::CROP;
use evtac_sim::Protocol;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One thing wrong with a dataset.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Problem {
    /// The file it is in or about.
    pub file: PathBuf,
    /// The 1-based line of `trials.csv` (the header is line 1), when it is about a row.
    pub line: Option<usize>,
    /// The manifest column (or `header`, `file`, ...), when one is at fault.
    pub field: Option<String>,
    /// What is wrong.
    pub problem: String,
    /// How to fix it.
    pub fix: String,
}

impl Problem {
    fn new(
        file: &Path,
        line: Option<usize>,
        field: Option<&str>,
        problem: String,
        fix: &str,
    ) -> Self {
        Problem {
            file: file.to_path_buf(),
            line,
            field: field.map(str::to_string),
            problem,
            fix: fix.to_string(),
        }
    }
}

/// What [`check`] found.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct CheckReport {
    /// The dataset folders checked, each with its number of trials.
    pub datasets: Vec<(PathBuf, usize)>,
    /// Recordings checked (trials and no-contact recordings).
    pub recordings: usize,
    /// Every problem, dataset by dataset, in manifest order.
    pub problems: Vec<Problem>,
}

/// What [`check`] reports as it goes (for a progress bar).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckProgress {
    /// This many more recordings are to be read.
    Recordings(u64),
    /// One recording has been read.
    Read,
}

/// The dataset folders under `dir`: `dir` itself when it holds `trials.csv`, else the datasets
/// `evtac reproduce --data` reads from it: `exp1/` (required, so checked even when absent) and
/// those of `exp2/`, `exp3-speed/`, `exp3-depth/` that exist.
fn dataset_dirs(dir: &Path) -> Vec<PathBuf> {
    if dir.join(MANIFEST_FILE).is_file() {
        return vec![dir.to_path_buf()];
    }
    // The folders are named after the protocols that fill them (`evtac simulate` lays them out
    // so); `evtac-experiments`' `pipeline::Datasets::in_dir` reads the same.
    let optional = [Protocol::Exp2, Protocol::Exp3Speed, Protocol::Exp3Depth]
        .map(|p| dir.join(p.name()))
        .into_iter()
        .filter(|d| d.join(MANIFEST_FILE).is_file());
    std::iter::once(dir.join(Protocol::Exp1.name()))
        .chain(optional)
        .collect()
}

/// Checks the dataset in `dir` (or each of the datasets `reproduce --data` would read from it)
/// as it would be opened with `inputs`; `progress` follows the recordings read.
pub fn check(
    dir: &Path,
    inputs: &Inputs,
    progress: &(dyn Fn(CheckProgress) + Sync),
) -> CheckReport {
    let mut report = CheckReport::default();
    // A folder that is not there, or holds nothing, is said as such rather than as the first
    // file a dataset would need (`exp1/trials.csv cannot be read`).
    let fix = "give the folder `evtac simulate`, `evtac import` or `reproduce --data` wrote";
    match std::fs::read_dir(dir).map(|mut entries| entries.next().is_none()) {
        Err(e) => {
            let problem = match e.kind() {
                std::io::ErrorKind::NotFound => "the folder does not exist".to_string(),
                _ => format!("the folder cannot be read: {e}"),
            };
            report
                .problems
                .push(Problem::new(dir, None, None, problem, fix));
            return report;
        }
        Ok(true) => {
            let problem = "the folder is empty: no trials.csv and no dataset folders".to_string();
            report
                .problems
                .push(Problem::new(dir, None, None, problem, fix));
            return report;
        }
        Ok(false) => {}
    }
    for ds in dataset_dirs(dir) {
        check_dataset(&ds, inputs, progress, &mut report);
    }
    report
}

fn check_dataset(
    dir: &Path,
    inputs: &Inputs,
    progress: &(dyn Fn(CheckProgress) + Sync),
    report: &mut CheckReport,
) {
    let manifest_path = Manifest::path(dir);
    let rows = match std::fs::read_to_string(&manifest_path) {
        Ok(text) => Manifest::parse_rows(&text, &manifest_path),
        Err(e) => {
            report.problems.push(Problem::new(
                &manifest_path,
                None,
                None,
                format!("cannot be read: {e}"),
                "write the manifest: one row per trial with the columns of evtac_events::manifest",
            ));
            report.datasets.push((dir.to_path_buf(), 0));
            return;
        }
    };
    let first_problem = report.problems.len();
    let problems = &mut report.problems;
    problems.extend(
        rows.errors
            .iter()
            .map(|e| manifest_problem(&manifest_path, e)),
    );
    if rows.trials.is_empty() && rows.errors.is_empty() {
        problems.push(Problem::new(
            &manifest_path,
            None,
            None,
            "lists no trials".into(),
            "add one row per trial",
        ));
    }
    for (line, meta) in &rows.trials {
        problems.extend(range_problems(&manifest_path, *line, meta));
    }
    problems.extend(group_problems(&manifest_path, &rows.trials));
    let source = LabelSource::of(dir).unwrap_or_else(|e| {
        problems.push(Problem::new(
            &LabelSource::path(dir),
            None,
            None,
            e.to_string(),
            r#"write {"labels": "commanded"} to label from the robot's log, or delete the file to label from the IMU"#,
        ));
        LabelSource::Imu
    });
    // Labels from the commanded motion use no IMU, so no calibration to rotate it.
    if source == LabelSource::Imu {
        problems.extend(calibration_problems(dir, inputs));
    }

    let with_no_contact =
        inputs.mask == MaskSource::NoContact && dir.join(NO_CONTACT_FILE).is_file();
    progress(CheckProgress::Recordings(
        rows.trials.len() as u64 + u64::from(with_no_contact),
    ));
    let labels = LabelConfig::default();
    let per_trial: Vec<Vec<Problem>> = rows
        .trials
        .par_iter()
        .map(|(line, meta)| {
            let found = recording_problems(dir, *line, meta, &labels, source);
            progress(CheckProgress::Read);
            found
        })
        .collect();
    report.recordings += per_trial.len();
    report.problems.extend(per_trial.into_iter().flatten());
    report.problems.extend(no_contact_problems(dir, inputs));
    if with_no_contact {
        report.recordings += 1;
        progress(CheckProgress::Read);
    }
    // The dataset's own problems first, then row by row (stable: each row's in check order).
    report.problems[first_problem..].sort_by_key(|p| p.line.unwrap_or(0));
    report.datasets.push((dir.to_path_buf(), rows.trials.len()));
}

/// How to fix a bad cell of `column`.
fn cell_fix(column: &str) -> &'static str {
    match column {
        "trial" => "a unique name without commas or quotes",
        "file" | "truth" => "a path relative to the dataset folder, without commas or quotes",
        "group" => "seen or unseen (Experiment 3), or empty",
        c if c.ends_with("_us") => "an integer: microseconds on the recording's clock",
        _ => "a finite number",
    }
}

fn manifest_problem(path: &Path, e: &ManifestError) -> Problem {
    match e {
        ManifestError::Header { found, .. } => {
            let found: Vec<&str> = found.split(',').map(str::trim).collect();
            let missing: Vec<&str> = COLUMNS
                .iter()
                .copied()
                .filter(|c| !found.contains(c))
                .collect();
            let unknown: Vec<&str> = found
                .iter()
                .copied()
                .filter(|c| !COLUMNS.contains(c))
                .collect();
            let mut what = Vec::new();
            if !missing.is_empty() {
                what.push(format!("missing columns {}", missing.join(", ")));
            }
            if !unknown.is_empty() {
                what.push(format!("unknown columns {}", unknown.join(", ")));
            }
            if what.is_empty() {
                what.push("the columns are out of order".into());
            }
            Problem::new(
                path,
                Some(1),
                Some("header"),
                what.join("; "),
                &format!("the header must be exactly `{}`", COLUMNS.join(",")),
            )
        }
        ManifestError::CellCount {
            line,
            expected,
            found,
            ..
        } => Problem::new(
            path,
            Some(*line),
            None,
            format!("{found} cells, {expected} expected"),
            "one cell per column; leave optional cells empty",
        ),
        ManifestError::Cell {
            line,
            column,
            value,
            reason,
            ..
        } => Problem::new(
            path,
            Some(*line),
            Some(column),
            format!("`{value}`: {reason}"),
            cell_fix(column),
        ),
        ManifestError::DuplicateTrial {
            line,
            first_line,
            trial,
            ..
        } => Problem::new(
            path,
            Some(*line),
            Some("trial"),
            format!("`{trial}` is already on line {first_line}"),
            "give every trial its own name",
        ),
        other => Problem::new(path, None, None, other.to_string(), "fix the manifest"),
    }
}

/// The range checks of one manifest row.
pub(crate) fn range_problems(path: &Path, line: usize, t: &TrialMeta) -> Vec<Problem> {
    let mut out = Vec::new();
    let mut bad = |field: &str, problem: String, fix: &str| {
        out.push(Problem::new(path, Some(line), Some(field), problem, fix));
    };
    // (column, value, whether zero is allowed, what the column means)
    let limits = [
        (
            "speed_deg_s",
            t.speed_deg_s,
            false,
            "the commanded tilt speed, deg/s",
        ),
        (
            "total_deg",
            t.total_deg,
            false,
            "the commanded final tilt, degrees",
        ),
        ("depth_mm", t.depth_mm, true, "the indentation depth, mm"),
    ];
    for (field, v, zero_ok, fix) in limits {
        if v < 0.0 || (v == 0.0 && !zero_ok) {
            let limit = if zero_ok {
                "below zero"
            } else {
                "not above zero"
            };
            bad(field, format!("{v} is {limit}"), fix);
        }
    }
    if t.motion_end_us <= t.motion_start_us {
        bad(
            "motion_end_us",
            format!(
                "{} is not after motion_start_us {}",
                t.motion_end_us, t.motion_start_us
            ),
            "the time the final tilt is reached, after the onset",
        );
    }
    let stop = [
        ("stop_start_us", t.stop_start_us.is_some()),
        ("stop_end_us", t.stop_end_us.is_some()),
        ("stop_deg", t.stop_deg.is_some()),
    ];
    if stop.iter().any(|s| s.1) {
        for (field, _) in stop.iter().filter(|s| !s.1) {
            bad(
                field,
                "empty while other stop columns are set".into(),
                "set stop_start_us, stop_end_us and stop_deg together, or none of them",
            );
        }
    }
    if let (Some(a), Some(b)) = (t.stop_start_us, t.stop_end_us)
        && !(t.motion_start_us <= a && a < b && b <= t.motion_end_us)
    {
        bad(
            "stop_start_us",
            format!(
                "the stop {a} .. {b} us is not a non-empty part of the motion {} .. {} us",
                t.motion_start_us, t.motion_end_us
            ),
            "the stop must start and end inside the motion window",
        );
    }
    if let Some(d) = t.stop_deg
        && !(d > 0.0 && d < t.total_deg)
    {
        bad(
            "stop_deg",
            format!("{d} is not between 0 and total_deg {}", t.total_deg),
            "the commanded tilt at which the sensor stops, degrees",
        );
    }
    out
}

/// Experiment 3's groups: `seen` / `unseen`, on every row or none, one group per value of the
/// axis the dataset varies (Experiment 3 reads the group of the first trial at each value).
fn group_problems(path: &Path, trials: &[(usize, TrialMeta)]) -> Vec<Problem> {
    let mut out = Vec::new();
    if trials.iter().all(|(_, t)| t.group.is_none()) {
        return out;
    }
    for (line, t) in trials {
        match t.group.as_deref() {
            Some("seen" | "unseen") => {}
            Some(g) => out.push(Problem::new(
                path,
                Some(*line),
                Some("group"),
                format!("`{g}` is neither seen nor unseen"),
                cell_fix("group"),
            )),
            None => out.push(Problem::new(
                path,
                Some(*line),
                Some("group"),
                "empty while other rows have a group".into(),
                "give every row of an Experiment 3 dataset a group, or none",
            )),
        }
    }
    // Groups per value (in thousandths, as Experiment 3 keys them), for each axis.
    type Axis = (&'static str, &'static str, fn(&TrialMeta) -> f64);
    let axes: [Axis; 2] = [
        ("speed_deg_s", "deg/s", |t| t.speed_deg_s),
        ("depth_mm", "mm", |t| t.depth_mm),
    ];
    let conflicts: Vec<Vec<Problem>> = axes
        .iter()
        .map(|(field, unit, value)| {
            let mut first: BTreeMap<i64, (usize, &str)> = BTreeMap::new();
            let mut found = Vec::new();
            for (line, t) in trials {
                // Rows without a valid group are reported above.
                let Some(g @ ("seen" | "unseen")) = t.group.as_deref() else {
                    continue;
                };
                let key = (value(t) * 1000.0).round() as i64;
                let (first_line, first_group) = *first.entry(key).or_insert((*line, g));
                if first_group != g {
                    found.push(Problem::new(
                        path,
                        Some(*line),
                        Some("group"),
                        format!(
                            "{g} at {field} = {} {unit}, but line {first_line} at the same value \
                             is {first_group}",
                            value(t)
                        ),
                        "one group per value of the varied axis (speed or depth)",
                    ));
                }
            }
            found
        })
        .collect();
    // Consistent along one axis is enough: that is the axis the dataset varies.
    if conflicts.iter().all(|c| !c.is_empty())
        && let Some(fewest) = conflicts.into_iter().min_by_key(Vec::len)
    {
        out.extend(fewest);
    }
    out
}

fn calibration_problems(dir: &Path, inputs: &Inputs) -> Vec<Problem> {
    if inputs.calibration == CalibrationSource::Identity {
        return Vec::new();
    }
    let path = dir.join(evtac_events::layout::CALIBRATION_FILE);
    match evtac_labels::read_calibration(dir) {
        Ok(_) => Vec::new(),
        Err(evtac_labels::Error::MissingCalibration { .. }) => vec![Problem::new(
            &path,
            None,
            None,
            "missing".into(),
            &format!(
                "write the IMU-to-sensor rotation there, or pass --{IDENTITY_CALIBRATION_FLAG} \
                 (here and to the commands that read the dataset) if the IMU's axes are the \
                 sensor's"
            ),
        )],
        Err(e) => vec![Problem::new(
            &path,
            None,
            None,
            e.to_string(),
            "a JSON object with imu_to_sensor (a 3x3 rotation) and tip_radius_mm",
        )],
    }
}

fn no_contact_problems(dir: &Path, inputs: &Inputs) -> Vec<Problem> {
    if inputs.mask == MaskSource::Unmasked {
        return Vec::new();
    }
    let path = dir.join(NO_CONTACT_FILE);
    let fix = format!(
        "record the sensor for a few seconds without contact, or pass --{NO_MASK_FLAG} (here and \
         to the commands that read the dataset) to run without a mask"
    );
    if !path.is_file() {
        return vec![Problem::new(&path, None, None, "missing".into(), &fix)];
    }
    match Summary::of_file(&path) {
        Err(e) => vec![Problem::new(
            &path,
            None,
            None,
            format!("unreadable: {e}"),
            &fix,
        )],
        Ok(s) if s.events == 0 => vec![Problem::new(&path, None, None, "no events".into(), &fix)],
        Ok(s) => sensor_problems(&path, None, &s),
    }
}

/// A sensor smaller than the crop.
fn sensor_problems(path: &Path, line: Option<usize>, s: &Summary) -> Vec<Problem> {
    match (s.width, s.height) {
        (Some(w), Some(h)) if w < CROP.width || h < CROP.height => vec![Problem::new(
            path,
            line,
            Some("file"),
            format!("the sensor is {w}x{h}, smaller than the {CROP} crop"),
            "record with a sensor of at least the crop's size",
        )],
        _ => Vec::new(),
    }
}

/// The problems of one trial's files: present, readable, long enough, IMU fast enough (when the
/// labels come from the IMU).
fn recording_problems(
    dir: &Path,
    line: usize,
    t: &TrialMeta,
    labels: &LabelConfig,
    source: LabelSource,
) -> Vec<Problem> {
    let mut out = Vec::new();
    if let Some(truth) = &t.truth
        && !dir.join(truth).is_file()
    {
        out.push(Problem::new(
            &dir.join(truth),
            Some(line),
            Some("truth"),
            "missing".into(),
            "correct the truth column, or leave it empty (real recordings have no truth)",
        ));
    }
    let path = dir.join(&t.file);
    let here = |field: &str, problem: String, fix: &str| {
        Problem::new(&path, Some(line), Some(field), problem, fix)
    };
    if !path.is_file() {
        out.push(here(
            "file",
            "missing".into(),
            "put the recording there, or correct the file column",
        ));
        return out;
    }
    let s = match Summary::of_file(&path) {
        Ok(s) => s,
        Err(e) => {
            out.push(here(
                "file",
                format!("unreadable: {e}"),
                "re-export the recording, or remove the trial",
            ));
            return out;
        }
    };
    out.extend(sensor_problems(&path, Some(line), &s));
    let lead = labels.still_lead_in_us();
    let (from, to) = (t.motion_start_us.saturating_sub(lead), t.motion_end_us);
    let mut streams = vec![("events", s.first_t_us, s.last_t_us, s.events)];
    if source == LabelSource::Imu {
        streams.push((
            "IMU samples",
            s.first_imu_t_us,
            s.last_imu_t_us,
            s.imu_samples,
        ));
    }
    for (stream, first, last, count) in streams {
        let (Some(first), Some(last)) = (first, last) else {
            let (why, fix) = if stream == "events" {
                (
                    "the representations are built from them",
                    "record with the camera's events enabled",
                )
            } else {
                (
                    "the labels come from the IMU",
                    "record with the camera's IMU enabled, or import with --labels commanded to \
                     label from the robot's log",
                )
            };
            out.push(here("file", format!("no {stream} ({count}): {why}"), fix));
            continue;
        };
        if first > from || last < to {
            // The field to correct: the onset when the start is not covered, else the end.
            let field = if first > from {
                "motion_start_us"
            } else {
                "motion_end_us"
            };
            out.push(here(
                field,
                format!(
                    "the {stream} span {first} .. {last} us, which does not cover {from} .. {to} \
                     us (the motion window and the {} ms still lead-in before it)",
                    lead / 1000
                ),
                &format!(
                    "times are on the recording's clock: correct motion_start_us and \
                     motion_end_us, or record at least {} ms of still sensor before each motion \
                     and until it ends",
                    lead / 1000
                ),
            ));
        }
    }
    let min_rate = labels.min_imu_rate_hz();
    if let Some(rate) = s.imu_rate_hz.filter(|_| source == LabelSource::Imu)
        && rate < min_rate
    {
        out.push(here(
            "file",
            format!(
                "IMU at {rate:.1} Hz: the labels need at least {min_rate:.0} Hz ({} samples in \
                 the {} ms still segment)",
                labels.min_stationary_samples,
                labels.min_stationary_us / 1000
            ),
            "raise the IMU's output rate in the recording software",
        ));
    }
    out
}
