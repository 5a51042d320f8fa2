//! A folder of per-trial recordings as `evtac import`'s input: each `.aedat4`, `.aedat`, `.bag`
//! or `.mcap` file in it (the formats that carry the IMU the labels need) is one recording, in
//! name order, and a log's row is cut from the file named after its trial (`<trial>.aedat4`),
//! so that the trials keep their names and each is cut on its own file's clock.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::import::{ImportError, Part};
use crate::robot_log::RobotLog;
use evtac_events::IoError;

/// The extensions of the files a folder of trials is read for.
pub const TRIAL_EXTENSIONS: [&str; 4] = ["aedat4", "aedat", "bag", "mcap"];

/// The recordings in `dir`, in name order (hidden files left out).
pub fn trial_files(dir: &Path) -> Result<Vec<PathBuf>, ImportError> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(IoError::at(dir))? {
        let path = entry.map_err(IoError::at(dir))?.path();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if path.is_file()
            && name.is_some_and(|n| !n.starts_with('.'))
            && extension.is_some_and(|e| TRIAL_EXTENSIONS.contains(&e.as_str()))
        {
            files.push(path);
        }
    }
    files.sort();
    if files.is_empty() {
        return Err(ImportError::Problems(vec![format!(
            "{}: no .{} file in the folder",
            dir.display(),
            TRIAL_EXTENSIONS.join(" or .")
        )]));
    }
    Ok(files)
}

/// `log`'s rows (read with [`RobotLog::read_per_trial`]) split by the file of `files` each
/// row's trial names (its stem), in `files`' order; files no row names are left out. A row
/// without its file, or two overlapping rows of one file, is an error naming the log's line.
pub fn split_by_file(log: &RobotLog, files: &[PathBuf]) -> Result<Vec<Part>, ImportError> {
    let by_stem: HashMap<String, usize> = files
        .iter()
        .enumerate()
        .filter_map(|(i, f)| Some((f.file_stem()?.to_string_lossy().into_owned(), i)))
        .collect();
    let mut rows = vec![Vec::new(); files.len()];
    let mut missing = Vec::new();
    for (line, t) in &log.rows {
        match by_stem.get(&t.trial) {
            Some(&i) => rows[i].push((*line, t.clone())),
            None => missing.push(format!(
                "{}:{line}: column `trial`: no file `{}.aedat4` (or .aedat, .bag, .mcap) in the \
                 folder of trials {}",
                log.path.display(),
                t.trial,
                files
                    .first()
                    .and_then(|f| f.parent())
                    .map_or_else(String::new, |d| d.display().to_string())
            )),
        }
    }
    if !missing.is_empty() {
        return Err(ImportError::Problems(missing));
    }
    let mut parts = Vec::new();
    for (file, rows) in files.iter().zip(rows).filter(|(_, r)| !r.is_empty()) {
        let log = RobotLog {
            path: log.path.clone(),
            rows,
        };
        // One file's motions are on one clock: those must not overlap.
        log.check_overlaps()
            .map_err(|e| ImportError::Problems(vec![e.to_string()]))?;
        parts.push(Part {
            session: file.clone(),
            log,
        });
    }
    Ok(parts)
}
