//! Tests of `evtac online`.

use crate::common::{evtac, run_ok, simulate_tiny};
use evtac_learn::{ModelBundle, Representation};
use evtac_repr::ReprConfig;
use std::io::Write;
use std::path::Path;
use std::process::Stdio;

/// An untrained bundle (weights from a seed) with the default representation.
fn bundle(dir: &Path) {
    ModelBundle::untrained(4, Representation::new(ReprConfig::default()), None)
        .save(dir)
        .unwrap();
}

/// 50 ms of events around the sensor's centre, as `t,x,y,p` CSV.
fn csv_events() -> String {
    let mut csv = String::from("t,x,y,p\n");
    for i in 0..20_000i64 {
        let t = 1_000_000 + i * 50_000 / 20_000;
        let x = 220 + (i * 7919 % 200);
        let y = 140 + (i * 104_729 % 200);
        csv.push_str(&format!("{t},{x},{y},{}\n", i % 3 == 0));
    }
    csv.replace("true", "1").replace("false", "0")
}

fn rows(csv: &str) -> Vec<Vec<String>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn replays_a_csv_file_and_standard_input_alike() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    bundle(&model);
    let events = dir.path().join("events.csv");
    std::fs::write(&events, csv_events()).unwrap();
    let out = dir.path().join("estimates.csv");
    let run = run_ok(&[
        "online",
        "--model",
        model.to_str().unwrap(),
        "--input",
        events.to_str().unwrap(),
        "--sensor",
        "640x480",
        "--output",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("t_us,pitch_deg,roll_deg,latency_us\n"));
    let file_rows = rows(&text);
    // 1,000,000 .. 1,049,997 us: estimates at every millisecond from 1,000,000 to 1,049,000.
    assert_eq!(file_rows.len(), 50, "{stderr}");
    for (k, row) in file_rows.iter().enumerate() {
        assert_eq!(row.len(), 4);
        assert_eq!(row[0], (1_000_000 + 1000 * k as i64).to_string());
        assert!(row[3].parse::<f64>().unwrap() >= 0.0);
    }
    assert!(stderr.contains("estimates: 50 every 1000 us"), "{stderr}");
    assert!(stderr.contains("20000 received"), "{stderr}");
    assert!(stderr.contains("0 dropped"), "{stderr}");

    // The same events on standard input give the same estimates.
    let mut child = evtac()
        .args(["online", "--model", model.to_str().unwrap(), "--input", "-"])
        .args(["--sensor", "640x480", "--interval-ms", "1"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(csv_events().as_bytes())
        .unwrap();
    let piped = child.wait_with_output().unwrap();
    assert!(
        piped.status.success(),
        "{}",
        String::from_utf8_lossy(&piped.stderr)
    );
    let stdin_rows = rows(&String::from_utf8_lossy(&piped.stdout));
    let values = |r: &[Vec<String>]| -> Vec<[String; 3]> {
        r.iter()
            .map(|r| [r[0].clone(), r[1].clone(), r[2].clone()])
            .collect()
    };
    assert_eq!(values(&stdin_rows), values(&file_rows));
}

#[test]
fn bad_inputs_fail_with_clear_messages() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    bundle(&model);
    let events = dir.path().join("events.csv");
    std::fs::write(&events, csv_events()).unwrap();
    let fail = |args: &[&str]| {
        let out = evtac().args(args).output().unwrap();
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let m = model.to_str().unwrap();
    let e = events.to_str().unwrap();
    let msg = fail(&["online", "--model", m, "--input", "tcp://localhost"]);
    assert!(msg.contains("tcp://HOST:PORT"), "{msg}");
    let msg = fail(&["online", "--model", m, "--input", e]);
    assert!(msg.contains("--sensor"), "{msg}");
    let msg = fail(&[
        "online",
        "--model",
        m,
        "--input",
        e,
        "--sensor",
        "640x480",
        "--interval-ms",
        "0",
    ]);
    assert!(msg.contains("--interval-ms"), "{msg}");
    let msg = fail(&[
        "online",
        "--model",
        dir.path().to_str().unwrap(),
        "--input",
        e,
    ]);
    assert!(
        msg.contains("model.safetensors") || msg.contains("model bundle"),
        "{msg}"
    );
    // Nothing listens on the port: bounded retries, then a message naming the input.
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let input = format!("tcp://127.0.0.1:{port}");
    let msg = fail(&[
        "online",
        "--model",
        m,
        "--input",
        &input,
        "--reconnect-attempts",
        "1",
        "--reconnect-initial-ms",
        "10",
    ]);
    assert!(msg.contains(&input) && msg.contains("attempt"), "{msg}");
}

#[test]
fn ctrl_c_ends_a_live_run_with_its_summary() {
    use std::io::{BufRead, BufReader};
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    bundle(&model);
    let mut child = evtac()
        .args(["online", "--model", model.to_str().unwrap(), "--input", "-"])
        .args(["--sensor", "640x480"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Events go in, and standard input stays open: a live producer that has gone quiet.
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(csv_events().as_bytes()).unwrap();
    stdin.flush().unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    let mut estimates = 0;
    while estimates < 10 {
        line.clear();
        assert!(
            stdout.read_line(&mut line).unwrap() > 0,
            "stdout ended early"
        );
        if line.starts_with(|c: char| c.is_ascii_digit()) {
            estimates += 1;
        }
    }
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut stdout, &mut rest).unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(stderr.contains("stopping"), "{stderr}");
    // The summary counts every estimate written.
    let total = estimates + rest.lines().count();
    assert!(
        stderr.contains(&format!("estimates: {total} every 1000 us")),
        "{total}: {stderr}"
    );
    drop(stdin);
}

/// Issue 19: a recording replayed as fast as possible is read far ahead of the estimator, so
/// its "latency" is mostly queueing (a P99 of milliseconds against about a hundred microseconds
/// at `--realtime`). Its summary must lead with the processing time per estimate and say that
/// latency needs `--realtime`; a paced replay still reports latency.
#[test]
fn a_replay_as_fast_as_possible_reports_processing_time_not_latency() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    bundle(&model);
    let ds = dir.path().join("ds");
    simulate_tiny("exp1", 3, &ds, 1);
    let manifest = evtac_events::manifest::Manifest::read(&ds).unwrap();
    let trial = ds.join(&manifest.trials[0].file);
    let (m, t) = (model.to_str().unwrap(), trial.to_str().unwrap());
    let out = dir.path().join("estimates.csv");
    let o = out.to_str().unwrap();
    let run = run_ok(&["online", "--model", m, "--input", t, "--output", o]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with("estimates: "))
        .unwrap_or_else(|| panic!("no summary in:\n{stderr}"));
    assert!(
        lines[at + 1].starts_with("processing time per estimate: median "),
        "the processing time is not the headline:\n{stderr}"
    );
    assert!(
        lines[at + 2].starts_with("latency: not measured") && lines[at + 2].contains("--realtime"),
        "no note that latency needs --realtime:\n{stderr}"
    );
    assert!(!stderr.contains("late (latency"), "{stderr}");
    let estimates = std::fs::read_to_string(&out).unwrap().lines().count() - 1;
    assert!(estimates > 100, "{estimates} estimates:\n{stderr}");

    // At recorded pace the latency is reported (a quarter second of the trial is enough).
    let paced = run_ok(&[
        "online",
        "--model",
        m,
        "--input",
        t,
        "--output",
        o,
        "--realtime",
        "--max-duration-s",
        "0.25",
    ]);
    let stderr = String::from_utf8_lossy(&paced.stderr);
    assert!(stderr.contains("\nlatency: median "), "{stderr}");
    assert!(stderr.contains("late (latency > interval)"), "{stderr}");
    assert!(
        stderr.contains("processing time per estimate: median "),
        "{stderr}"
    );
    assert!(!stderr.contains("not measured"), "{stderr}");
}
