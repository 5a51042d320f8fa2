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

/// Simulates the first `limit` trials of `protocol` at the tiny scale with `seed` into `out`.
pub fn simulate_tiny(protocol: &str, seed: u64, out: &std::path::Path, limit: usize) {
    let (seed, limit) = (seed.to_string(), limit.to_string());
    let out = out.to_str().expect("utf-8 path");
    run_ok(&[
        "simulate",
        "--protocol",
        protocol,
        "--scale",
        "tiny",
        "--seed",
        &seed,
        "--out",
        out,
        "--limit",
        &limit,
    ]);
}
