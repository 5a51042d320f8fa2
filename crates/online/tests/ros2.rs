//! Publishing on ROS 2 (`evtac_online::ros2`), checked against Cyclone DDS (through its Python
//! binding, `tests/support/ros2_subscriber.py`): a subscriber defined the way ROS 2 generates
//! `geometry_msgs/msg/Vector3Stamped` receives every estimate of a replay, with the values and
//! stamps evtac computed. Everything stays on loopback: Cyclone through `CYCLONEDDS_URI` (the `lo`
//! interface, unicast discovery to 127.0.0.1, no multicast, which `lo` lacks unless enabled),
//! RustDDS through `Ros2Options::interfaces` and its same-host discovery peers. Each run takes a
//! domain id of its own so that concurrent runs do not see each other.

use crate::support::dds::{CYCLONE_LOOPBACK, loopback_options, random_domain};
use crate::support::{self, SENSOR, Synthetic};
use evtac_learn::Model;
use evtac_online::input::{MemorySource, Paced};
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::ros2::{self, Ros2Options, Ros2Publisher, Time};
use evtac_online::{Estimate, Estimator};
use std::io::{BufRead, BufReader};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::process::{Child, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// A running Cyclone subscriber.
struct Subscriber {
    child: Child,
    stdout: BufReader<ChildStdout>,
}

/// One sample as the subscriber received it.
#[derive(Debug)]
struct Received {
    recv_ns: i128,
    stamp: Time,
    frame_id: String,
    vector: [f64; 3],
}

impl Subscriber {
    /// Starts the subscriber in `domain` and waits until its reader exists; `None` (skipped)
    /// without Python and cyclonedds outside CI.
    fn start(domain: u16, idle_s: f64) -> Option<Self> {
        let python: PathBuf = evtac_testkit::python_with("cyclonedds")?;
        let script = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests")
            .join("support")
            .join("ros2_subscriber.py");
        let mut child = Command::new(python)
            .arg(script)
            .args([
                &domain.to_string(),
                "rt/contact_angle",
                &idle_s.to_string(),
                "120",
            ])
            .env("CYCLONEDDS_URI", CYCLONE_LOOPBACK)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("the subscriber starts");
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let mut line = String::new();
        stdout.read_line(&mut line).unwrap();
        assert_eq!(line.trim(), "ready", "the subscriber did not start");
        Some(Self { child, stdout })
    }

    /// Waits for the subscriber to stop (idle after the last sample) and returns what it got.
    fn received(mut self) -> Vec<Received> {
        let mut samples = Vec::new();
        let mut ended = false;
        for line in (&mut self.stdout).lines() {
            let line = line.unwrap();
            if line == "end" {
                ended = true;
                break;
            }
            let f: Vec<&str> = line.split(' ').collect();
            assert_eq!(f.len(), 7, "{line}");
            samples.push(Received {
                recv_ns: f[0].parse().unwrap(),
                stamp: Time {
                    sec: f[1].parse().unwrap(),
                    nanosec: f[2].parse().unwrap(),
                },
                frame_id: f[3].to_owned(),
                vector: [f[4], f[5], f[6]].map(|v| v.parse().unwrap()),
            });
        }
        assert!(ended, "the subscriber ended without its `end` line");
        assert!(self.child.wait().unwrap().success());
        samples
    }
}

impl Drop for Subscriber {
    fn drop(&mut self) {
        // A failed assertion must not leave the subscriber running.
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn model(dir: &std::path::Path) -> Model {
    let (_, repr) = support::representations()[2];
    support::seeded_bundle(dir, 3, &repr, None);
    Model::load(dir).unwrap()
}

/// Wall-clock nanoseconds since the Unix epoch (the clock Python's `time.time_ns` reads).
fn wall_ns() -> i128 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap()
        .as_nanos() as i128
}

fn quantile(sorted: &[i128], q: f64) -> i128 {
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

#[test]
fn a_cyclone_dds_subscriber_receives_every_estimate_with_its_values_and_stamp() {
    let domain = random_domain(1);
    let Some(subscriber) = Subscriber::start(domain, 3.0) else {
        return;
    };
    let publisher = Ros2Publisher::new(loopback_options(domain, "neurotac_left")).unwrap();
    assert_eq!(publisher.dds_topic(), "rt/contact_angle");
    assert!(
        publisher.wait_for_subscribers(1, Duration::from_secs(30)),
        "the Cyclone subscriber was not discovered in domain {domain} within 30 s"
    );

    // 1.5 s of a pressed sensor, released at recorded pace in 1 ms slices: one estimate every
    // millisecond, as a live sensor gives them.
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let events = Synthetic::new(9, 300_000.0, 1000, 1_500_000).collect();
    let source = Paced::new(MemorySource::new(events, 4096), 1000);
    let estimator = Estimator::for_model(&model, SENSOR, 1000).unwrap();
    let mut estimates: Vec<(Estimate, i128)> = Vec::new();
    let mut summary = pipeline::run(source, estimator, &PipelineConfig::default(), |out| {
        if let Output::Estimate(e) = out {
            // Wall time when the estimate is handed over: the start of the latency below.
            estimates.push((e, wall_ns()));
            publisher.publish(&e);
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    let stats = publisher.finish();
    assert!(estimates.len() >= 1400, "{} estimates", estimates.len());
    assert_eq!(stats.published, estimates.len() as u64, "{stats}");
    assert_eq!(stats.dropped(), 0, "{stats}");
    assert_eq!(stats.subscribers, 1, "{stats}");
    assert!(stats.acknowledged, "{stats}");
    summary.ros2 = Some(stats);
    let text = summary.to_string();
    assert!(
        text.contains(&format!(
            "ROS 2 /contact_angle (DDS rt/contact_angle, domain {domain}): {} published, 0 dropped",
            estimates.len()
        )),
        "{text}"
    );
    assert!(text.contains("ROS 2 publish latency"), "{text}");

    let received = subscriber.received();
    assert_eq!(
        received.len(),
        estimates.len(),
        "the subscriber received {} of {} estimates",
        received.len(),
        estimates.len()
    );
    let distinct: std::collections::BTreeSet<u64> =
        received.iter().map(|r| r.vector[0].to_bits()).collect();
    assert!(
        distinct.len() > 10,
        "pitch barely varies: the check is weak"
    );
    let mut latencies = Vec::new();
    for ((e, handed_ns), r) in estimates.iter().zip(&received) {
        // The stamp is t_us exactly.
        assert_eq!(r.stamp, Time::from_micros(e.t_us));
        assert_eq!(
            i64::from(r.stamp.sec) * 1_000_000 + i64::from(r.stamp.nanosec / 1000),
            e.t_us
        );
        assert_eq!(r.stamp.nanosec % 1000, 0);
        assert_eq!(r.frame_id, "neurotac_left");
        // Radians of the f32 degrees widened exactly to f64, bit for bit.
        let expected =
            [e.pitch_deg, e.roll_deg].map(|d| f64::from(d) * (std::f64::consts::PI / 180.0));
        assert_eq!(
            [r.vector[0].to_bits(), r.vector[1].to_bits()],
            [expected[0].to_bits(), expected[1].to_bits()],
            "t = {} us: received {:?}, expected {expected:?} from {} / {} degrees",
            e.t_us,
            r.vector,
            e.pitch_deg,
            e.roll_deg
        );
        assert_eq!(ros2::radians(e.pitch_deg), expected[0]);
        assert_eq!(r.vector[2], 0.0);
        latencies.push(r.recv_ns - handed_ns);
    }
    latencies.sort_unstable();
    // Reported, not asserted (a shared machine's scheduling decides the tail): the figure for
    // docs/online.md.
    let us = |ns: i128| ns as f64 / 1000.0;
    let report = format!(
        "ROS 2 on loopback, estimate handed over -> taken by the Cyclone subscriber, {} \
         estimates at 1 ms: median {:.0} us, P99 {:.0} us, max {:.0} us\n",
        latencies.len(),
        us(quantile(&latencies, 0.5)),
        us(quantile(&latencies, 0.99)),
        us(*latencies.last().unwrap())
    );
    let _ = std::io::Write::write_all(&mut std::io::stderr(), report.as_bytes());
}

#[test]
fn publishing_never_waits_without_subscribers_or_with_a_flood() {
    // No subscriber anywhere in this domain: estimates go on, nothing is owed to anyone.
    let domain = random_domain(2);
    let publisher = Ros2Publisher::new(loopback_options(domain, "neurotac")).unwrap();
    assert_eq!(publisher.subscribers(), 0);
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let events = Synthetic::new(4, 300_000.0, 1000, 300_000).collect();
    let expected = support::replayed(&model, &events, 4096);
    let mut got = Vec::new();
    let summary = pipeline::run(
        MemorySource::new(events, 4096),
        Estimator::for_model(&model, SENSOR, 1000).unwrap(),
        &PipelineConfig::default(),
        |out| {
            if let Output::Estimate(e) = out {
                publisher.publish(&e);
                got.push(e);
            }
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    support::assert_same_estimates(&got, &expected);
    assert_eq!(summary.estimates, got.len() as u64);

    // A flood far beyond the queue: every call returns at once, and every estimate is either
    // published or counted as dropped.
    let e = got[0];
    let started = Instant::now();
    let flood = 200_000u64;
    for _ in 0..flood {
        publisher.publish(&e);
    }
    let took = started.elapsed();
    assert!(took < Duration::from_secs(2), "{flood} calls took {took:?}");
    let stats = publisher.finish();
    assert_eq!(
        stats.published + stats.dropped(),
        got.len() as u64 + flood,
        "{stats}"
    );
    assert_eq!(stats.subscribers, 0);
}

#[test]
fn bad_topics_and_domains_are_refused_before_joining_a_domain() {
    let mut options = Ros2Options::new("/contact angle");
    let e = Ros2Publisher::new(options.clone()).unwrap_err().to_string();
    assert!(
        e.contains("invalid ROS 2 topic name \"/contact angle\""),
        "{e}"
    );
    options.topic = "/contact_angle".into();
    options.domain = 250;
    let e = Ros2Publisher::new(options).unwrap_err().to_string();
    assert!(e.contains("domain id 250"), "{e}");
}

#[test]
fn a_subscriber_that_comes_and_goes_holds_nothing_up() {
    let domain = random_domain(3);
    // Checks that the environment has the subscriber's tools before anything else.
    if evtac_testkit::python_with("cyclonedds").is_none() {
        return;
    }
    let publisher = Ros2Publisher::new(loopback_options(domain, "neurotac")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let events = Synthetic::new(5, 300_000.0, 1000, 2_000_000).collect();
    let expected = support::replayed(&model, &events, 4096);
    let source = Paced::new(MemorySource::new(events, 4096), 1000);
    let estimator = Estimator::for_model(&model, SENSOR, 1000).unwrap();
    // A subscriber joins while estimates flow, and is killed (no goodbye: its writer side
    // only learns of it when its lease runs out) while they still flow.
    let visitor = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(200));
        let mut subscriber = Subscriber::start(domain, 10.0).unwrap();
        std::thread::sleep(Duration::from_millis(900));
        subscriber.child.kill().unwrap();
    });
    let mut got = Vec::new();
    let mut matched_at_some_point = false;
    let started = Instant::now();
    pipeline::run(source, estimator, &PipelineConfig::default(), |out| {
        if let Output::Estimate(e) = out {
            publisher.publish(&e);
            matched_at_some_point |= publisher.subscribers() > 0;
            got.push(e);
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    let took = started.elapsed();
    visitor.join().unwrap();
    let stats = publisher.finish();
    // The paced source vouches for the time up to its last slice's end, which may make one
    // estimate past the last event that the replay from memory does not make.
    assert!(
        (expected.len()..=expected.len() + 1).contains(&got.len()),
        "{} estimates, {} from memory",
        got.len(),
        expected.len()
    );
    support::assert_same_estimates(&got[..expected.len()], &expected);
    assert!(
        matched_at_some_point,
        "the visiting subscriber never matched"
    );
    assert_eq!(
        stats.published + stats.dropped(),
        got.len() as u64,
        "{stats}"
    );
    // A 2 s replay at recorded pace, not held up by the subscriber (generous for a busy
    // machine; a stall on a dead reader would be the 5 ms write bound per estimate at least).
    assert!(took < Duration::from_secs(4), "the replay took {took:?}");
}
