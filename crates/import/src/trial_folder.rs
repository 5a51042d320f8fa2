//! A folder of per-trial recordings as `evtac import`'s input: each recording in it is one
//! trial's, in name order, and a log's row is cut from the file named after its trial
//! (`<trial>.aedat4`), so that the trials keep their names and each is cut on its own file's
//! clock.
//!
//! The recordings are the files of the formats evtac reads: those that carry the IMU the
//! paper's labels need (`.aedat4`, `.aedat`, `.bag`, `.mcap`: [`IMU_EXTENSIONS`]) and those
//! that hold events only, for a dataset labelled from the commanded motion
//! ([`EVENT_ONLY_EXTENSIONS`]; whether a trial's recording must hold an IMU is `evtac check`'s
//! question, asked at the end of the import). The NeuroTac lab's pickles come in pairs,
//! `<trial>_events_on` and `<trial>_events_off`, with or without an extension: a pair is one
//! recording (read from either file), named `<trial>`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::import::{ImportError, Part};
use crate::robot_log::RobotLog;
use evtac_events::IoError;

/// The extensions of the recordings that carry an IMU.
pub const IMU_EXTENSIONS: [&str; 4] = ["aedat4", "aedat", "bag", "mcap"];
/// The extensions of the recordings that hold events only (HDF5, NPY, NPZ, CSV, the lab's
/// pickles, Prophesee's EVT `.raw`).
pub const EVENT_ONLY_EXTENSIONS: [&str; 8] =
    ["h5", "hdf5", "npy", "npz", "csv", "pickle", "pkl", "raw"];
/// The suffixes of the lab's pickle pairs (after the trial's name).
const PAIR_SUFFIXES: [&str; 2] = ["_events_on", "_events_off"];

/// A recording's name without its extension (`file_stem`; the whole name for a pickle of a
/// lab's pair saved without one, whose trial name may hold dots), and whether it is one of a
/// lab's pickle pair.
fn stem_of(path: &Path) -> Option<(&str, bool)> {
    let pair = |s: &str| PAIR_SUFFIXES.iter().any(|x| s.ends_with(x));
    let name = path.file_name()?.to_str()?;
    if pair(name) {
        return Some((name, true));
    }
    let stem = path.file_stem()?.to_str()?;
    Some((stem, pair(stem)))
}

/// The trial a recording of a folder is named after: its file's stem, or for one of the lab's
/// pickle pairs, the stem without `_events_on` / `_events_off`.
pub fn trial_name(path: &Path) -> Option<String> {
    let (stem, _) = stem_of(path)?;
    let base = PAIR_SUFFIXES
        .iter()
        .find_map(|s| stem.strip_suffix(s))
        .unwrap_or(stem);
    Some(base.to_string())
}

/// Whether `path` is a recording a folder of trials is read for (`imu_only`: of a format that
/// carries an IMU).
fn is_recording(path: &Path, imu_only: bool) -> bool {
    let Some((stem, pair)) = stem_of(path) else {
        return false;
    };
    let no_extension = path.file_name().and_then(|n| n.to_str()) == Some(stem);
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .filter(|_| !no_extension);
    let known = |list: &[&str]| extension.as_deref().is_some_and(|e| list.contains(&e));
    !stem.is_empty()
        && (known(&IMU_EXTENSIONS)
            || (!imu_only && (known(&EVENT_ONLY_EXTENSIONS) || (pair && no_extension))))
}

/// The ON file of the pair whose OFF file is `path` (`None` for any other file).
fn on_partner(path: &Path) -> Option<PathBuf> {
    let (stem, _) = stem_of(path)?;
    let base = stem.strip_suffix("_events_off")?;
    let name = path.file_name()?.to_str()?;
    Some(path.with_file_name(format!("{base}_events_on{}", &name[stem.len()..])))
}

/// The recordings in `dir`, in name order (hidden files left out; of a lab's pickle pair, the
/// ON file, or the OFF file alone); with `imu_only`, only those of formats that carry an IMU
/// (the motions are then found in it).
pub fn trial_files(dir: &Path, imu_only: bool) -> Result<Vec<PathBuf>, ImportError> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(IoError::at(dir))? {
        let path = entry.map_err(IoError::at(dir))?.path();
        let hidden = path
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if path.is_file() && !hidden && is_recording(&path, imu_only) {
            files.push(path);
        }
    }
    files.sort();
    // A pair's OFF file is read with its ON file: kept only when it is alone.
    let kept: Vec<PathBuf> = files
        .iter()
        .filter(|f| on_partner(f).is_none_or(|on| !files.contains(&on)))
        .cloned()
        .collect();
    if kept.is_empty() {
        let extensions = if imu_only {
            IMU_EXTENSIONS.join(" or .")
        } else {
            [IMU_EXTENSIONS.as_slice(), EVENT_ONLY_EXTENSIONS.as_slice()]
                .concat()
                .join(", .")
        };
        return Err(ImportError::Problems(vec![format!(
            "{}: no recording in the folder (.{extensions})",
            dir.display(),
        )]));
    }
    Ok(kept)
}

/// `log`'s rows (read with [`RobotLog::read_per_trial`]) split by the file of `files` each
/// row's trial names (its stem), in `files`' order; files no row names are left out. A row
/// without its file, a row whose trial names two files (`t0.aedat4` and `t0.h5`), or two
/// overlapping rows of one file, is an error naming the log's line.
pub fn split_by_file(log: &RobotLog, files: &[PathBuf]) -> Result<Vec<Part>, ImportError> {
    let mut by_stem: HashMap<String, Vec<usize>> = HashMap::new();
    for (i, f) in files.iter().enumerate() {
        if let Some(name) = trial_name(f) {
            by_stem.entry(name).or_default().push(i);
        }
    }
    let mut rows = vec![Vec::new(); files.len()];
    let mut missing = Vec::new();
    for (line, t) in &log.rows {
        match by_stem.get(&t.trial).map(Vec::as_slice) {
            Some(&[i]) => rows[i].push((*line, t.clone())),
            Some(several @ [_, _, ..]) => missing.push(format!(
                "{}:{line}: column `trial`: `{}` names {} recordings ({}): keep one per trial in \
                 the folder",
                log.path.display(),
                t.trial,
                several.len(),
                several
                    .iter()
                    .map(|&i| files[i].display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
            _ => missing.push(format!(
                "{}:{line}: column `trial`: no recording `{}.aedat4` (or another format evtac \
                 reads; `_events_on` for the lab's pickles) in the folder of trials {}",
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_lists_recordings_and_reads_a_pickle_pair_as_one_trial() {
        let dir = tempfile::tempdir().unwrap();
        for name in [
            "t0.aedat4",
            "t1.bag",
            "t2_events_on.pickle",
            "t2_events_off.pickle",
            "t3_events_off",
            "t4.5_events_on",
            "t6.h5",
            "robot_log.txt",
            ".hidden.aedat4",
        ] {
            std::fs::write(dir.path().join(name), b"").unwrap();
        }
        let names = |files: Vec<PathBuf>| -> Vec<String> {
            files.iter().map(|f| trial_name(f).unwrap()).collect()
        };
        assert_eq!(
            names(trial_files(dir.path(), false).unwrap()),
            ["t0", "t1", "t2", "t3", "t4.5", "t6"]
        );
        let all = trial_files(dir.path(), false).unwrap();
        assert!(all.contains(&dir.path().join("t2_events_on.pickle")));
        assert_eq!(names(trial_files(dir.path(), true).unwrap()), ["t0", "t1"]);

        // A trial of two recordings is refused, naming both.
        std::fs::write(dir.path().join("t0.h5"), b"").unwrap();
        let log_path = dir.path().join("log.csv");
        std::fs::write(
            &log_path,
            "trial,direction_deg,speed_deg_s,depth_mm,total_deg,motion_start_us,motion_end_us\n\
             t0,0,6,1.5,20,1000000,4000000\n",
        )
        .unwrap();
        let log = RobotLog::read_per_trial(&log_path, 0).unwrap();
        let files = trial_files(dir.path(), false).unwrap();
        let Err(ImportError::Problems(p)) = split_by_file(&log, &files) else {
            panic!("two recordings of t0 accepted");
        };
        assert!(
            p[0].contains("log.csv:2") && p[0].contains("t0.h5"),
            "{p:?}"
        );
    }
}
