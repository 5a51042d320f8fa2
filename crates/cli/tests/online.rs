//! Tests of `evtac online`.

use crate::common::{evtac, run_err, run_ok, simulate_tiny};
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

/// Cyclone DDS on loopback only, discovering peers by unicast to 127.0.0.1 (as the online
/// crate's ROS 2 tests run it).
const CYCLONE_LOOPBACK: &str = "<CycloneDDS><Domain id=\"any\"><General><Interfaces>\
     <NetworkInterface name=\"lo\"/></Interfaces><AllowMulticast>false</AllowMulticast>\
     </General><Discovery><ParticipantIndex>auto</ParticipantIndex>\
     <MaxAutoParticipantIndex>20</MaxAutoParticipantIndex><Peers>\
     <Peer address=\"127.0.0.1\"/></Peers></Discovery></Domain></CycloneDDS>";

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

/// `--ros2`: a Cyclone DDS subscriber (Python binding, ROS 2's IDL types for
/// `geometry_msgs/msg/Vector3Stamped`, reliable) on loopback receives one message per CSV row,
/// stamped with its `t_us`, carrying its degrees in radians, in the frame `--frame-id` names;
/// the summary reports the publishing. The subscriber script is the online crate's.
#[test]
fn ros2_publishes_what_the_csv_holds() {
    use std::io::{BufRead, BufReader};
    let Some(python) = evtac_testkit::python_with("cyclonedds") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    bundle(&model);
    // 400 ms of events whose density and position change every 20 ms, so that estimates vary.
    let mut csv = String::from("t,x,y,p\n");
    for i in 0..60_000i64 {
        let t = 2_000_000 + i * 400_000 / 60_000;
        let phase = (t / 20_000) % 7;
        let x = 220 + (i * 7919 % (60 + 20 * phase));
        let y = 140 + (i * 104_729 % (200 - 20 * phase));
        csv.push_str(&format!("{t},{x},{y},{}\n", i32::from(i % 3 == 0)));
    }
    let events = dir.path().join("events.csv");
    std::fs::write(&events, csv).unwrap();
    let domain =
        1 + (std::process::id() ^ std::time::UNIX_EPOCH.elapsed().unwrap().subsec_nanos()) % 230;
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../online/tests/support/ros2_subscriber.py");
    let mut subscriber = std::process::Command::new(python)
        .arg(script)
        .args([&domain.to_string(), "rt/robot/contact_angle", "3", "120"])
        .env("CYCLONEDDS_URI", CYCLONE_LOOPBACK)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut received = BufReader::new(subscriber.stdout.take().unwrap());
    let mut line = String::new();
    received.read_line(&mut line).unwrap();
    assert_eq!(line.trim(), "ready");

    let out = dir.path().join("estimates.csv");
    let run = evtac()
        .args(["online", "--model", model.to_str().unwrap()])
        .args(["--input", events.to_str().unwrap(), "--sensor", "640x480"])
        .args(["--realtime", "--output", out.to_str().unwrap()])
        .args([
            "--ros2",
            "/robot/contact_angle",
            "--frame-id",
            "left_finger",
        ])
        .args([
            "--ros-domain",
            &domain.to_string(),
            "--ros-interface",
            "127.0.0.1",
        ])
        .args(["--ros2-wait-subscribers", "1"])
        .env_remove("ROS_DOMAIN_ID")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    if !run.status.success() {
        let _ = subscriber.kill();
        panic!("evtac online failed: {stderr}");
    }
    let rows = rows(&std::fs::read_to_string(&out).unwrap());
    assert!(rows.len() >= 390, "{} rows: {stderr}", rows.len());
    assert!(
        stderr.contains(&format!(
            "ROS 2 /robot/contact_angle (DDS rt/robot/contact_angle, domain {domain}): {} \
             published, 0 dropped",
            rows.len()
        )),
        "{stderr}"
    );
    let mut samples = Vec::new();
    for line in received.lines() {
        let line = line.unwrap();
        if line == "end" {
            break;
        }
        samples.push(line);
    }
    assert!(subscriber.wait().unwrap().success());
    assert_eq!(
        samples.len(),
        rows.len(),
        "messages received vs CSV rows; first received {:?}, first row {:?}; last received \
         {:?}, last row {:?}",
        samples.first(),
        rows.first(),
        samples.last(),
        rows.last()
    );
    for (row, sample) in rows.iter().zip(&samples) {
        let f: Vec<&str> = sample.split(' ').collect();
        let t_us: i64 = row[0].parse().unwrap();
        let (sec, nanosec): (i64, i64) = (f[1].parse().unwrap(), f[2].parse().unwrap());
        assert_eq!(sec * 1_000_000 + nanosec / 1000, t_us, "{sample}");
        assert_eq!(nanosec % 1000, 0);
        assert_eq!(f[3], "left_finger");
        for (deg, rad) in [(&row[1], f[4]), (&row[2], f[5])] {
            let expected = f64::from(deg.parse::<f32>().unwrap()).to_radians();
            assert_eq!(
                rad.parse::<f64>().unwrap().to_bits(),
                expected.to_bits(),
                "t = {t_us}: {deg} degrees published as {rad}"
            );
        }
        assert_eq!(f[6], "0.0");
    }
}

#[test]
fn ros2_flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    bundle(&model);
    let events = dir.path().join("events.csv");
    std::fs::write(&events, csv_events()).unwrap();
    let (m, e) = (model.to_str().unwrap(), events.to_str().unwrap());
    let base = ["online", "--model", m, "--input", e, "--sensor", "640x480"];
    let with = |extra: &[&'static str]| [&base[..], extra].concat();
    let msg = run_err(&with(&["--ros2", "/contact-angle", "--ros-domain", "9"]));
    assert!(msg.contains("invalid ROS 2 topic name"), "{msg}");
    let msg = run_err(&with(&["--ros2", "/contact_angle", "--ros-domain", "240"]));
    assert!(msg.contains("domain id 240"), "{msg}");
    // --frame-id without --ros2 or --mcap is a mistake worth saying.
    let msg = run_err(&with(&["--frame-id", "x"]));
    assert!(msg.contains("--ros2"), "{msg}");
    let out = evtac()
        .args(with(&["--ros2", "/contact_angle"]))
        .env("ROS_DOMAIN_ID", "abc")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(msg.contains("ROS_DOMAIN_ID=\"abc\""), "{msg}");
    // Nobody subscribes in this domain: waiting for one fails, naming the topic and domain.
    let msg = run_err(&with(&[
        "--ros2",
        "/contact_angle",
        "--ros-domain",
        "231",
        "--ros-interface",
        "127.0.0.1",
        "--ros2-wait-subscribers",
        "1",
        "--ros2-wait-timeout-s",
        "0.5",
    ]));
    assert!(
        msg.contains("0 of 1 ROS 2 subscriber(s) matched on /contact_angle in domain 231"),
        "{msg}"
    );
    // The ROS 2 input's flags.
    let msg = run_err(&with(&["--ros-domain", "9"]));
    assert!(
        msg.contains("--ros-domain and --ros-interface are for --ros2 and ros2:// inputs"),
        "{msg}"
    );
    let msg = run_err(&with(&["--ros-event-type", "dvs_msgs/msg/EventArray"]));
    assert!(
        msg.contains("--ros-event-type is the message type of a ros2:// input"),
        "{msg}"
    );
    let ros2_input = ["online", "--model", m, "--input", "ros2:///nobody/events"];
    let msg = run_err(
        &[
            &ros2_input[..],
            &["--ros-event-type", "sensor_msgs/msg/Image"],
        ]
        .concat(),
    );
    assert!(
        msg.contains("not an event message type evtac reads"),
        "{msg}"
    );
    let msg = run_err(&["online", "--model", m, "--input", "ros2:///cam-0/events"]);
    assert!(
        msg.contains("input `ros2:///cam-0/events`: invalid ROS 2 topic name"),
        "{msg}"
    );
    // Nobody publishes in this domain: opening fails, naming the topic and domain.
    let started = std::time::Instant::now();
    let msg = run_err(
        &[
            &ros2_input[..],
            &["--ros-domain", "231", "--ros-interface", "127.0.0.1"],
            &["--connect-timeout-s", "0.3", "--reconnect-attempts", "0"],
        ]
        .concat(),
    );
    assert!(
        msg.contains(
            "could not reach ros2:///nobody/events: no publisher of /nobody/events (DDS \
             rt/nobody/events) discovered in domain 231 within 0.3 s"
        ) && msg.contains(
            "no sample on ROS 2 topic /nobody/events (DDS rt/nobody/events) in domain 231 after 1 \
             attempts"
        ),
        "{msg}"
    );
    assert!(started.elapsed() < std::time::Duration::from_secs(10));
}

/// `--input ros2://`: a Cyclone DDS publisher (the online crate's
/// `tests/support/ros2_publisher.py`, a default rclpy publisher's QoS) sends the real EVT3
/// fixture's words as `event_camera_msgs/msg/EventPacket`s; the estimates equal, row for row
/// and bit for bit, those of the same events from files: the MCAP bag of the messages sent,
/// and the camera's `.raw` file. The publisher leaves after its last packet, and the run ends a
/// stall timeout later with the input's summary line.
#[test]
fn ros2_input_estimates_as_the_same_events_from_files() {
    use std::io::{BufRead, BufReader};
    let Some(python) = evtac_testkit::python_with("cyclonedds") else {
        return;
    };
    if evtac_testkit::python_with("mcap").is_none() {
        return;
    }
    let (Some(raw), Some(npy)) = (
        evtac_testkit::real_fixture("prophesee_gen4_1280x720.evt3.raw"),
        evtac_testkit::real_fixture("prophesee_gen4_1280x720.evt3.expected.npy"),
    ) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    bundle(&model);
    let bag = dir.path().join("published.mcap");
    let domain =
        1 + (std::process::id() ^ std::time::UNIX_EPOCH.elapsed().unwrap().subsec_nanos()) % 230;
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../online/tests/support/ros2_publisher.py");
    let mut publisher = std::process::Command::new(python)
        .arg(script)
        .args([
            &domain.to_string(),
            "rt/event_camera/events",
            "packet",
            "reliable",
        ])
        .args([raw.as_os_str(), npy.as_os_str(), bag.as_os_str()])
        .args(["all", "leave"])
        .env("CYCLONEDDS_URI", CYCLONE_LOOPBACK)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let m = model.to_str().unwrap();
    let estimate = |input: &str, out: &Path, extra: &[&str]| {
        evtac()
            .args([
                "online",
                "--model",
                m,
                "--input",
                input,
                "--interval-ms",
                "0.1",
            ])
            .args(["--output", out.to_str().unwrap()])
            .args(extra)
            .env_remove("ROS_DOMAIN_ID")
            .output()
            .unwrap()
    };
    let live = dir.path().join("live.csv");
    let run = estimate(
        "ros2:///event_camera/events",
        &live,
        &[
            "--ros-domain",
            &domain.to_string(),
            "--ros-interface",
            "127.0.0.1",
            "--connect-timeout-s",
            "60",
            "--stall-timeout-s",
            "1",
            "--reconnect-attempts",
            "0",
        ],
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    let said: Vec<String> = BufReader::new(publisher.stdout.take().unwrap())
        .lines()
        .map(Result::unwrap)
        .collect();
    let _ = publisher.kill();
    assert!(run.status.success(), "evtac online failed: {stderr}");
    assert!(publisher.wait().is_ok());
    let published = said
        .iter()
        .find_map(|l| l.strip_prefix("published "))
        .unwrap_or_else(|| panic!("the publisher said {said:?}"));
    assert!(
        stderr.contains(&format!(
            "ROS 2 input /event_camera/events (DDS rt/event_camera/events, \
             event_camera_msgs/msg/EventPacket, reliable, domain {domain}): {published} samples, \
             219596 events, 0 lost (sequence gaps), 0 malformed (skipped)"
        )),
        "{stderr}"
    );
    assert!(
        stderr.contains("lost ros2:///event_camera/events: no sample for 1.0 s"),
        "{stderr}"
    );
    let live = rows(&std::fs::read_to_string(&live).unwrap());
    assert!(live.len() >= 80, "{} estimates: {stderr}", live.len());
    for file in [&bag, &raw] {
        let out = dir.path().join("file.csv");
        let run = estimate(file.to_str().unwrap(), &out, &[]);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let from_file = rows(&std::fs::read_to_string(&out).unwrap());
        assert_eq!(live.len(), from_file.len(), "{}", file.display());
        for (a, b) in live.iter().zip(&from_file) {
            assert_eq!(a[..3], b[..3], "{}", file.display());
        }
    }
}

/// In `dir`: a model, 50 ms of events as CSV, and the names of the estimates' CSV and the MCAP
/// log; returned as `[model, events, est.csv, run.mcap]`.
fn mcap_run_files(dir: &Path) -> [String; 4] {
    let model = dir.join("model");
    bundle(&model);
    let events = dir.join("events.csv");
    std::fs::write(&events, csv_events()).unwrap();
    [model, events, dir.join("est.csv"), dir.join("run.mcap")]
        .map(|p| p.to_str().unwrap().to_owned())
}

/// Runs `base` with `--output csv --mcap log` and `extra`; returns its standard error and the
/// CSV's rows.
fn logged_run(base: &[&str], csv: &str, log: &str, extra: &[&str]) -> (String, Vec<Vec<String>>) {
    let run = run_ok(&[base, &["--output", csv, "--mcap", log], extra].concat());
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    (stderr, rows(&std::fs::read_to_string(csv).unwrap()))
}

/// `--mcap`: the log holds what the CSV holds, read back by the `mcap` Python package (schema,
/// encoding, log time) and by `rosbags` (`AnyReader` on the file, `deserialize_cdr`).
#[test]
fn mcap_logs_what_the_csv_holds() {
    let dir = tempfile::tempdir().unwrap();
    let [m, e, o, l] = mcap_run_files(dir.path());
    let [m, e, o, l] = [&m, &e, &o, &l].map(String::as_str);
    let base = ["online", "--model", m, "--input", e, "--sensor", "640x480"];
    let (stderr, rows) = logged_run(&base, o, l, &["--frame-id", "left"]);
    assert!(rows.len() >= 40, "{} rows", rows.len());
    assert!(
        stderr.contains(&format!("logged {} estimate(s) to {l}", rows.len())),
        "{stderr}"
    );
    // The log is never written over the input.
    let msg = run_err(&[&base[..], &["--mcap", e]].concat());
    assert!(msg.contains("refusing to write over it"), "{msg}");
    assert!(std::fs::read_to_string(e).unwrap() == csv_events());
    let msg = run_err(&[&base[..], &["--output", l, "--mcap", l]].concat());
    assert!(msg.contains("--mcap and --output are both"), "{msg}");

    if evtac_testkit::python_with("mcap").is_none()
        || evtac_testkit::python_with("rosbags").is_none()
    {
        return;
    }
    let script = r#"
import sys
from pathlib import Path
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
with open(sys.argv[1], 'rb') as f:
    times = [(s.name, s.encoding, c.topic, c.message_encoding, m.log_time)
             for s, c, m in make_reader(f).iter_messages()]
with AnyReader([Path(sys.argv[1])]) as reader:
    msgs = [(c.msgtype, reader.typestore.deserialize_cdr(raw, c.msgtype))
            for c, _, raw in reader.messages()]
assert len(times) == len(msgs), (len(times), len(msgs))
for (name, enc, topic, menc, t), (typ, msg) in zip(times, msgs):
    print(name, enc, topic, menc, t, typ, msg.header.stamp.sec, msg.header.stamp.nanosec,
          msg.header.frame_id, repr(msg.vector.x), repr(msg.vector.y), repr(msg.vector.z))
"#;
    let got = evtac_testkit::run_python(script, &[l]).unwrap();
    let lines: Vec<Vec<&str>> = got.lines().map(|l| l.split(' ').collect()).collect();
    assert_eq!(lines.len(), rows.len(), "messages vs CSV rows");
    for (row, f) in rows.iter().zip(&lines) {
        let t_us: i64 = row[0].parse().unwrap();
        let ns = (t_us * 1000).to_string();
        let ty = "geometry_msgs/msg/Vector3Stamped";
        assert_eq!(f[..6], [ty, "ros2msg", "/contact_angle", "cdr", &ns, ty]);
        let (sec, nanosec): (i64, i64) = (f[6].parse().unwrap(), f[7].parse().unwrap());
        assert_eq!(sec * 1_000_000 + nanosec / 1000, t_us, "{f:?}");
        assert_eq!(f[8], "left");
        for (deg, rad) in [(&row[1], f[9]), (&row[2], f[10])] {
            let expected = f64::from(deg.parse::<f32>().unwrap()).to_radians();
            assert_eq!(
                rad.parse::<f64>().unwrap().to_bits(),
                expected.to_bits(),
                "t = {t_us}: {deg} degrees logged as {rad}"
            );
        }
        assert_eq!(f[11], "0.0");
    }
}

/// `--mcap-frames`: the representation's frames as images beside the estimates (the frames
/// themselves are checked against offline ones in `evtac-online`'s tests), refused without
/// `--mcap` or with a rate that is no rate.
#[test]
fn mcap_frames_log_the_representation_as_images() {
    let dir = tempfile::tempdir().unwrap();
    let [m, e, o, l] = mcap_run_files(dir.path());
    let [m, e, o, l] = [&m, &e, &o, &l].map(String::as_str);
    let base = ["online", "--model", m, "--input", e, "--sensor", "640x480"];
    let (stderr, rows) = logged_run(&base, o, l, &["--mcap-frames", "100"]);
    // One frame set per 10 ms of estimates (one per millisecond), the first at the first.
    let sets = rows.len().div_ceil(10);
    assert!(
        stderr.contains(&format!(
            "logged {} estimate(s) and {sets} frame set(s) to {l}",
            rows.len()
        )),
        "{stderr}"
    );
    let msg = run_err(&[&base[..], &["--mcap-frames", "10"]].concat());
    assert!(msg.contains("--mcap"), "{msg}");
    for bad in ["0", "inf", "nan"] {
        let msg = run_err(&[&base[..], &["--mcap", l, "--mcap-frames", bad]].concat());
        assert!(msg.contains("--mcap-frames"), "{bad}: {msg}");
    }

    if evtac_testkit::python_with("rosbags").is_none() {
        return;
    }
    let script = r#"
import sys
from collections import Counter
from pathlib import Path
from rosbags.highlevel import AnyReader
with AnyReader([Path(sys.argv[1])]) as reader:
    topics = Counter((c.topic, c.msgtype) for c, _, _ in reader.messages())
for (topic, msgtype), n in sorted(topics.items()):
    print(topic, msgtype, n)
"#;
    let got = evtac_testkit::run_python(script, &[l]).unwrap();
    let image = "sensor_msgs/msg/Image";
    let want = format!(
        "/contact_angle geometry_msgs/msg/Vector3Stamped {}\n\
         /contact_angle/frames/combined {image} {sets}\n\
         /contact_angle/frames/dynamic {image} {sets}\n\
         /contact_angle/frames/static {image} {sets}\n",
        rows.len()
    );
    assert_eq!(got, want);
}

/// `--mcap` on a replayed dataset trial: the trial's labels and truth at each estimate's time on
/// `/contact_angle/label` and `/contact_angle/truth`, read back by the `mcap` Python package,
/// equal (in radians) to the dataset's label and truth files at those times.
#[test]
fn mcap_logs_a_dataset_trial_s_labels_and_truth_beside_the_estimates() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("sim");
    crate::common::simulate_tiny("exp1", 7, &ds, 1);
    run_ok(&["labels", ds.to_str().unwrap()]);
    let model = dir.path().join("model");
    bundle(&model);
    let (out, log) = (dir.path().join("est.csv"), dir.path().join("run.mcap"));
    let trial = ds.join("t0000.aedat4");
    let [m, i, o, l] = [&model, &trial, &out, &log].map(|p| p.to_str().unwrap());
    let run = run_ok(&[
        "online", "--model", m, "--input", i, "--output", o, "--mcap", l,
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    for name in ["label", "truth"] {
        assert!(
            stderr.contains(&format!(
                "logging the trial's {name} on /contact_angle/{name}"
            )),
            "{stderr}"
        );
    }
    let rows = rows(&std::fs::read_to_string(&out).unwrap());
    assert!(rows.len() > 100, "{} rows", rows.len());
    if evtac_testkit::python_with("mcap").is_none() {
        return;
    }
    let script = r#"
import sys, struct
from mcap.reader import make_reader
with open(sys.argv[1], 'rb') as f:
    for s, c, m in make_reader(f).iter_messages():
        # CDR: 4-byte encapsulation, stamp (8), frame_id (4 + len, padded to 8), then x, y, z.
        d = m.data[4:]
        n = struct.unpack_from('<I', d, 8)[0]
        at = (12 + n + 7) // 8 * 8
        x, y, z = struct.unpack_from('<3d', d, at)
        print(c.topic, m.log_time // 1000, repr(x), repr(y))
"#;
    let got = evtac_testkit::run_python(script, &[l]).unwrap();
    let labels = evtac_labels::LabelSeries::read_csv(ds.join("labels/t0000.csv")).unwrap();
    let truth = evtac_labels::LabelSeries::read_csv(ds.join("truth/t0000.csv")).unwrap();
    let mut counts = std::collections::HashMap::new();
    for line in got.lines() {
        let f: Vec<&str> = line.split(' ').collect();
        *counts.entry(f[0].to_string()).or_insert(0usize) += 1;
        let t: i64 = f[1].parse().unwrap();
        let series = match f[0] {
            "/contact_angle/label" => &labels,
            "/contact_angle/truth" => &truth,
            _ => continue,
        };
        let (pitch, roll) = series.at(t);
        let (x, y): (f64, f64) = (f[2].parse().unwrap(), f[3].parse().unwrap());
        assert_eq!(x.to_bits(), pitch.to_radians().to_bits(), "{line}");
        assert_eq!(y.to_bits(), roll.to_radians().to_bits(), "{line}");
    }
    for topic in [
        "/contact_angle",
        "/contact_angle/label",
        "/contact_angle/truth",
    ] {
        assert_eq!(counts.get(topic), Some(&rows.len()), "{topic}: {counts:?}");
    }
}

#[test]
fn filters_run_as_the_model_records_them_and_others_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (plain, filtered) = (dir.path().join("plain"), dir.path().join("filtered"));
    bundle(&plain);
    let representation = Representation {
        filters: vec!["polarity=on".into(), "region=200,100,240,240".into()],
        ..Representation::new(ReprConfig::default())
    };
    ModelBundle::untrained(4, representation, None)
        .save(&filtered)
        .unwrap();
    let events = dir.path().join("events.csv");
    std::fs::write(&events, csv_events()).unwrap();
    let online = |model: &Path, input: &Path, filters: &[&str]| {
        let mut args = vec![
            "online".to_string(),
            "--model".into(),
            s(model),
            "--input".into(),
            s(input),
            "--sensor".into(),
            "640x480".into(),
        ];
        for f in filters {
            args.extend(["--filter".to_string(), f.to_string()]);
        }
        args
    };
    let err = run_err(&as_strs(&online(&filtered, &events, &["polarity=on"])));
    assert!(
        err.contains(
            "was trained on events through polarity=on region=200,100,240,240, and this \
             run's go through polarity=on: give its filters (--filter polarity=on --filter \
             region=200,100,240,240)"
        ),
        "{err}"
    );
    let err = run_err(&as_strs(&online(&plain, &events, &["polarity=on"])));
    assert!(
        err.contains("through no filter, and this run's go through polarity=on: give no --filter"),
        "{err}"
    );

    // The estimator's filters remove what `evtac filter` removes from the file: the estimates
    // equal those of the unfiltered model's bundle on the filtered file (the same weights).
    let run = run_ok(&as_strs(&online(
        &filtered,
        &events,
        &["polarity=on", "region=200,100,240,240"],
    )));
    let said = String::from_utf8_lossy(&run.stderr);
    let cleaned = dir.path().join("cleaned.csv");
    run_ok(&[
        "filter",
        &s(&events),
        &s(&cleaned),
        "--sensor",
        "640x480",
        "--filter",
        "polarity=on",
        "--filter",
        "region=200,100,240,240",
    ]);
    let kept = std::fs::read_to_string(&cleaned).unwrap().lines().count() - 1;
    assert!(kept > 0 && kept < 20_000);
    assert!(
        said.contains(&format!("filters: removed {} events", 20_000 - kept)),
        "{said}"
    );
    let reference = run_ok(&as_strs(&online(&plain, &cleaned, &[])));
    let values = |out: &[u8]| -> Vec<[String; 3]> {
        rows(&String::from_utf8_lossy(out))
            .into_iter()
            .map(|r| [r[0].clone(), r[1].clone(), r[2].clone()])
            .collect()
    };
    // The filtered file's events start later (the first kept event), so its grid may start
    // later too: the shared estimate times agree.
    let (a, b) = (values(&run.stdout), values(&reference.stdout));
    let common: Vec<_> = a
        .iter()
        .filter(|r| b.iter().any(|q| q[0] == r[0]))
        .collect();
    assert!(common.len() >= 45, "{} of {}", common.len(), a.len());
    for r in common {
        assert!(b.contains(r), "{r:?}");
    }
}

fn as_strs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}
