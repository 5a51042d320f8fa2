//! A live stream served on loopback by dv-processing's `dv.io.NetworkWriter` (the reference
//! implementation of DV's network protocol): estimates arrive while events are still being
//! sent, and they equal the estimates of the same events replayed from memory.

use crate::support::{self, SENSOR, Synthetic};
use evtac_learn::Model;
use evtac_online::input::{self, NetworkOptions, OpenOptions, SourceSpec};
use evtac_online::{Backoff, Estimate, Estimator, Notice};
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// Serves the events in `argv[2]` (packed `<i8 t, <i2 x, <i2 y, u1 p`) on 127.0.0.1:`argv[1]`
/// at recorded pace in packets of `argv[3]` us, once a client is connected; prints the wall
/// time of the first and last packet written.
const SERVER: &str = r#"
import sys, time
import numpy as np
import dv_processing as dv

port, path, packet_us = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
ev = np.fromfile(path, dtype=np.dtype([("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")]))
stream = dv.io.Stream.EventStream(0, "events", "DVXplorer_evtac", (640, 480))
writer = dv.io.NetworkWriter("127.0.0.1", port, stream)
print("listening", flush=True)
deadline = time.time() + 20
while writer.getClientCount() == 0 and time.time() < deadline:
    time.sleep(0.005)
if writer.getClientCount() == 0:
    sys.exit("no client connected")
t0 = int(ev["t"][0])
start = time.time()
first = None
i = 0
edge = t0 + packet_us
while i < len(ev):
    j = int(np.searchsorted(ev["t"], edge, side="left"))
    store = dv.EventStore()
    for k in range(i, j):
        store.push_back(int(ev["t"][k]), int(ev["x"][k]), int(ev["y"][k]), bool(ev["p"][k]))
    due = start + (edge - t0) * 1e-6
    now = time.time()
    if due > now:
        time.sleep(due - now)
    if j > i:
        writer.writeEvents(store)
        if first is None:
            first = time.time()
    i = j
    edge += packet_us
last = time.time()
while writer.getQueuedPacketCount() > 0 and time.time() < last + 5:
    time.sleep(0.005)
time.sleep(0.2)
print(f"first_write {first:.6f}", flush=True)
print(f"last_write {last:.6f}", flush=True)
"#;

fn unix_now() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

#[test]
fn estimates_arrive_while_a_dv_network_writer_streams() {
    let Some(python) = evtac_testkit::python() else {
        return;
    };
    // 0.6 s of a busy contact at 300k events/s, in 2 ms packets.
    let events = Synthetic::new(21, 300_000.0, 1000, 600_000).collect();
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("events.bin");
    let mut bytes = Vec::with_capacity(events.len() * 13);
    for e in &events {
        bytes.extend_from_slice(&e.t.to_le_bytes());
        bytes.extend_from_slice(&(e.x as i16).to_le_bytes());
        bytes.extend_from_slice(&(e.y as i16).to_le_bytes());
        bytes.push(u8::from(e.polarity));
    }
    std::fs::File::create(&raw)
        .unwrap()
        .write_all(&bytes)
        .unwrap();
    let (_, repr) = support::representations()[0];
    support::seeded_bundle(dir.path(), 9, &repr, None);
    let model = Model::load(dir.path()).unwrap();

    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let mut server = Command::new(python)
        .arg("-c")
        .arg(SERVER)
        .arg(port.to_string())
        .arg(&raw)
        .arg("2000")
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("python starts");
    let mut lines = BufReader::new(server.stdout.take().unwrap()).lines();
    assert_eq!(lines.next().unwrap().unwrap(), "listening");

    let spec: SourceSpec = format!("tcp://127.0.0.1:{port}").parse().unwrap();
    let options = OpenOptions {
        network: NetworkOptions {
            backoff: Backoff {
                initial: Duration::from_millis(50),
                max: Duration::from_millis(50),
                attempts: 1,
            },
            connect_timeout: Duration::from_secs(2),
            stall_timeout: Duration::from_secs(5),
        },
        ..OpenOptions::default()
    };
    let mut notices: Vec<Notice> = Vec::new();
    let opened = input::open(&spec, &options, &mut |n| notices.push(n)).unwrap();
    assert_eq!(opened.resolution, Some(SENSOR));
    let estimator = Estimator::for_model(&model, SENSOR, 1000).unwrap();
    let mut estimates: Vec<(Estimate, f64)> = Vec::new();
    let summary = support::run_to_end(opened.source, estimator, &mut notices, |e| {
        estimates.push((e, unix_now()))
    });
    let status = server.wait().unwrap();
    assert!(status.success(), "the Python server failed: {status}");
    let mut times = std::collections::HashMap::new();
    for line in lines {
        let line = line.unwrap();
        if let Some((key, value)) = line.split_once(' ') {
            times.insert(key.to_string(), value.parse::<f64>().unwrap());
        }
    }
    let last_write = times["last_write"];

    assert_eq!(summary.events, events.len() as u64, "{notices:?}");
    // Live: most estimates were out before the server wrote its last packet (the stream lasts
    // 0.6 s; estimates trail their packet by microseconds, not by the rest of the stream).
    let before = estimates.iter().filter(|(_, at)| *at < last_write).count();
    assert!(
        before * 10 >= estimates.len() * 8,
        "only {before} of {} estimates arrived before the last packet was written",
        estimates.len()
    );
    // The same values as a replay of the same events.
    let live: Vec<Estimate> = estimates.iter().map(|(e, _)| *e).collect();
    support::assert_same_estimates(&live, &support::replayed(&model, &events, 4096));
}
