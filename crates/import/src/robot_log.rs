//! The robot's log of a recording session, as `evtac import` reads it: a CSV with a header row
//! and one row per commanded motion, holding the manifest's columns except `file` and `truth`
//! ([`FILLED_IN`]: the import fills those in), in any order. Required: `trial`, `direction_deg`,
//! `speed_deg_s`, `depth_mm`, `total_deg`, `motion_start_us`, `motion_end_us`; optional:
//! `stop_start_us`, `stop_end_us`, `stop_deg`, `group`. Times are on the recording's clock, or on
//! the robot's when a clock offset is given (recording time = robot time + offset).
//!
//! The cells are read by the manifest's own reader (each log row becomes a manifest row on the
//! same line), so a bad cell is the same error as in `trials.csv`, naming the log's line and
//! column; the ranges are `evtac check`'s; and motions must not overlap.

use crate::check::range_problems;
use evtac_events::layout::trial_file;
use evtac_events::manifest::{COLUMNS, Manifest, ManifestError, NOT_IN_LOG, TrialMeta};
use std::path::{Path, PathBuf};

/// The manifest's columns a log does not have: the import fills them in.
pub const FILLED_IN: [&str; 2] = NOT_IN_LOG;

/// The columns a log may have.
pub const OPTIONAL: [&str; 4] = ["stop_start_us", "stop_end_us", "stop_deg", "group"];

/// The columns a log must have: the manifest's but [`FILLED_IN`] and [`OPTIONAL`].
pub fn required_columns() -> Vec<&'static str> {
    COLUMNS
        .into_iter()
        .filter(|c| !FILLED_IN.contains(c) && !OPTIONAL.contains(c))
        .collect()
}

/// Errors reading a log; each names the log, its line and the column at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LogError {
    /// The log could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The log.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A required column is missing from the header.
    #[error(
        "{}:1: column `{column}` is missing (a log needs {})",
        path.display(),
        required_columns().join(", ")
    )]
    MissingColumn {
        /// The log.
        path: PathBuf,
        /// The missing column.
        column: &'static str,
    },
    /// The header names a column a log does not have.
    #[error(
        "{}:1: unknown column `{column}` (a log has {} and optionally {}; the import names the \
         files)",
        path.display(),
        required_columns().join(", "),
        OPTIONAL.join(", ")
    )]
    UnknownColumn {
        /// The log.
        path: PathBuf,
        /// The column.
        column: String,
    },
    /// The header names a column twice.
    #[error("{}:1: column `{column}` appears twice", path.display())]
    RepeatedColumn {
        /// The log.
        path: PathBuf,
        /// The column.
        column: String,
    },
    /// A bad cell, a wrong number of cells or a repeated trial name.
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    /// A row's values are out of range or its motion overlaps another.
    #[error("{}:{line}: column `{column}`: {reason}", path.display())]
    Row {
        /// The log.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// The column.
        column: String,
        /// What is wrong and how to fix it.
        reason: String,
    },
}

/// A parsed log: one trial per row, with its line, on the recording's clock.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotLog {
    /// The log file.
    pub path: PathBuf,
    /// The rows in log order: the 1-based line and the trial (its `file` is
    /// [`trial_file`]`(trial)`, its `truth` empty).
    pub rows: Vec<(usize, TrialMeta)>,
}

impl RobotLog {
    /// Puts `prefix` before every trial's name (and so its file's): two sessions whose logs
    /// both name `t0000` go into one dataset as `s0_t0000` and `s1_t0000`.
    pub fn prefix_trials(&mut self, prefix: &str) {
        for (_, t) in &mut self.rows {
            t.trial = format!("{prefix}{}", t.trial);
            t.file = trial_file(&t.trial).into();
        }
    }

    /// Reads the log at `path`, shifting its times by `clock_offset_us`.
    pub fn read(path: &Path, clock_offset_us: i64) -> Result<Self, LogError> {
        Self::parse(&read_text(path)?, path, clock_offset_us)
    }

    /// Reads the log at `path` of a folder of per-trial files, shifting its times by
    /// `clock_offset_us`: each row is on its own trial file's clock, so rows of different
    /// trials may overlap (the rows of one file are checked with [`Self::check_overlaps`] once
    /// split by file).
    pub fn read_per_trial(path: &Path, clock_offset_us: i64) -> Result<Self, LogError> {
        Self::parse_rows(&read_text(path)?, path, clock_offset_us)
    }

    /// Parses log text (`path` names it in errors), shifting its times by `clock_offset_us`.
    pub fn parse(text: &str, path: &Path, clock_offset_us: i64) -> Result<Self, LogError> {
        let log = Self::parse_rows(text, path, clock_offset_us)?;
        log.check_overlaps()?;
        Ok(log)
    }

    /// Motions one after another, else the first overlap as an error naming both lines.
    pub fn check_overlaps(&self) -> Result<(), LogError> {
        check_overlaps(&self.path, &self.rows)
    }

    /// [`Self::parse`] but for the overlaps.
    fn parse_rows(text: &str, path: &Path, clock_offset_us: i64) -> Result<Self, LogError> {
        let mut lines = text.lines();
        let header: Vec<&str> = lines
            .next()
            .unwrap_or("")
            .split(',')
            .map(str::trim)
            .collect();
        for (i, column) in header.iter().enumerate() {
            let known = COLUMNS.contains(column) && !FILLED_IN.contains(column);
            let err = if !known {
                LogError::UnknownColumn {
                    path: path.to_path_buf(),
                    column: (*column).to_string(),
                }
            } else if header[..i].contains(column) {
                LogError::RepeatedColumn {
                    path: path.to_path_buf(),
                    column: (*column).to_string(),
                }
            } else {
                continue;
            };
            return Err(err);
        }
        if let Some(column) = required_columns().into_iter().find(|c| !header.contains(c)) {
            return Err(LogError::MissingColumn {
                path: path.to_path_buf(),
                column,
            });
        }
        // Each log line becomes the manifest line with the same number.
        let mut manifest = COLUMNS.join(",");
        for (index, raw) in lines.enumerate() {
            manifest.push('\n');
            let raw = raw.trim_end();
            if raw.is_empty() {
                continue;
            }
            let cells: Vec<&str> = raw.split(',').collect();
            if cells.len() != header.len() {
                return Err(ManifestError::CellCount {
                    path: path.to_path_buf(),
                    line: index + 2,
                    expected: header.len(),
                    found: cells.len(),
                }
                .into());
            }
            let cell = |name: &str| header.iter().position(|c| *c == name).map(|i| cells[i]);
            let trial = cell("trial").unwrap_or("").trim();
            let row: Vec<String> = COLUMNS
                .iter()
                .map(|&c| match c {
                    "file" => trial_file(trial),
                    "truth" => String::new(),
                    other => cell(other).unwrap_or("").to_string(),
                })
                .collect();
            manifest.push_str(&row.join(","));
        }
        let parsed = Manifest::parse_rows(&manifest, path);
        if let Some(e) = parsed.errors.into_iter().next() {
            return Err(e.into());
        }
        let mut rows = parsed.trials;
        for (line, t) in &mut rows {
            t.shift(clock_offset_us);
            if t.trial.contains(['/', '\\']) {
                return Err(row_error(
                    path,
                    *line,
                    "trial",
                    "must not contain / or \\ (it names the trial's file)".into(),
                ));
            }
            if let Some(p) = range_problems(path, *line, t).into_iter().next() {
                let column = p.field.unwrap_or_default();
                return Err(row_error(
                    path,
                    *line,
                    &column,
                    format!("{} ({})", p.problem, p.fix),
                ));
            }
        }
        Ok(RobotLog {
            path: path.to_path_buf(),
            rows,
        })
    }

    /// The log with each row's times moved by its own offset (`offsets[i]` for row `i`, in log
    /// order), as a per-motion synchronisation finds them; the motions must still not overlap.
    pub fn shifted(mut self, offsets: &[i64]) -> Result<Self, LogError> {
        for ((_, t), by) in self.rows.iter_mut().zip(offsets) {
            t.shift(*by);
        }
        check_overlaps(&self.path, &self.rows)?;
        Ok(self)
    }

    /// The row indices in the order of their motions' onsets.
    pub fn by_onset(&self) -> Vec<usize> {
        by_start(&self.rows)
    }

    /// For each row (in log order), the end of the motion before it in time, if any.
    pub fn previous_ends(&self) -> Vec<Option<i64>> {
        let order = by_start(&self.rows);
        let mut out = vec![None; self.rows.len()];
        for pair in order.windows(2) {
            out[pair[1]] = Some(self.rows[pair[0]].1.motion_end_us);
        }
        out
    }
}

/// The log file's text.
fn read_text(path: &Path) -> Result<String, LogError> {
    std::fs::read_to_string(path).map_err(|source| LogError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn row_error(path: &Path, line: usize, column: &str, reason: String) -> LogError {
    LogError::Row {
        path: path.to_path_buf(),
        line,
        column: column.to_string(),
        reason,
    }
}

/// The indices of `rows` by motion onset.
fn by_start(rows: &[(usize, TrialMeta)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..rows.len()).collect();
    order.sort_by_key(|&i| rows[i].1.motion_start_us);
    order
}

/// Motions one after another: a robot moves one at a time, so overlapping windows mean a wrong
/// time or clock.
fn check_overlaps(path: &Path, rows: &[(usize, TrialMeta)]) -> Result<(), LogError> {
    for pair in by_start(rows).windows(2) {
        let ((l0, a), (l1, b)) = (&rows[pair[0]], &rows[pair[1]]);
        if b.motion_start_us < a.motion_end_us {
            return Err(row_error(
                path,
                *l1,
                "motion_start_us",
                format!(
                    "the motion from {} us overlaps the motion on line {l0} (`{}`, {} .. {} us); \
                     motions are one after another",
                    b.motion_start_us, a.trial, a.motion_start_us, a.motion_end_us
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str =
        "trial,direction_deg,speed_deg_s,depth_mm,total_deg,motion_start_us,motion_end_us";

    fn parse(text: &str) -> Result<RobotLog, LogError> {
        RobotLog::parse(text, Path::new("log.csv"), 0)
    }

    #[test]
    fn reads_rows_in_any_column_order_with_an_offset() {
        let text = "motion_end_us,trial,group,direction_deg,speed_deg_s,depth_mm,total_deg,\
                    motion_start_us\n5000,b,seen,90,4,1.5,20,1000\n\n9000,a,,0,4,1.5,20,6000\n";
        let log = RobotLog::parse(text, Path::new("log.csv"), 100).unwrap();
        let rows: Vec<(usize, &str, &str, i64, i64)> = log
            .rows
            .iter()
            .map(|(l, t)| {
                let file = t.file.to_str().unwrap();
                (
                    *l,
                    t.trial.as_str(),
                    file,
                    t.motion_start_us,
                    t.motion_end_us,
                )
            })
            .collect();
        assert_eq!(
            rows,
            [
                (2, "b", "b.aedat4", 1100, 5100),
                (4, "a", "a.aedat4", 6100, 9100)
            ]
        );
        assert_eq!(log.rows[0].1.group.as_deref(), Some("seen"));
        assert_eq!(log.rows[1].1.truth, None);
        assert_eq!(log.previous_ends(), [None, Some(5100)]);
    }

    #[test]
    fn bad_logs_name_the_line_and_column() {
        let cases = [
            (
                format!("{HEADER}\na,0,-4,1.5,20,1000,5000\n"),
                "log.csv:2: column `speed_deg_s`",
            ),
            (
                format!("{HEADER}\na,0,4,1.5,20,1000,5000\nb,0,4,1.5,20,4000,9000\n"),
                "log.csv:3: column `motion_start_us`",
            ),
            (
                format!("{HEADER}\na,0,4,1.5,20,x,5000\n"),
                "log.csv:2: column `motion_start_us`: invalid value `x`",
            ),
            (format!("{HEADER}\na,0,4\n"), "log.csv:2: expected 7"),
            (
                format!("{HEADER}\na/b,0,4,1.5,20,1000,5000\n"),
                "log.csv:2: column `trial`",
            ),
            (
                format!("{HEADER},file\n"),
                "log.csv:1: unknown column `file`",
            ),
            (
                "trial,direction_deg\n".to_string(),
                "log.csv:1: column `speed_deg_s` is missing",
            ),
            (
                format!("{HEADER},trial\n"),
                "log.csv:1: column `trial` appears twice",
            ),
        ];
        for (text, want) in cases {
            let err = parse(&text).unwrap_err().to_string();
            assert!(err.starts_with(want), "{want}: {err}");
        }
    }
}
