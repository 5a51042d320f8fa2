//! What publishing on ROS 2 adds to an estimate: from the estimate handed to the publisher to a
//! Cyclone DDS subscriber (Python binding, `tests/support/ros2_subscriber.py`) having it, on
//! loopback, one estimate per millisecond as a live sensor gives them. The goal of issue 36:
//! P99 under 100 us.
//!
//! The subscriber polls its reader (`poll` mode) rather than waiting in a `WaitSet`, so the time
//! is when Cyclone had the sample rather than when the operating system woke Python up (the
//! interop test, `tests/ros2.rs`, measures that waking subscriber too; its figures in
//! `docs/online.md`). Both sides stamp the wall clock (`SystemTime`, Python's `time.time_ns`).
//!
//! `cargo bench -p evtac-online --bench ros2_latency` (with `EVTAC_PYTHON` naming a Python
//! that has `cyclonedds`); `EVTAC_ROS2_BENCH_RUNS` runs (5) of 3,000 estimates each. Prints each
//! run's median, P99 and maximum, then all runs pooled.
//!
//! Where the time goes: with `EVTAC_ROS2_BENCH_DUMP=FILE` every estimate is appended to FILE as
//! `t_us handed_ns received_ns`; `benches/ros2_hops.py` captures the datagrams on `lo` meanwhile
//! (as root) and splits each estimate's time at the moment its DATA crossed loopback: evtac's
//! side (the write, RustDDS's event loop waking and sending) and the subscriber's (Cyclone's
//! receive thread waking and storing the sample, the polling loop finding it).

#[path = "../tests/support/mod.rs"]
mod support;

use evtac_learn::Model;
use evtac_online::Estimator;
use evtac_online::input::{MemorySource, Paced};
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::ros2::Ros2Publisher;
use std::io::{BufRead, BufReader, Write};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, SystemTime, UNIX_EPOCH};
use support::dds::{CYCLONE_LOOPBACK, loopback_options, random_domain};

fn wall_ns() -> i128 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as i128)
}

/// `(median, P99, max)` of `ns` in microseconds.
fn figures(ns: &mut [i128]) -> (f64, f64, f64) {
    ns.sort_unstable();
    let at = |q: f64| ns[((ns.len() - 1) as f64 * q).round() as usize] as f64 / 1000.0;
    (at(0.5), at(0.99), at(1.0))
}

/// One run: the added latency of every estimate, in nanoseconds.
fn run(python: &PathBuf, model: &Model, run: u32) -> Vec<i128> {
    let domain = random_domain(20 + run);
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/support/ros2_subscriber.py");
    let mut child = Command::new(python)
        .arg(script)
        .args([&domain.to_string(), "rt/contact_angle", "2", "120", "poll"])
        .env("CYCLONEDDS_URI", CYCLONE_LOOPBACK)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("the subscriber starts");
    let mut lines = BufReader::new(child.stdout.take().expect("piped")).lines();
    assert_eq!(lines.next().and_then(Result::ok).as_deref(), Some("ready"));
    let publisher = Ros2Publisher::new(loopback_options(domain, "neurotac")).expect("publisher");
    assert!(publisher.wait_for_subscribers(1, Duration::from_secs(30)));
    let events = support::Synthetic::new(9 + u64::from(run), 300_000.0, 1000, 3_000_000).collect();
    let source = Paced::new(MemorySource::new(events, 4096), 1000);
    let estimator = Estimator::for_model(model, support::SENSOR, 1000).expect("estimator");
    let mut handed: Vec<(i64, i128)> = Vec::with_capacity(3100);
    pipeline::run(source, estimator, &PipelineConfig::default(), |out| {
        if let Output::Estimate(e) = out {
            handed.push((e.t_us, wall_ns()));
            publisher.publish(&e);
        }
        ControlFlow::Continue(())
    })
    .expect("the run");
    let stats = publisher.finish();
    assert_eq!(stats.dropped(), 0, "{stats}");
    eprintln!("{stats}");
    let mut added = Vec::with_capacity(handed.len());
    let mut dump = std::env::var_os("EVTAC_ROS2_BENCH_DUMP").map(|path| {
        std::fs::OpenOptions::new()
            .append(true)
            .create(true)
            .open(path)
            .expect("the dump opens")
    });
    for line in lines.map_while(Result::ok) {
        if line == "end" {
            break;
        }
        let f: Vec<&str> = line.split(' ').collect();
        let recv: i128 = f[0].parse().expect("recv_ns");
        let (sec, nanosec): (i64, i64) = (f[1].parse().expect("sec"), f[2].parse().expect("ns"));
        let t_us = sec * 1_000_000 + nanosec / 1000;
        if let Ok(k) = handed.binary_search_by_key(&t_us, |&(t, _)| t) {
            added.push(recv - handed[k].1);
            if let Some(dump) = &mut dump {
                writeln!(dump, "{t_us} {} {recv}", handed[k].1).expect("the dump is written");
            }
        }
    }
    let _ = child.wait();
    assert_eq!(added.len(), handed.len(), "every estimate received");
    added
}

fn main() {
    let Some(python) = evtac_testkit::python_with("cyclonedds") else {
        eprintln!("ros2_latency: no Python with cyclonedds (set EVTAC_PYTHON); skipped");
        return;
    };
    let runs: u32 = std::env::var("EVTAC_ROS2_BENCH_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let dir = tempfile::tempdir().expect("tempdir");
    let (_, repr) = support::representations()[2];
    support::seeded_bundle(dir.path(), 3, &repr, None);
    let model = Model::load(dir.path()).expect("model");
    let mut all = Vec::new();
    for k in 0..runs {
        let mut added = run(&python, &model, k);
        let (median, p99, max) = figures(&mut added);
        println!(
            "run {}: {} estimates at 1 ms, added latency median {median:.0} us, P99 {p99:.0} us, \
             max {max:.0} us",
            k + 1,
            added.len()
        );
        all.extend(added);
    }
    let (median, p99, max) = figures(&mut all);
    println!(
        "all {runs} runs: {} estimates, median {median:.0} us, P99 {p99:.0} us, max {max:.0} us",
        all.len()
    );
}
