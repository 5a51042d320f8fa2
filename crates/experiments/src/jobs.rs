//! Jobs: every expensive step is a pure function of (inputs, config, seed) that writes its own
//! output folder and, last, a `done` marker. A run that is interrupted resumes from the finished
//! jobs (folders with `done`); a half-written folder is redone. The same job list can be exported
//! as one `evtac ...` command per line for a Slurm array or GNU parallel.

use evtac_events::IoError;
use evtac_events::output::write_atomic;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Name of the marker file a finished job writes last.
pub const DONE: &str = "done";

/// Errors of the job machinery.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A job's folder or marker could not be written.
    #[error(transparent)]
    Io(#[from] IoError),
}

/// Whether the job writing to `dir` has finished.
pub fn is_done(dir: &Path) -> bool {
    dir.join(DONE).is_file()
}

/// Marks the job writing to `dir` as finished (its outputs must be complete by now).
pub fn mark_done(dir: &Path) -> Result<(), Error> {
    let marker = dir.join(DONE);
    create_parent(&marker)
        .and_then(|()| write_atomic(&marker, b""))
        .map_err(IoError::at(&marker))?;
    Ok(())
}

/// Creates the folder `path` is written into (the experiments write into folders they make as
/// they go; [`write_atomic`] needs its folder to exist).
pub fn create_parent(path: &Path) -> std::io::Result<()> {
    match path.parent() {
        Some(parent) => std::fs::create_dir_all(parent),
        None => Ok(()),
    }
}

/// A sibling temporary path for `path` (same folder, so a rename is atomic), unique to this call:
/// parallel jobs may write the same cache file at once (e.g. two seeds needing the same
/// features), and each must rename its own complete copy rather than race on one shared name.
pub fn tmp_path(path: &Path) -> PathBuf {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".tmp{}-{n}", std::process::id()));
    path.with_file_name(name)
}

/// Runs `work` on every item in parallel, skipping those whose `dir(item)` is done, and
/// calling `progress(skipped)` after each item (`true` when it was done already). Returns the
/// first error in `items`' order, after the other items finished (their work is kept for a
/// resumed run).
///
/// Items start in the order given: each of rayon's threads takes the next item as it frees.
/// Callers put the longest first (`crate::exp1::train_all` orders training runs by their
/// features' density), so the last items to finish are short and the tail, where a core has
/// nothing left to take, is short too. (rayon's `par_iter` splits the slice in halves instead,
/// so a long item can start last.)
pub fn run_all<T, E, D, W, P>(items: &[T], dir: D, work: W, progress: P) -> Result<(), E>
where
    T: Sync,
    E: Send,
    D: Fn(&T) -> PathBuf + Sync,
    W: Fn(&T) -> Result<(), E> + Sync,
    P: Fn(bool) + Sync,
{
    let next = AtomicUsize::new(0);
    let errors = Mutex::new(Vec::new());
    let workers = rayon::current_num_threads().clamp(1, items.len().max(1));
    rayon::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|_| {
                loop {
                    let index = next.fetch_add(1, Ordering::Relaxed);
                    let Some(item) = items.get(index) else { break };
                    let skipped = is_done(&dir(item));
                    let result = if skipped { Ok(()) } else { work(item) };
                    progress(skipped);
                    if let Err(e) = result {
                        errors
                            .lock()
                            .unwrap_or_else(|p| p.into_inner())
                            .push((index, e));
                    }
                }
            });
        }
    });
    let errors = errors.into_inner().unwrap_or_else(|p| p.into_inner());
    match errors.into_iter().min_by_key(|(index, _)| *index) {
        Some((_, e)) => Err(e),
        None => Ok(()),
    }
}

/// Quotes `arg` for a POSIX shell when it needs it.
pub fn shell_quote(arg: &str) -> String {
    let plain = !arg.is_empty()
        && arg
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', r"'\''"))
    }
}

/// One shell command line from program arguments.
pub fn command_line(args: &[String]) -> String {
    args.iter()
        .map(|a| shell_quote(a))
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finished_jobs_are_skipped_and_failures_keep_the_rest() {
        let dir = tempfile::tempdir().unwrap();
        let items: Vec<usize> = (0..8).collect();
        let ran = AtomicUsize::new(0);
        let job_dir = |i: &usize| dir.path().join(format!("job{i}"));
        // First run: job 5 fails ("interrupted"); the others finish.
        let result = run_all(
            &items,
            job_dir,
            |&i| {
                ran.fetch_add(1, Ordering::SeqCst);
                if i == 5 {
                    return Err(format!("job {i} failed"));
                }
                std::fs::create_dir_all(job_dir(&i)).unwrap();
                mark_done(&job_dir(&i)).map_err(|e| e.to_string())
            },
            |skipped| assert!(!skipped),
        );
        assert_eq!(result, Err("job 5 failed".to_string()));
        assert_eq!(ran.load(Ordering::SeqCst), 8);
        // Resumed run: only job 5 runs again.
        let (ran_again, skipped_again) = (AtomicUsize::new(0), AtomicUsize::new(0));
        let result: Result<(), String> = run_all(
            &items,
            job_dir,
            |&i| {
                ran_again.fetch_add(1, Ordering::SeqCst);
                assert_eq!(i, 5);
                std::fs::create_dir_all(job_dir(&i)).unwrap();
                mark_done(&job_dir(&i)).map_err(|e| e.to_string())
            },
            |skipped| {
                if skipped {
                    skipped_again.fetch_add(1, Ordering::SeqCst);
                }
            },
        );
        assert!(result.is_ok());
        assert_eq!(ran_again.load(Ordering::SeqCst), 1);
        // The seven finished ones are reported as skipped, for the ETA to leave them out.
        assert_eq!(skipped_again.load(Ordering::SeqCst), 7);
    }

    /// Items start in the order given (what lets callers put the longest first), and each
    /// runs once; the first error is the first in the items' order. When item k records its
    /// start, items 0..k were all handed out and each other worker holds at most one it has
    /// not recorded yet, so at least k - (threads - 1) starts were recorded before it (rayon's
    /// `par_iter` would start item 10 of 20 second on two threads). Late recording can only
    /// move an item later, which this allows.
    #[test]
    fn items_start_in_the_order_given() {
        let dir = tempfile::tempdir().unwrap();
        let items: Vec<usize> = (0..20).collect();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let started = Mutex::new(Vec::new());
            let result = pool.install(|| {
                run_all(
                    &items,
                    |i| dir.path().join(format!("job{i}")),
                    |&i| {
                        started.lock().unwrap().push(i);
                        std::thread::sleep(std::time::Duration::from_millis(2));
                        if i % 7 == 6 { Err(i) } else { Ok(()) }
                    },
                    |_| {},
                )
            });
            assert_eq!(result, Err(6), "{threads} threads");
            let mut started = started.into_inner().unwrap();
            for (place, &k) in started.iter().enumerate() {
                assert!(place + threads > k, "{threads} threads: {started:?}");
            }
            started.sort_unstable();
            assert_eq!(started, items, "{threads} threads: each item once");
        }
    }

    #[test]
    fn quoting() {
        assert_eq!(shell_quote("abc-1.0/x"), "abc-1.0/x");
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
        assert_eq!(
            command_line(&["evtac".into(), "train".into(), "my dir".into()]),
            "evtac train 'my dir'"
        );
    }
}
