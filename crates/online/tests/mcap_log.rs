//! MCAP logs (`evtac_online::mcap_log`), read back by two independent readers: the `mcap`
//! Python package (schema, encodings, log times, and the CDR decoded by hand here) and `rosbags`
//! (`AnyReader` on the single `.mcap` file, types built from the schema the file embeds,
//! `deserialize_cdr`). Every message must be the replayed estimate: pitch and roll in radians
//! bit for bit, the stamp and log time its `t_us`.

use crate::support::{self, SENSOR, Synthetic};
use evtac_learn::Model;
use evtac_online::input::MemorySource;
use evtac_online::mcap_log::{self, McapLog};
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::ros2::{self, MSG_DEFINITION, Time};
use evtac_online::{Estimate, Estimator};
use std::ops::ControlFlow;
use std::path::Path;
use std::time::Duration;

/// Prints every message of the MCAP file `argv[1]` as each reader sees it, one line each.
const READ_BACK: &str = r#"
import struct, sys
from pathlib import Path
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

path = Path(sys.argv[1])
with open(path, 'rb') as f:
    reader = make_reader(f)
    print('profile', reader.get_header().profile)
    schemas = set()
    for schema, channel, message in reader.iter_messages(log_time_order=False):
        if schema.id not in schemas:
            schemas.add(schema.id)
            print('schema', schema.name, schema.encoding, schema.data.hex())
        data = message.data
        assert data[:4] == b'\x00\x01\x00\x00', data[:4]
        body = data[4:]
        sec, nanosec, n = struct.unpack_from('<iII', body, 0)
        assert body[12 + n - 1] == 0
        frame = body[12:12 + n - 1].decode()
        off = 12 + n
        off += (-off) % 8
        x, y, z = struct.unpack_from('<3d', body, off)
        assert off + 24 == len(body), (off, len(body))
        print('mcap', channel.topic, channel.message_encoding, message.log_time,
              message.publish_time, message.sequence, sec, nanosec, frame,
              repr(x), repr(y), repr(z))
with AnyReader([path]) as reader:
    for connection, timestamp, rawdata in reader.messages():
        msg = reader.typestore.deserialize_cdr(rawdata, connection.msgtype)
        print('rosbags', connection.topic, connection.msgtype, timestamp,
              msg.header.stamp.sec, msg.header.stamp.nanosec, msg.header.frame_id,
              repr(msg.vector.x), repr(msg.vector.y), repr(msg.vector.z))
"#;

fn model(dir: &Path) -> Model {
    let (_, repr) = support::representations()[2];
    support::seeded_bundle(dir, 3, &repr, None);
    Model::load(dir).unwrap()
}

fn estimate(t_us: i64) -> Estimate {
    Estimate {
        t_us,
        pitch_deg: 1.5,
        roll_deg: -2.25,
        latency: Duration::ZERO,
        processing: Duration::ZERO,
    }
}

/// The two readers' lines for `path`; `None` (skipped) without Python, `mcap` and `rosbags`
/// outside CI.
fn read_back(path: &Path) -> Option<String> {
    evtac_testkit::python_with("mcap")?;
    evtac_testkit::python_with("rosbags")?;
    evtac_testkit::run_python(READ_BACK, &[path.to_str().unwrap()])
}

/// Checks the stamp, frame and vector one reader decoded against the estimate `e`.
fn check_values(reader: &str, e: &Estimate, stamp: (&str, &str), frame: &str, xyz: &[&str]) {
    let time = Time::from_micros(e.t_us);
    assert_eq!(
        (
            stamp.0.parse::<i32>().unwrap(),
            stamp.1.parse::<u32>().unwrap()
        ),
        (time.sec, time.nanosec),
        "{reader}: stamp of t = {} us",
        e.t_us
    );
    assert_eq!(
        i64::from(time.sec) * 1_000_000 + i64::from(time.nanosec / 1000),
        e.t_us
    );
    assert_eq!(frame, "neurotac_left", "{reader}");
    let got: Vec<u64> = xyz
        .iter()
        .map(|v| v.parse::<f64>().unwrap().to_bits())
        .collect();
    // Radians of the f32 degrees widened exactly to f64, bit for bit.
    let expected = [
        f64::from(e.pitch_deg) * (std::f64::consts::PI / 180.0),
        f64::from(e.roll_deg) * (std::f64::consts::PI / 180.0),
        0.0,
    ];
    assert_eq!(
        got,
        expected.map(f64::to_bits),
        "{reader}: t = {} us, {:?} for {} / {} degrees",
        e.t_us,
        xyz,
        e.pitch_deg,
        e.roll_deg
    );
}

#[test]
fn mcap_and_rosbags_read_every_replayed_estimate_with_its_values_and_times() {
    let dir = tempfile::tempdir().unwrap();
    let model = model(&dir.path().join("model"));
    let events = Synthetic::new(9, 300_000.0, 1000, 1_500_000).collect();
    let expected = support::replayed(&model, &events, 4096);
    let path = dir.path().join("run.mcap");
    let mut log = McapLog::create(
        &path,
        &[dir.path().join("input.aedat4")],
        "/robot/contact_angle",
        "neurotac_left",
    )
    .unwrap();
    let mut got = Vec::new();
    pipeline::run(
        MemorySource::new(events, 4096),
        Estimator::for_model(&model, SENSOR, 1000).unwrap(),
        &PipelineConfig::default(),
        |out| {
            if let Output::Estimate(e) = out {
                log.write(&e).unwrap();
                got.push(e);
            }
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    support::assert_same_estimates(&got, &expected);
    assert!(got.len() >= 1400, "{} estimates", got.len());
    assert_eq!(log.written() as usize, got.len());
    assert!(!path.exists(), "nothing under the final name before finish");
    log.finish().unwrap();
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(
        !names.iter().any(|n| n.starts_with(".run.")),
        "the temporary file is left: {names:?}"
    );

    let Some(out) = read_back(&path) else { return };
    let distinct: std::collections::BTreeSet<u32> =
        got.iter().map(|e| e.pitch_deg.to_bits()).collect();
    assert!(
        distinct.len() > 10,
        "pitch barely varies: the check is weak"
    );
    let lines: Vec<Vec<&str>> = out.lines().map(|l| l.split(' ').collect()).collect();
    assert_eq!(lines[0], ["profile", "ros2"]);
    assert_eq!(
        lines[1][..3],
        ["schema", "geometry_msgs/msg/Vector3Stamped", "ros2msg"]
    );
    let hex: String = MSG_DEFINITION.bytes().map(|b| format!("{b:02x}")).collect();
    assert_eq!(lines[1][3], hex, "the schema text");
    let mcap: Vec<&Vec<&str>> = lines.iter().filter(|l| l[0] == "mcap").collect();
    let rosbags: Vec<&Vec<&str>> = lines.iter().filter(|l| l[0] == "rosbags").collect();
    assert_eq!(lines.len(), 2 + mcap.len() + rosbags.len(), "{out}");
    assert_eq!(mcap.len(), got.len(), "messages the mcap package read");
    assert_eq!(rosbags.len(), got.len(), "messages rosbags read");
    for (i, ((e, m), r)) in got.iter().zip(&mcap).zip(&rosbags).enumerate() {
        let ns = (e.t_us * 1000).to_string();
        assert_eq!(
            m[1..4],
            ["/robot/contact_angle", "cdr", &ns],
            "mcap: log time"
        );
        assert_eq!(m[4], ns, "mcap: publish time");
        assert_eq!(m[5], (i + 1).to_string(), "mcap: sequence");
        check_values("mcap", e, (m[6], m[7]), m[8], &m[9..12]);
        assert_eq!(
            r[1..4],
            [
                "/robot/contact_angle",
                "geometry_msgs/msg/Vector3Stamped",
                &ns
            ],
            "rosbags: topic, type, time"
        );
        check_values("rosbags", e, (r[4], r[5]), r[6], &r[7..10]);
        assert_eq!(m[9].parse::<f64>().unwrap(), ros2::radians(e.pitch_deg));
    }
}

#[test]
fn the_log_refuses_its_input_and_times_before_zero_and_leaves_nothing_on_failure() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("trial.csv");
    std::fs::write(&input, "t,x,y,p\n").unwrap();
    let e = McapLog::create(&input, &[&input], mcap_log::DEFAULT_TOPIC, "neurotac")
        .unwrap_err()
        .to_string();
    assert!(e.contains("refusing to write over it"), "{e}");
    assert_eq!(std::fs::read_to_string(&input).unwrap(), "t,x,y,p\n");

    let path = dir.path().join("run.mcap");
    let mut log = McapLog::create(&path, &[&input], mcap_log::DEFAULT_TOPIC, "neurotac").unwrap();
    log.write(&estimate(0)).unwrap();
    let e = log.write(&estimate(-1)).unwrap_err().to_string();
    assert!(e.contains("t = -1 us is before the clock's zero"), "{e}");
    // Dropped unfinished (a failed run): no file, not even the temporary one.
    drop(log);
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1, "only the input is left");
}
