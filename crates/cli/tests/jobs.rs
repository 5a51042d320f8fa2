//! Tests of `evtac jobs`: running one job of a jobs file, as a Slurm array task does. Running an
//! exported training job for real is in `reproduce.rs`.

use crate::common::{evtac, run_err, run_ok};
use evtac_experiments::job::{self, Job, SimulateJob, TrainJob};
use evtac_experiments::sampling::{Phase, Sampling};
use evtac_experiments::training::TrainSpec;
use evtac_import::inputs::Inputs;
use evtac_repr::{ReprConfig, StaticConfig};
use evtac_sim::{Protocol, Scale};

/// A jobs file of two jobs in `dir`: a training job on a dataset that does not exist, and a
/// simulation.
fn jobs_file(dir: &std::path::Path) -> std::path::PathBuf {
    let jobs = [
        Job::Train(TrainJob {
            dataset: dir.join("no such dataset"),
            inputs: Inputs::from_flags(false, true),
            splits_seed: 2,
            spec: TrainSpec {
                repr: ReprConfig::Static(StaticConfig {
                    tau_ms: 250.0,
                    ..StaticConfig::default()
                }),
                seed: 4,
                epochs: 3,
                sampling: Sampling::MOTION,
                phases: vec![Phase::Motion],
                label_noise_deg: 0.0,
            },
            out: dir.join("model"),
        }),
        Job::Simulate(SimulateJob {
            protocol: Protocol::Exp1,
            scale: Scale::Tiny,
            seed: 1,
            out: dir.join("exp1"),
            repeats: None,
        }),
    ];
    let file = dir.join("test.jobs");
    job::write(&file, &jobs).unwrap();
    file
}

#[test]
fn count_and_show_list_the_jobs_as_the_commands_they_equal() {
    let dir = tempfile::tempdir().unwrap();
    let file = jobs_file(dir.path());
    let file = file.to_str().unwrap();
    let count = run_ok(&["jobs", "count", file]);
    assert_eq!(String::from_utf8_lossy(&count.stdout).trim(), "2");
    let show = String::from_utf8_lossy(&run_ok(&["jobs", "show", file]).stdout).into_owned();
    let lines: Vec<&str> = show.lines().collect();
    assert_eq!(lines.len(), 2, "{show}");
    for part in [
        "evtac train ",
        " --repr static --tau-ms 250 --threshold 2 --epochs 3 --seed 4 --splits-seed 2 --no-mask ",
    ] {
        assert!(lines[0].contains(part), "no `{part}` in {}", lines[0]);
    }
    assert!(
        lines[1].contains("evtac simulate --protocol exp1 --scale tiny --seed 1 --out "),
        "{}",
        lines[1]
    );
}

#[test]
fn a_failing_job_and_a_missing_index_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let file = jobs_file(dir.path());
    let file = file.to_str().unwrap();
    let err = run_err(&["jobs", "run", file, "--index", "0"]);
    assert!(
        err.contains("job 0 of") && err.contains("no such dataset"),
        "{err}"
    );
    assert!(!dir.path().join("model").exists());
    let err = run_err(&["jobs", "run", file, "--index", "2"]);
    assert!(
        err.contains("holds 2 jobs (indices 0 to 1); there is no job 2"),
        "{err}"
    );
}

#[test]
fn a_jobs_file_of_command_lines_asks_to_export_again() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("old.jobs");
    std::fs::write(
        &file,
        "evtac train data/exp1 --repr static --out m --quiet\n",
    )
    .unwrap();
    let out = evtac()
        .args(["jobs", "run", file.to_str().unwrap(), "--index", "0"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("old.jobs:1: this jobs file holds command lines")
            && err.contains("--export-jobs"),
        "{err}"
    );
}
