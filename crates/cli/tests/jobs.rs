//! Tests of `evtac jobs`: running one line of a jobs file, as a Slurm array task does.

use crate::common::{evtac, run_ok};

/// A jobs file of three lines (one failing) in a temporary folder.
fn jobs_file(dir: &std::path::Path) -> std::path::PathBuf {
    let file = dir.join("test.jobs");
    let marker = dir.join("ran");
    let lines = format!(
        "echo first > '{}'\n\nexit 3\necho third\n",
        marker.display()
    );
    std::fs::write(&file, lines).unwrap();
    file
}

#[test]
fn jobs_run_runs_the_indexed_line_and_count_skips_blank_lines() {
    let dir = tempfile::tempdir().unwrap();
    let file = jobs_file(dir.path());
    let file = file.to_str().unwrap();
    let count = run_ok(&["jobs", "count", file]);
    assert_eq!(String::from_utf8_lossy(&count.stdout).trim(), "3");
    run_ok(&["jobs", "run", file, "--index", "0"]);
    let ran = std::fs::read_to_string(dir.path().join("ran")).unwrap();
    assert_eq!(ran.trim(), "first");
}

#[test]
fn jobs_run_fails_with_the_job_s_failure_and_names_a_missing_index() {
    let dir = tempfile::tempdir().unwrap();
    let file = jobs_file(dir.path());
    let file = file.to_str().unwrap();
    let failed = evtac()
        .args(["jobs", "run", file, "--index", "1"])
        .output()
        .unwrap();
    assert!(!failed.status.success());
    let stderr = String::from_utf8_lossy(&failed.stderr);
    assert!(
        stderr.contains("job 1 of") && stderr.contains("exit 3"),
        "{stderr}"
    );
    let missing = evtac()
        .args(["jobs", "run", file, "--index", "3"])
        .output()
        .unwrap();
    assert!(!missing.status.success());
    let stderr = String::from_utf8_lossy(&missing.stderr);
    assert!(
        stderr.contains("holds 3 jobs (indices 0 to 2); there is no job 3"),
        "{stderr}"
    );
}
