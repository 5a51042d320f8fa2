//! `evtac reproduce --executor slurm` against a real Slurm (slurmctld + slurmd on localhost,
//! started by `.ci/slurm-up`): the tiny reproduction submitted as job arrays, one array task
//! cancelled mid-run (`scancel`), the run resumed, and the results compared with the local run
//! of the same seed ([`crate::reproduce::tiny_run`]). And `evtac sensitivity --executor slurm`:
//! the tiny study's points as one array, the study the same bytes as the local one
//! ([`crate::sensitivity::tiny_study`]).
//!
//! Every array is submitted held (`--slurm-args=--hold`) and released by the test, so the task
//! is cancelled at a known point (before it ran) rather than by a race with the scheduler.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::evtac;
use crate::reproduce::{tiny_args, tiny_run};

/// The task of the first training array the test cancels.
const CANCELLED_TASK: usize = 2;

/// Runs `cmd` and returns its stdout (panics when it fails).
fn output(cmd: &str, args: &[&str]) -> String {
    let out = Command::new(cmd)
        .args(args)
        .output()
        .expect("slurm command runs");
    assert!(
        out.status.success(),
        "{cmd} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Starts the Slurm reproduction into `out`, every array held.
fn start(out: &Path) -> Child {
    evtac()
        .args(tiny_args(out))
        .args(["--executor", "slurm", "--slurm-args=--hold"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("evtac starts")
}

/// Releases every held `evtac-*` array until `child` exits; when `cancel` is set, first cancels
/// task [`CANCELLED_TASK`] of the first training array. Returns the child's success and stderr.
fn follow(mut child: Child, mut cancel: bool) -> (bool, String) {
    let started = Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            let out = child.wait_with_output().expect("output");
            return (
                status.success(),
                String::from_utf8_lossy(&out.stderr).into_owned(),
            );
        }
        assert!(
            started.elapsed() < Duration::from_secs(600),
            "the Slurm reproduction did not finish in 10 minutes"
        );
        let queue = output("squeue", &["--noheader", "--array", "--format=%F %K %j %r"]);
        for line in queue.lines() {
            let f: Vec<&str> = line.split_whitespace().collect();
            let [job, task, name, reason] = f[..] else {
                continue;
            };
            if !name.starts_with("evtac-") || reason != "JobHeldUser" {
                continue;
            }
            if cancel && name == "evtac-train-1" && task == CANCELLED_TASK.to_string() {
                output("scancel", &[&format!("{job}_{task}")]);
                cancel = false;
            } else if !cancel || name != "evtac-train-1" {
                // `%K` is the task id, or `N/A` for a job that is not an array.
                let id = match task.parse::<usize>() {
                    Ok(task) => format!("{job}_{task}"),
                    Err(_) => job.to_string(),
                };
                output("scontrol", &["release", &id]);
            }
        }
        std::thread::sleep(Duration::from_millis(300));
    }
}

/// `results.json` without what depends on the machine's pace (stage times, latency, the
/// end-to-end replay).
fn results_without_timing(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("results.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["run"]["stage_seconds"] = serde_json::Value::Null;
    v["run"]["stage_history"] = serde_json::Value::Null;
    v["latency"] = serde_json::Value::Null;
    v["paced_latency"] = serde_json::Value::Null;
    v
}

/// Every model file (weights and config, not the wall-clock training history) under `out`.
fn model_files(out: &Path) -> Vec<(String, Vec<u8>)> {
    fn walk(dir: &Path, root: &Path, into: &mut Vec<(String, Vec<u8>)>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, root, into);
            } else if path
                .extension()
                .is_some_and(|e| e == "safetensors" || e == "json")
            {
                let name = path.strip_prefix(root).unwrap().display().to_string();
                into.push((name, std::fs::read(&path).unwrap()));
            }
        }
    }
    let mut files = Vec::new();
    walk(&out.join("models"), out, &mut files);
    files.sort();
    files
}

#[test]
fn slurm_reproduction_resumes_after_a_cancelled_task_and_matches_the_local_run() {
    if !evtac_testkit::slurm_cluster() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");

    let (ok, stderr) = follow(start(&out), true);
    assert!(!ok, "the run with a cancelled task succeeded:\n{stderr}");
    for what in [
        format!("task {CANCELLED_TASK} not listed by Slurm (cancelled before it started"),
        "`train-1` array".to_string(),
        "run the same command again to resume".to_string(),
    ] {
        assert!(stderr.contains(&what), "no `{what}` in:\n{stderr}");
    }
    let first_round = std::fs::read_to_string(out.join("slurm/train-1.jobs")).unwrap();

    let (ok, stderr) = follow(start(&out), false);
    assert!(ok, "the resumed run failed:\n{stderr}");
    // The resumed run submitted only the cancelled job of the first round.
    let resumed = std::fs::read_to_string(out.join("slurm/train-1.jobs")).unwrap();
    assert_eq!(
        resumed.lines().collect::<Vec<_>>(),
        [first_round.lines().nth(CANCELLED_TASK).unwrap()]
    );

    let local = tiny_run();
    assert_eq!(results_without_timing(&out), results_without_timing(local));
    let (slurm, local) = (model_files(&out), model_files(local));
    assert_eq!(
        slurm.iter().map(|(n, _)| n).collect::<Vec<_>>(),
        local.iter().map(|(n, _)| n).collect::<Vec<_>>()
    );
    for ((name, a), (_, b)) in slurm.iter().zip(&local) {
        assert!(a == b, "{name} differs from the local run's");
    }
    assert!(out.join("report.md").is_file());
}

#[test]
fn slurm_sensitivity_runs_a_task_per_point_and_matches_the_local_study() {
    if !evtac_testkit::slurm_cluster() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    let run = evtac()
        .args(crate::sensitivity::tiny_study_args(&out))
        .args(["--executor", "slurm"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    // One task per point: the baseline and the parameter at its two factors.
    let jobs = evtac_experiments::job::read(&out.join("slurm/sensitivity.jobs")).unwrap();
    assert_eq!(jobs.len(), 3, "{jobs:?}");
    let logs = std::fs::read_dir(out.join("slurm"))
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().ends_with(".out"))
        .count();
    assert_eq!(logs, 3, "one log per task");
    let (local, _) = crate::sensitivity::tiny_study();
    assert!(
        std::fs::read(out.join("sensitivity.json")).unwrap()
            == std::fs::read(local.join("sensitivity.json")).unwrap(),
        "the Slurm study differs from the local one"
    );
    // Run again: nothing is left to submit, and the summary is the same.
    let again = evtac()
        .args(crate::sensitivity::tiny_study_args(&out))
        .args(["--executor", "slurm"])
        .output()
        .unwrap();
    assert!(again.status.success());
    assert!(
        !String::from_utf8_lossy(&again.stderr).contains("submitted as Slurm job"),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
}
