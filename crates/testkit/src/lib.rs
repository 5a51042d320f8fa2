//! Test support shared by evtac's crates: where the shared fixtures are, and how to reach the
//! Python reference tools (dv-processing, numpy, safetensors, Pillow) and ffmpeg that interop
//! tests compare against.
//!
//! Fixtures live in `../shared` beside the checkout, or wherever `$EVTAC_SHARED` points. The
//! Python interpreter is `$EVTAC_PYTHON`, else `.venv/bin/python` at the workspace root (made by
//! `bash .ci/python-env`). Under CI (`CI` set) a missing fixture or interpreter fails the test;
//! elsewhere the test says it was skipped and passes, so `cargo test` works on a bare machine.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root (two levels above this crate).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .expect("testkit lives at crates/testkit")
        .to_path_buf()
}

fn in_ci() -> bool {
    std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false")
}

fn missing(what: &str) -> Option<PathBuf> {
    if in_ci() {
        panic!("{what} is required under CI but was not found");
    }
    // Straight to the process's standard error: libtest captures `eprintln!` and shows it only
    // for failing tests or with `--nocapture`, and a skipped test must say so in a plain run.
    let _ = std::io::Write::write_all(
        &mut std::io::stderr(),
        format!("skipped: {what} not found\n").as_bytes(),
    );
    None
}

/// The shared folder (`$EVTAC_SHARED` or `../shared` beside the checkout), or `None` (test
/// skipped) when absent outside CI.
pub fn shared_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("EVTAC_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("..").join("shared"));
    if dir.join("fixtures").is_dir() {
        Some(dir)
    } else {
        missing(&format!("the shared fixtures folder {}", dir.display()))
    }
}

/// A file under `shared/fixtures/real/`, or `None` (test skipped) outside CI when absent.
pub fn real_fixture(name: &str) -> Option<PathBuf> {
    let path = shared_dir()?.join("fixtures").join("real").join(name);
    if path.is_file() {
        Some(path)
    } else {
        missing(&format!("the fixture {}", path.display()))
    }
}

/// The Python interpreter with the reference tools installed, or `None` (test skipped) outside CI.
pub fn python() -> Option<PathBuf> {
    let candidate = std::env::var_os("EVTAC_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join(".venv").join("bin").join("python"));
    if candidate.is_file() {
        Some(candidate)
    } else {
        missing("the Python reference environment (run `bash .ci/python-env`)")
    }
}

/// The reference Python when it can import `module` (e.g. `cyclonedds`, installed by
/// `bash .ci/python-env`), or `None` (test skipped) outside CI.
pub fn python_with(module: &str) -> Option<PathBuf> {
    let python = python()?;
    let imports = Command::new(&python)
        .args(["-c", &format!("import {module}")])
        .output()
        .is_ok_and(|o| o.status.success());
    if imports {
        Some(python)
    } else {
        missing(&format!(
            "the Python module {module} in {} (run `bash .ci/python-env`)",
            python.display()
        ))
    }
}

/// Runs `script` with the reference Python and `args`; returns its stdout. Panics with the
/// script's stderr when it fails. `None` when Python is unavailable outside CI.
pub fn run_python(script: &str, args: &[&str]) -> Option<String> {
    let python = python()?;
    let out = Command::new(&python)
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("could not start {}: {e}", python.display()));
    if !out.status.success() {
        panic!(
            "python script failed ({}):\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Some(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Whether `ffmpeg` and `ffprobe` run from the `PATH` (`evtac render`'s MP4 output and its
/// independent decoder). `false` (test skipped) outside CI when either is missing; `.ci/run`
/// installs them (`.ci/system-packages`).
pub fn ffmpeg() -> bool {
    let runs = |tool: &str| {
        Command::new(tool)
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success())
    };
    (runs("ffmpeg") && runs("ffprobe"))
        || missing("ffmpeg and ffprobe on the PATH (`apt install ffmpeg`)").is_some()
}

/// Whether a Slurm cluster answers on this machine (`scontrol ping`; `bash .ci/slurm-up` starts
/// one). `false` (test skipped) outside CI when none does.
pub fn slurm_cluster() -> bool {
    let up = Command::new("scontrol")
        .arg("ping")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("is UP"));
    up || missing("a running Slurm cluster (`bash .ci/slurm-up` starts one)").is_some()
}
