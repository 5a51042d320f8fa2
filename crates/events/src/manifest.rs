//! The dataset manifest `trials.csv`: one row per trial with its conditions and phases.
//!
//! A dataset folder holds `trials.csv`, the trial recordings, and (for simulated data) the
//! ground truth `truth/<trial>.csv`; every path in the manifest is relative to that folder. The
//! file is a plain CSV with a header row and exactly these columns, in this order:
//!
//! ```text
//! trial,file,truth,direction_deg,speed_deg_s,depth_mm,total_deg,motion_start_us,motion_end_us,
//! stop_start_us,stop_end_us,stop_deg,group
//! ```
//!
//! Optional values (`truth`, the three stop columns and `group`) are empty cells when absent.
//! Names and paths never need quoting: the writer rejects commas, quotes and line breaks in them,
//! so the reader can stay a simple split on commas.
//!
//! ```
//! use evtac_events::manifest::{Manifest, TrialMeta};
//!
//! let dir = std::env::temp_dir().join(format!("evtac-manifest-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let manifest = Manifest {
//!     trials: vec![TrialMeta {
//!         trial: "t0000".into(),
//!         file: "t0000.aedat4".into(),
//!         truth: Some("truth/t0000.csv".into()),
//!         direction_deg: 18.0,
//!         speed_deg_s: 4.0,
//!         depth_mm: 1.5,
//!         total_deg: 20.0,
//!         motion_start_us: 1_000_000,
//!         motion_end_us: 6_000_000,
//!         stop_start_us: None,
//!         stop_end_us: None,
//!         stop_deg: None,
//!         group: None,
//!     }],
//! };
//! manifest.write(&dir).unwrap();
//! assert_eq!(Manifest::read(&dir).unwrap(), manifest);
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::layout::MANIFEST_FILE as FILE_NAME;

/// The manifest's columns, in file order.
pub const COLUMNS: [&str; 13] = [
    "trial",
    "file",
    "truth",
    "direction_deg",
    "speed_deg_s",
    "depth_mm",
    "total_deg",
    "motion_start_us",
    "motion_end_us",
    "stop_start_us",
    "stop_end_us",
    "stop_deg",
    "group",
];

/// The columns a robot's log does not have: `evtac import` names the files. A log's columns are
/// the other [`COLUMNS`], in any order.
pub const NOT_IN_LOG: [&str; 2] = ["file", "truth"];

/// One trial of a dataset: where its recording is, the conditions it was taken under and the
/// times of its phases (microseconds on the recording's clock).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialMeta {
    /// The trial's unique name, e.g. `t0042`.
    pub trial: String,
    /// The recording, relative to the dataset folder.
    pub file: PathBuf,
    /// The ground-truth tilt CSV relative to the dataset folder (simulated datasets only).
    pub truth: Option<PathBuf>,
    /// Tilt direction `phi` in degrees (see `evtac_labels::geometry`).
    pub direction_deg: f64,
    /// Commanded tilt speed in degrees per second.
    pub speed_deg_s: f64,
    /// Indentation depth of the contact plane in millimetres.
    pub depth_mm: f64,
    /// Commanded final tilt in degrees (20 in the paper).
    pub total_deg: f64,
    /// When the tilt motion starts.
    pub motion_start_us: i64,
    /// When the tilt motion ends (the final tilt is reached).
    pub motion_end_us: i64,
    /// When a mid-motion stop starts (Experiment 2 only).
    pub stop_start_us: Option<i64>,
    /// When a mid-motion stop ends (Experiment 2 only).
    pub stop_end_us: Option<i64>,
    /// The commanded tilt in degrees at which the sensor stops (Experiment 2 only).
    pub stop_deg: Option<f64>,
    /// A free-form group label, e.g. `seen` / `unseen` in Experiment 3.
    pub group: Option<String>,
}

/// All trials of a dataset, in file order.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Manifest {
    /// The trials, one per CSV row.
    pub trials: Vec<TrialMeta>,
}

/// Errors reading or writing a manifest.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ManifestError {
    /// The manifest file could not be read or written.
    #[error("cannot access manifest {path}: {source}")]
    Io {
        /// The manifest file.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The first line is not the expected header.
    #[error("{path}:1: header must be `{expected}`, found `{found}`")]
    Header {
        /// The manifest file.
        path: PathBuf,
        /// The header the format requires.
        expected: String,
        /// The first line of the file.
        found: String,
    },
    /// A row has the wrong number of cells.
    #[error("{path}:{line}: expected {expected} comma-separated cells, found {found}")]
    CellCount {
        /// The manifest file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The number of columns (13).
        expected: usize,
        /// The number of cells on the line.
        found: usize,
    },
    /// A cell does not hold a valid value for its column.
    #[error("{path}:{line}: column `{column}`: invalid value `{value}`: {reason}")]
    Cell {
        /// The manifest file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The column's name.
        column: &'static str,
        /// The cell's text.
        value: String,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// Two rows share a trial name.
    #[error("{path}:{line}: trial `{trial}` already appears on line {first_line}")]
    DuplicateTrial {
        /// The manifest file.
        path: PathBuf,
        /// 1-based line number of the repeated row.
        line: usize,
        /// 1-based line number of the first row with that name.
        first_line: usize,
        /// The repeated name.
        trial: String,
    },
    /// A value cannot be written without quoting (it holds a comma, quote or line break), is
    /// not valid UTF-8, or is not a finite number.
    #[error("trial `{trial}`: column `{column}`: cannot write `{value}`: {reason}")]
    Unwritable {
        /// The trial's name.
        trial: String,
        /// The column's name.
        column: &'static str,
        /// The offending value (lossy text).
        value: String,
        /// What is wrong with it.
        reason: &'static str,
    },
}

impl TrialMeta {
    /// Moves every time of the trial (motion and stop) by `by_us`, saturating: onto another
    /// clock, or to where the trial lies in a longer recording.
    pub fn shift(&mut self, by_us: i64) {
        for v in [
            Some(&mut self.motion_start_us),
            Some(&mut self.motion_end_us),
            self.stop_start_us.as_mut(),
            self.stop_end_us.as_mut(),
        ]
        .into_iter()
        .flatten()
        {
            *v = v.saturating_add(by_us);
        }
    }
}

impl Manifest {
    /// The path of the manifest inside `dataset_dir`.
    pub fn path(dataset_dir: impl AsRef<Path>) -> PathBuf {
        dataset_dir.as_ref().join(FILE_NAME)
    }

    /// Reads `dataset_dir/trials.csv`.
    pub fn read(dataset_dir: impl AsRef<Path>) -> Result<Self, ManifestError> {
        let path = Self::path(dataset_dir);
        let text = std::fs::read_to_string(&path).map_err(|source| ManifestError::Io {
            path: path.clone(),
            source,
        })?;
        Self::parse(&text, &path)
    }

    /// Parses manifest text; `path` only names the source in errors. Fails on the first bad
    /// row ([`Manifest::parse_rows`] reports them all).
    pub fn parse(text: &str, path: &Path) -> Result<Self, ManifestError> {
        let rows = Self::parse_rows(text, path);
        match rows.errors.into_iter().next() {
            Some(e) => Err(e),
            None => Ok(Self {
                trials: rows.trials.into_iter().map(|(_, t)| t).collect(),
            }),
        }
    }

    /// Parses manifest text row by row, keeping going past bad rows: every good row with its
    /// line number, and an error for every bad one (a bad header is the only error, as the
    /// rows cannot be read without it). What `evtac check` lists.
    pub fn parse_rows(text: &str, path: &Path) -> ParsedRows {
        let mut out = ParsedRows::default();
        let mut lines = text.lines().enumerate();
        let header = lines.next().map(|(_, l)| l.trim_end()).unwrap_or("");
        let expected = COLUMNS.join(",");
        if header != expected {
            out.errors.push(ManifestError::Header {
                path: path.to_path_buf(),
                expected,
                found: header.to_string(),
            });
            return out;
        }
        let mut seen = std::collections::HashMap::new();
        for (index, raw) in lines {
            let line = index + 1;
            let raw = raw.trim_end();
            if raw.is_empty() {
                continue;
            }
            match parse_row(path, line, raw) {
                Ok(meta) => {
                    if let Some(&first_line) = seen.get(&meta.trial) {
                        out.errors.push(ManifestError::DuplicateTrial {
                            path: path.to_path_buf(),
                            line,
                            first_line,
                            trial: meta.trial,
                        });
                        continue;
                    }
                    seen.insert(meta.trial.clone(), line);
                    out.trials.push((line, meta));
                }
                Err(e) => out.errors.push(e),
            }
        }
        out
    }

    /// The manifest as CSV text (header and one line per trial, `\n` line ends).
    pub fn to_csv(&self) -> Result<String, ManifestError> {
        let mut out = COLUMNS.join(",");
        out.push('\n');
        for t in &self.trials {
            let cells = [
                checked_name(t, 0, &t.trial)?,
                checked_path(t, 1, &t.file)?,
                t.truth
                    .as_deref()
                    .map(|p| checked_path(t, 2, p))
                    .transpose()?
                    .unwrap_or_default(),
                checked_float(t, 3, t.direction_deg)?,
                checked_float(t, 4, t.speed_deg_s)?,
                checked_float(t, 5, t.depth_mm)?,
                checked_float(t, 6, t.total_deg)?,
                t.motion_start_us.to_string(),
                t.motion_end_us.to_string(),
                t.stop_start_us.map(|v| v.to_string()).unwrap_or_default(),
                t.stop_end_us.map(|v| v.to_string()).unwrap_or_default(),
                t.stop_deg
                    .map(|v| checked_float(t, 11, v))
                    .transpose()?
                    .unwrap_or_default(),
                t.group
                    .as_deref()
                    .map(|g| checked_name(t, 12, g))
                    .transpose()?
                    .unwrap_or_default(),
            ];
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        Ok(out)
    }

    /// The manifest as a robot's log (what `evtac import --log` reads): [`Self::to_csv`]
    /// without the [`NOT_IN_LOG`] columns.
    pub fn to_log_csv(&self) -> Result<String, ManifestError> {
        let keep: Vec<bool> = COLUMNS.iter().map(|c| !NOT_IN_LOG.contains(c)).collect();
        // No cell holds a comma (the writer refuses them), so a split finds the cells.
        let text = self.to_csv()?;
        let mut out = String::with_capacity(text.len());
        for line in text.lines() {
            let cells: Vec<&str> = line
                .split(',')
                .zip(&keep)
                .filter_map(|(c, k)| k.then_some(c))
                .collect();
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        Ok(out)
    }

    /// Writes `dataset_dir/trials.csv` (the folder must exist). The file is written under a
    /// temporary name and renamed, so readers never see half a manifest.
    pub fn write(&self, dataset_dir: impl AsRef<Path>) -> Result<(), ManifestError> {
        let text = self.to_csv()?;
        let path = Self::path(&dataset_dir);
        crate::output::write_atomic(&path, text.as_bytes()).map_err(|source| ManifestError::Io {
            path: path.clone(),
            source,
        })
    }

    /// The trial named `trial`, if present.
    pub fn get(&self, trial: &str) -> Option<&TrialMeta> {
        self.trials.iter().find(|t| t.trial == trial)
    }
}

/// What [`Manifest::parse_rows`] found: the rows that parse, and an error per row that does not.
#[derive(Debug, Default)]
pub struct ParsedRows {
    /// The good rows, each with its 1-based line number, in file order.
    pub trials: Vec<(usize, TrialMeta)>,
    /// The bad header, or every bad row (wrong cell count, bad cell, repeated trial name).
    pub errors: Vec<ManifestError>,
}

/// Parses the data row `raw` at 1-based `line`.
fn parse_row(path: &Path, line: usize, raw: &str) -> Result<TrialMeta, ManifestError> {
    let cells: Vec<&str> = raw.split(',').collect();
    if cells.len() != COLUMNS.len() {
        return Err(ManifestError::CellCount {
            path: path.to_path_buf(),
            line,
            expected: COLUMNS.len(),
            found: cells.len(),
        });
    }
    let row = Row { path, line, cells };
    Ok(TrialMeta {
        trial: row.name(0)?,
        file: PathBuf::from(row.name(1)?),
        truth: row.optional(2, |r, i| r.name(i).map(PathBuf::from))?,
        direction_deg: row.float(3)?,
        speed_deg_s: row.float(4)?,
        depth_mm: row.float(5)?,
        total_deg: row.float(6)?,
        motion_start_us: row.int(7)?,
        motion_end_us: row.int(8)?,
        stop_start_us: row.optional(9, Row::int)?,
        stop_end_us: row.optional(10, Row::int)?,
        stop_deg: row.optional(11, Row::float)?,
        group: row.optional(12, Row::name)?,
    })
}

/// One data row being parsed, carrying what error messages need.
struct Row<'a> {
    path: &'a Path,
    line: usize,
    cells: Vec<&'a str>,
}

impl Row<'_> {
    fn error(&self, col: usize, reason: &'static str) -> ManifestError {
        ManifestError::Cell {
            path: self.path.to_path_buf(),
            line: self.line,
            column: COLUMNS[col],
            value: self.cells[col].to_string(),
            reason,
        }
    }

    fn name(&self, col: usize) -> Result<String, ManifestError> {
        let v = self.cells[col].trim();
        if v.is_empty() {
            return Err(self.error(col, "must not be empty"));
        }
        if v.contains('"') {
            return Err(self.error(col, "quoted cells are not supported"));
        }
        Ok(v.to_string())
    }

    fn float(&self, col: usize) -> Result<f64, ManifestError> {
        match self.cells[col].trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.error(col, "must be a finite number")),
            Err(_) => Err(self.error(col, "not a number")),
        }
    }

    fn int(&self, col: usize) -> Result<i64, ManifestError> {
        self.cells[col]
            .trim()
            .parse::<i64>()
            .map_err(|_| self.error(col, "not an integer (microseconds)"))
    }

    /// An empty cell is `None`; anything else must parse with `parse`.
    fn optional<T>(
        &self,
        col: usize,
        parse: impl Fn(&Self, usize) -> Result<T, ManifestError>,
    ) -> Result<Option<T>, ManifestError> {
        if self.cells[col].trim().is_empty() {
            Ok(None)
        } else {
            parse(self, col).map(Some)
        }
    }
}

fn unwritable(t: &TrialMeta, col: usize, value: String, reason: &'static str) -> ManifestError {
    ManifestError::Unwritable {
        trial: t.trial.clone(),
        column: COLUMNS[col],
        value,
        reason,
    }
}

fn checked_name(t: &TrialMeta, col: usize, v: &str) -> Result<String, ManifestError> {
    if v.trim().is_empty() {
        return Err(unwritable(t, col, v.to_string(), "must not be empty"));
    }
    if v.contains([',', '"', '\n', '\r']) {
        return Err(unwritable(
            t,
            col,
            v.to_string(),
            "must not contain commas, quotes or line breaks",
        ));
    }
    if v.trim() != v {
        return Err(unwritable(
            t,
            col,
            v.to_string(),
            "must not start or end with whitespace",
        ));
    }
    Ok(v.to_string())
}

fn checked_path(t: &TrialMeta, col: usize, p: &Path) -> Result<String, ManifestError> {
    match p.to_str() {
        Some(s) => checked_name(t, col, s),
        None => Err(unwritable(
            t,
            col,
            p.to_string_lossy().into_owned(),
            "path is not valid UTF-8",
        )),
    }
}

fn checked_float(t: &TrialMeta, col: usize, v: f64) -> Result<String, ManifestError> {
    if v.is_finite() {
        // `Display` for f64 prints the shortest text that parses back to the same value.
        Ok(v.to_string())
    } else {
        Err(unwritable(t, col, v.to_string(), "must be a finite number"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trial(name: &str) -> TrialMeta {
        TrialMeta {
            trial: name.into(),
            file: format!("{name}.aedat4").into(),
            truth: Some(format!("truth/{name}.csv").into()),
            direction_deg: 0.1 + 0.2,
            speed_deg_s: 2.0,
            depth_mm: 1.25,
            total_deg: 20.0,
            motion_start_us: 1_500_000,
            motion_end_us: 11_500_000,
            stop_start_us: Some(3_000_000),
            stop_end_us: Some(3_500_000),
            stop_deg: Some(7.123456789012345),
            group: Some("unseen".into()),
        }
    }

    fn plain(name: &str) -> TrialMeta {
        TrialMeta {
            truth: None,
            stop_start_us: None,
            stop_end_us: None,
            stop_deg: None,
            group: None,
            ..trial(name)
        }
    }

    fn parse(text: &str) -> Result<Manifest, ManifestError> {
        Manifest::parse(text, Path::new("trials.csv"))
    }

    const HEADER: &str = "trial,file,truth,direction_deg,speed_deg_s,depth_mm,total_deg,\
        motion_start_us,motion_end_us,stop_start_us,stop_end_us,stop_deg,group";

    #[test]
    fn round_trips_exactly_through_a_folder() {
        let dir = tempfile::tempdir().unwrap();
        let m = Manifest {
            trials: vec![trial("a"), plain("b"), trial("c")],
        };
        m.write(dir.path()).unwrap();
        assert_eq!(Manifest::read(dir.path()).unwrap(), m);
        assert!(!dir.path().join(".trials.csv.tmp").exists());
    }

    #[test]
    fn writes_empty_cells_for_absent_values_in_column_order() {
        let text = Manifest {
            trials: vec![plain("b")],
        }
        .to_csv()
        .unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], HEADER);
        assert_eq!(
            lines[1],
            "b,b.aedat4,,0.30000000000000004,2,1.25,20,1500000,11500000,,,,"
        );
    }

    #[test]
    fn reads_crlf_and_skips_blank_lines() {
        let text = format!("{HEADER}\r\nb,b.aedat4,,0.5,2,1.25,20,1,2,,,,\r\n\r\n");
        let m = parse(&text).unwrap();
        assert_eq!(m.trials.len(), 1);
        assert_eq!(m.trials[0].direction_deg, 0.5);
        assert_eq!(m.get("b").map(|t| t.motion_end_us), Some(2));
        assert!(m.get("x").is_none());
    }

    #[test]
    fn empty_manifest_has_only_a_header() {
        let text = Manifest::default().to_csv().unwrap();
        assert_eq!(text, format!("{HEADER}\n"));
        assert_eq!(parse(&text).unwrap(), Manifest::default());
    }

    #[test]
    fn rejects_wrong_header() {
        let err = parse("trial,file\n").unwrap_err();
        assert!(matches!(err, ManifestError::Header { .. }), "{err}");
        assert!(err.to_string().contains("trials.csv:1"), "{err}");
        assert!(matches!(parse(""), Err(ManifestError::Header { .. })));
    }

    #[test]
    fn names_line_and_column_of_a_bad_cell() {
        let text = format!(
            "{HEADER}\nb,b.aedat4,,0.5,2,1.25,20,1,2,,,,\nc,c.aedat4,,0.5,fast,1,20,1,2,,,,\n"
        );
        let err = parse(&text).unwrap_err();
        match &err {
            ManifestError::Cell {
                line,
                column,
                value,
                ..
            } => {
                assert_eq!((*line, *column, value.as_str()), (3, "speed_deg_s", "fast"));
            }
            other => panic!("unexpected error {other}"),
        }
        assert!(err.to_string().contains("trials.csv:3"), "{err}");
    }

    #[test]
    fn rejects_bad_cells() {
        let bad = [
            ("b,b.aedat4,,0.5,2,1.25,20,1.5,2,,,,", "motion_start_us"),
            ("b,b.aedat4,,0.5,2,1.25,20,1,2,x,,,", "stop_start_us"),
            ("b,b.aedat4,,NaN,2,1.25,20,1,2,,,,", "direction_deg"),
            (",b.aedat4,,0.5,2,1.25,20,1,2,,,,", "trial"),
            ("b,,,0.5,2,1.25,20,1,2,,,,", "file"),
            ("\"b\",b.aedat4,,0.5,2,1.25,20,1,2,,,,", "trial"),
        ];
        for (row, col) in bad {
            match parse(&format!("{HEADER}\n{row}\n")) {
                Err(ManifestError::Cell { column, line, .. }) => {
                    assert_eq!((column, line), (col, 2), "{row}");
                }
                other => panic!("{row}: unexpected {other:?}"),
            }
        }
    }

    #[test]
    fn rejects_wrong_cell_count() {
        let err = parse(&format!("{HEADER}\nb,b.aedat4,,0.5\n")).unwrap_err();
        assert!(
            matches!(
                err,
                ManifestError::CellCount {
                    line: 2,
                    expected: 13,
                    found: 4,
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn rejects_duplicate_trials() {
        let row = "b,b.aedat4,,0.5,2,1.25,20,1,2,,,,";
        let err = parse(&format!("{HEADER}\n{row}\n{row}\n")).unwrap_err();
        assert!(
            matches!(
                err,
                ManifestError::DuplicateTrial {
                    line: 3,
                    first_line: 2,
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn parse_rows_reports_every_bad_row_and_keeps_the_good_ones() {
        let text = format!(
            "{HEADER}\nb,b.aedat4,,0.5,2,1.25,20,1,2,,,,\nc,c.aedat4,,x,2,1,20,1,2,,,,\n\
             d,d.aedat4\nb,b.aedat4,,0.5,2,1.25,20,1,2,,,,\ne,e.aedat4,,1,2,1,20,1,2,,,,\n"
        );
        let rows = Manifest::parse_rows(&text, Path::new("trials.csv"));
        let good: Vec<(usize, &str)> = rows
            .trials
            .iter()
            .map(|(l, t)| (*l, t.trial.as_str()))
            .collect();
        assert_eq!(good, [(2, "b"), (6, "e")]);
        let lines: Vec<String> = rows.errors.iter().map(|e| e.to_string()).collect();
        assert_eq!(rows.errors.len(), 3, "{lines:?}");
        assert!(lines[0].contains(":3: column `direction_deg`"), "{lines:?}");
        assert!(lines[1].contains(":4: expected 13"), "{lines:?}");
        assert!(
            lines[2].contains(":5: trial `b` already appears on line 2"),
            "{lines:?}"
        );
        let rows = Manifest::parse_rows("trial,file\n", Path::new("trials.csv"));
        assert!(rows.trials.is_empty());
        assert!(matches!(rows.errors[..], [ManifestError::Header { .. }]));
    }

    #[test]
    fn refuses_to_write_what_it_could_not_read_back() {
        let cases = [
            TrialMeta {
                trial: "a,b".into(),
                ..plain("x")
            },
            TrialMeta {
                file: "dir\nname.aedat4".into(),
                ..plain("x")
            },
            TrialMeta {
                group: Some("un\"seen".into()),
                ..plain("x")
            },
            TrialMeta {
                group: Some(String::new()),
                ..plain("x")
            },
            TrialMeta {
                depth_mm: f64::INFINITY,
                ..plain("x")
            },
            TrialMeta {
                trial: " padded".into(),
                ..plain("x")
            },
        ];
        for t in cases {
            let err = Manifest { trials: vec![t] }.to_csv().unwrap_err();
            assert!(matches!(err, ManifestError::Unwritable { .. }), "{err}");
        }
    }

    #[test]
    fn missing_file_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let err = Manifest::read(dir.path()).unwrap_err();
        assert!(matches!(err, ManifestError::Io { .. }));
        assert!(err.to_string().contains("trials.csv"), "{err}");
    }
}
