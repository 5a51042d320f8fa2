//! Helpers shared by the CLI tests: running the built `evtac` binary.

#![allow(dead_code)]

use std::process::{Command, Output};

/// A `Command` for the `evtac` binary built with these tests.
pub fn evtac() -> Command {
    Command::new(env!("CARGO_BIN_EXE_evtac"))
}

/// Runs `evtac` with `args`, panicking with its stderr when it fails; returns its output.
pub fn run_ok(args: &[&str]) -> Output {
    let out = evtac().args(args).output().expect("evtac runs");
    assert!(
        out.status.success(),
        "evtac {args:?} failed: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs `evtac` with `args`, expecting it to fail; returns its stderr.
pub fn run_err(args: &[&str]) -> String {
    let out = evtac().args(args).output().expect("evtac runs");
    assert!(!out.status.success(), "evtac {args:?} should have failed");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Simulates the first `limit` trials of `protocol` at the tiny scale with `seed` into `out`.
pub fn simulate_tiny(protocol: &str, seed: u64, out: &std::path::Path, limit: usize) {
    simulate(protocol, seed, out, Some(limit), false);
}

/// Simulates a session of the first `limit` trials (all without) of `protocol` at the tiny
/// scale with `seed` into `out`.
pub fn simulate_session_tiny(
    protocol: &str,
    seed: u64,
    out: &std::path::Path,
    limit: Option<usize>,
) {
    simulate(protocol, seed, out, limit, true);
}

fn simulate(protocol: &str, seed: u64, out: &std::path::Path, limit: Option<usize>, session: bool) {
    let seed = seed.to_string();
    let limit = limit.map(|l| l.to_string());
    let out = out.to_str().expect("utf-8 path");
    let mut args = vec![
        "simulate",
        "--protocol",
        protocol,
        "--scale",
        "tiny",
        "--seed",
        &seed,
        "--out",
        out,
    ];
    if let Some(limit) = &limit {
        args.extend(["--limit", limit]);
    }
    if session {
        args.push("--session");
    }
    run_ok(&args);
}
