//! The stage times of every invocation that worked on one reproduction's output folder
//! (`OUT/stage-times.csv`), so that a report written by a resumed run states what the whole
//! reproduction took, not only its last invocation.
//!
//! A paper-scale reproduction is often stopped and resumed (a machine needed elsewhere, a
//! cluster's time limit): each invocation skips the finished jobs, so its own stage times say
//! little about the reproduction. Each invocation takes the next number and appends a row as
//! each of its stages finishes, so an interrupted invocation keeps what it finished too.

pub use crate::results::StageRecord;
use crate::stage::Timed;
use evtac_events::IoError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The file in the output folder.
pub const FILE: &str = "stage-times.csv";

/// Its header.
const HEADER: &str = "invocation,stage,seconds";

/// Errors reading or appending to the log.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The file could not be read or written.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A line is not `invocation,stage,seconds`.
    #[error(
        "{path}, line {line}: {message} (expected `{HEADER}`; delete the file to start the log anew)"
    )]
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// The log of one output folder, opened by one invocation.
#[derive(Debug)]
pub struct StageLog {
    path: PathBuf,
    invocation: u32,
    earlier: Vec<StageRecord>,
    own: std::sync::Mutex<Vec<StageRecord>>,
}

impl StageLog {
    /// Opens the log of `out` for a new invocation: the earlier invocations' rows are read,
    /// and this one takes the next number. Nothing is written until a stage finishes.
    pub fn open(out: &Path) -> Result<StageLog, Error> {
        let path = out.join(FILE);
        let earlier = match std::fs::read_to_string(&path) {
            Ok(text) => parse(&path, &text)?,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
            Err(e) => return Err(IoError::at(&path)(e).into()),
        };
        let invocation = earlier.iter().map(|r| r.invocation).max().unwrap_or(0) + 1;
        Ok(StageLog {
            path,
            invocation,
            earlier,
            own: std::sync::Mutex::new(Vec::new()),
        })
    }

    /// This invocation's number (1 for a fresh output folder).
    pub fn invocation(&self) -> u32 {
        self.invocation
    }

    /// Appends this invocation's finished `stage` and its `seconds` to the file.
    pub fn record(&self, stage: Timed, seconds: f64) -> Result<(), Error> {
        let at = IoError::at(&self.path);
        if let Some(dir) = self.path.parent() {
            std::fs::create_dir_all(dir).map_err(IoError::at(dir))?;
        }
        let fresh = !self.path.exists();
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&self.path)
            .map_err(&at)?;
        let mut text = String::new();
        if fresh {
            text.push_str(HEADER);
            text.push('\n');
        }
        // A comma in a stage name would split its row: written as a semicolon instead of
        // quoting (evtac's stage names have none).
        let stage = stage.name().replace(',', ";");
        text.push_str(&format!("{},{stage},{seconds:.3}\n", self.invocation));
        file.write_all(text.as_bytes()).map_err(&at)?;
        let record = StageRecord {
            invocation: self.invocation,
            stage,
            seconds,
        };
        self.own
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(record);
        Ok(())
    }

    /// Every invocation's finished stages, in the order they ran: the earlier ones' read at
    /// [`StageLog::open`], then this one's.
    pub fn records(&self) -> Vec<StageRecord> {
        let own = self.own.lock().unwrap_or_else(|e| e.into_inner());
        self.earlier.iter().chain(own.iter()).cloned().collect()
    }
}

/// The rows of the log's `text` (read from `path`).
fn parse(path: &Path, text: &str) -> Result<Vec<StageRecord>, Error> {
    let bad = |line: usize, message: String| Error::Line {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, HEADER)) | None => {}
        Some((_, other)) => return Err(bad(1, format!("the header is `{other}`"))),
    }
    lines
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let fields: Vec<&str> = l.split(',').collect();
            let [invocation, stage, seconds] = fields[..] else {
                return Err(bad(i + 1, format!("{} fields, not 3", fields.len())));
            };
            let invocation = invocation
                .parse::<u32>()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| bad(i + 1, format!("invocation `{invocation}` is not 1 or more")))?;
            let seconds = seconds
                .parse::<f64>()
                .ok()
                .filter(|s| s.is_finite() && *s >= 0.0)
                .ok_or_else(|| bad(i + 1, format!("seconds `{seconds}` is not a duration")))?;
            Ok(StageRecord {
                invocation,
                stage: stage.to_string(),
                seconds,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_invocation_takes_the_next_number_and_keeps_the_earlier_rows() {
        let dir = tempfile::tempdir().unwrap();
        let first = StageLog::open(dir.path()).unwrap();
        assert_eq!(first.invocation(), 1);
        assert!(
            !dir.path().join(FILE).exists(),
            "nothing written before a stage ends"
        );
        first.record(Timed::Simulation, 12.5).unwrap();
        first.record(Timed::TuningStatic, 100.25).unwrap();
        // Interrupted here; the next invocation resumes.
        let second = StageLog::open(dir.path()).unwrap();
        assert_eq!(second.invocation(), 2);
        second.record(Timed::TuningStatic, 0.5).unwrap();
        let rows: Vec<(u32, String, f64)> = second
            .records()
            .into_iter()
            .map(|r| (r.invocation, r.stage, r.seconds))
            .collect();
        assert_eq!(
            rows,
            [
                (1, "simulation".to_string(), 12.5),
                (1, "tuning (static)".to_string(), 100.25),
                (2, "tuning (static)".to_string(), 0.5),
            ]
        );
        assert_eq!(StageLog::open(dir.path()).unwrap().invocation(), 3);
    }

    #[test]
    fn a_damaged_log_is_an_error_naming_the_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(FILE);
        for (text, line, what) in [
            ("stage,seconds\n", 1, "header"),
            (
                "invocation,stage,seconds\n1,simulation,2.0\n1,latency\n",
                3,
                "2 fields",
            ),
            (
                "invocation,stage,seconds\n0,simulation,2.0\n",
                2,
                "invocation `0`",
            ),
            (
                "invocation,stage,seconds\n1,simulation,-1\n",
                2,
                "seconds `-1`",
            ),
        ] {
            std::fs::write(&path, text).unwrap();
            let err = StageLog::open(dir.path()).unwrap_err().to_string();
            assert!(
                err.contains(&format!("{}, line {line}", path.display())) && err.contains(what),
                "{err}"
            );
        }
    }
}
