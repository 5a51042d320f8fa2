//! ROS bags written by independent tools (`rosbags`' ROS 1 and rosbag2 MCAP writers, the `mcap`
//! package), read back event for event and sample for sample against the arrays the bags were
//! written from: ROS 1 bags with uncompressed, bz2 and lz4 chunks; rosbag2 MCAP folders (plain
//! and zstd chunks) and a lone `.mcap` (lz4 chunks); `dvs_msgs/EventArray`, the real EVT3 words
//! of the Prophesee fixture cut into `event_camera_msgs/EventPacket`s (against its
//! `.expected.npy`), `mono` packets and `sensor_msgs/Imu`. Then what must fail: a truncated bag,
//! a topic that is not there or holds the wrong type, several event topics and none chosen, an
//! unknown packet encoding, each named with the file and topic.

use std::path::Path;

use evtac_events::{Event, ImuSample, Resolution};
use evtac_formats::StreamSelection;
use evtac_formats::{Error, Format, Summary};
use evtac_testkit::{real_fixture, run_python};

use crate::common::{read_expected_csv, read_npy_events};

const WRITE: &str = include_str!("ros_bags.py");
const EVT3_RAW: &str = "prophesee_gen4_1280x720.evt3.raw";
const EVT3_EXPECTED: &str = "prophesee_gen4_1280x720.evt3.expected.npy";

/// The bags, written into a temporary folder (`None`: no Python outside CI, test skipped). The
/// EVT3 bag is written when the shared fixture is there.
fn written() -> Option<tempfile::TempDir> {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap().to_string();
    let raw = real_fixture(EVT3_RAW);
    let mut args = vec![out.as_str()];
    let raw_str = raw.as_ref().map(|p| p.to_str().unwrap().to_string());
    if let Some(r) = &raw_str {
        args.push(r);
    }
    run_python(WRITE, &args)?;
    Some(dir)
}

fn csv_rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

fn assert_events(what: &str, got: &[Event], want: &[Event]) {
    assert!(
        want.len() > 100,
        "{what}: only {} expected events",
        want.len()
    );
    assert_eq!(got.len(), want.len(), "{what}: event count");
    if let Some(i) = got.iter().zip(want).position(|(a, b)| a != b) {
        panic!(
            "{what}: first difference at event {i}: {:?} != {:?}",
            got[i], want[i]
        );
    }
}

/// `NAME.imu.csv`: t (us), accelerometer (g), gyroscope (deg/s), computed in numpy from the
/// m/s^2 and rad/s the bag holds: each value must match within f32 rounding.
fn assert_imu(what: &str, got: &[ImuSample], want: &Path) {
    let want = csv_rows(want);
    assert!(
        want.len() >= 5,
        "{what}: only {} expected samples",
        want.len()
    );
    assert_eq!(got.len(), want.len(), "{what}: IMU sample count");
    for (i, (s, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(s.t, w[0] as i64, "{what}: IMU sample {i} time");
        let values = s.accelerometer.iter().chain(&s.gyroscope);
        for (k, (&v, &w)) in values.zip(&w[1..]).enumerate() {
            let tolerance = w.abs() * 2e-7 + 1e-9;
            assert!(
                (f64::from(v) - w).abs() <= tolerance,
                "{what}: IMU sample {i} value {k}: {v} != {w}"
            );
        }
        assert!(
            s.temperature.is_nan(),
            "{what}: sensor_msgs/Imu has no temperature"
        );
    }
}

#[test]
fn ros1_bags_read_event_for_event_with_every_chunk_compression() {
    let Some(dir) = written() else { return };
    let d = dir.path();
    let want = read_expected_csv(&d.join("dvs1.events.csv"));
    for file in ["dvs.bag", "dvs_bz2.bag", "dvs_lz4.bag"] {
        let path = d.join(file);
        assert_eq!(Format::detect(&path).unwrap(), Format::RosBag, "{file}");
        let reader = evtac_formats::open(&path).unwrap();
        let note = reader.note().unwrap_or_default().to_string();
        assert!(
            note.contains("events from /dvs/events (dvs_msgs/EventArray, 12 messages)")
                && note.contains("IMU from /dvs/imu (sensor_msgs/Imu, 50 messages"),
            "{file}: {note}"
        );
        let topics: Vec<(String, String, u64)> = reader
            .topics()
            .iter()
            .map(|t| (t.name.clone(), t.message_type.clone(), t.messages))
            .collect();
        let listed = vec![
            ("/dvs/events".into(), "dvs_msgs/EventArray".into(), 12),
            ("/dvs/imu".into(), "sensor_msgs/Imu".into(), 50),
            ("/note".into(), "std_msgs/String".into(), 1),
        ];
        let mut sorted = topics.clone();
        sorted.sort();
        assert_eq!(sorted, listed, "{file}");
        assert_eq!(
            evtac_formats::ros::topics(&path).unwrap(),
            reader.topics(),
            "{file}"
        );
        let rec = reader.into_recording().unwrap();
        assert_eq!(rec.format, Format::RosBag);
        assert_eq!(rec.resolution, Some(Resolution::new(346, 260)), "{file}");
        assert_events(file, &rec.events, &want);
        assert_imu(file, &rec.imu, &d.join("dvs1.imu.csv"));
    }
}

#[test]
fn ros2_mcap_folders_and_files_read_event_for_event() {
    let Some(dir) = written() else { return };
    let d = dir.path();
    let want = read_expected_csv(&d.join("dvs2.events.csv"));
    for file in ["dvs2", "dvs2/dvs2.mcap", "dvs2_zstd"] {
        let path = d.join(file);
        assert_eq!(Format::detect(&path).unwrap(), Format::Mcap, "{file}");
        let rec = evtac_formats::read_recording(&path).unwrap();
        assert_eq!(rec.resolution, Some(Resolution::new(346, 260)), "{file}");
        assert_events(file, &rec.events, &want);
        assert_imu(file, &rec.imu, &d.join("dvs2.imu.csv"));
    }
    let topics = evtac_formats::ros::topics(d.join("dvs2_zstd")).unwrap();
    let names: Vec<(&str, &str, u64)> = topics
        .iter()
        .map(|t| (t.name.as_str(), t.message_type.as_str(), t.messages))
        .collect();
    assert!(
        names.contains(&("/dvs/events", "dvs_msgs/msg/EventArray", 9))
            && names.contains(&("/dvs/imu", "sensor_msgs/msg/Imu", 40)),
        "{names:?}"
    );
    let summary = Summary::of_file(d.join("dvs2")).unwrap();
    assert_eq!(summary.format, "ROS 2 MCAP");
    assert_eq!(
        (summary.events, summary.imu_samples),
        (want.len() as u64, 40)
    );
    assert_eq!(summary.topics, topics);
}

#[test]
fn evt3_packets_decode_as_the_raw_file_across_packet_boundaries() {
    let Some(dir) = written() else { return };
    let Some(expected) = real_fixture(EVT3_EXPECTED) else {
        return;
    };
    let d = dir.path();
    let packets: u64 = std::fs::read_to_string(d.join("evt3.packets"))
        .unwrap()
        .parse()
        .unwrap();
    assert!(packets >= 5, "the words must be cut into several packets");
    let want = read_npy_events(&expected);
    let reader = evtac_formats::open(d.join("evt3")).unwrap();
    let note = reader.note().unwrap().to_string();
    assert!(
        note.contains(&format!(
            "/prophesee/events (event_camera_msgs/msg/EventPacket, {packets} messages)"
        )) && note.contains("camera's own clock"),
        "{note}"
    );
    let rec = reader.into_recording().unwrap();
    assert_eq!(rec.resolution, Some(Resolution::new(1280, 720)));
    assert_eq!(want.len(), 219_596);
    assert_events("evt3 packets", &rec.events, &want);
    assert_imu("evt3 IMU", &rec.imu, &d.join("evt3.imu.csv"));
    // The same packets in a ROS 1 bag.
    let rec = evtac_formats::read_recording(d.join("evt3.bag")).unwrap();
    assert_eq!(rec.format, Format::RosBag);
    assert_eq!(rec.resolution, Some(Resolution::new(1280, 720)));
    assert_events("evt3 packets in a ROS 1 bag", &rec.events, &want);
}

#[test]
fn mono_packets_add_dt_to_the_time_base() {
    let Some(dir) = written() else { return };
    let d = dir.path();
    let rec = evtac_formats::read_recording(d.join("mono.mcap")).unwrap();
    assert_eq!(rec.resolution, Some(Resolution::new(640, 480)));
    let want = read_expected_csv(&d.join("mono.events.csv"));
    assert_events("mono", &rec.events, &want);
    assert!(rec.imu.is_empty());
}

#[test]
fn a_time_range_of_a_bag_holds_its_events_and_imu_samples() {
    let Some(dir) = written() else { return };
    let path = dir.path().join("dvs_lz4.bag");
    let whole = evtac_formats::read_recording(&path).unwrap();
    let (first, last) = (whole.events[0].t, whole.events.last().unwrap().t);
    let (from, to) = (first + (last - first) / 3, first + (last - first) * 2 / 3);
    let (part, _) = evtac_formats::read_recording_range(&path, from, to).unwrap();
    let events: Vec<Event> = whole
        .events
        .iter()
        .copied()
        .filter(|e| (from..to).contains(&e.t))
        .collect();
    let imu: Vec<ImuSample> = whole
        .imu
        .iter()
        .copied()
        .filter(|s| (from..to).contains(&s.t))
        .collect();
    assert!(!events.is_empty() && !imu.is_empty());
    assert_eq!(part.events, events);
    assert_eq!(part.imu.len(), imu.len());
    assert!(part.imu.iter().zip(&imu).all(|(a, b)| a.t == b.t));
}

fn choose(events: Option<&str>, imu: Option<&str>) -> StreamSelection {
    StreamSelection {
        events: events.map(|s| s.parse().unwrap()),
        imu: imu.map(|s| s.parse().unwrap()),
        ..Default::default()
    }
}

#[test]
fn with_two_cameras_a_topic_is_chosen_by_name() {
    let Some(dir) = written() else { return };
    let d = dir.path();
    let path = d.join("stereo.bag");
    let err = evtac_formats::open(&path).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, Error::Streams { .. }), "{err:?}");
    assert!(
        text.contains("stereo.bag")
            && text.contains("2 event topics: pick one with --stream TOPIC")
            && text.contains("/cam0/events: dvs_msgs/EventArray, 3 messages")
            && text.contains("/cam1/events: dvs_msgs/EventArray, 4 messages"),
        "{text}"
    );
    // The IMU topic follows the chosen camera's namespace.
    let rec = evtac_formats::open_with(&path, &choose(Some("/cam1/events"), None))
        .unwrap()
        .into_recording()
        .unwrap();
    assert_events(
        "stereo /cam1",
        &rec.events,
        &read_expected_csv(&d.join("stereo1.events.csv")),
    );
    assert_imu("stereo /cam1", &rec.imu, &d.join("stereo1.imu.csv"));
    // `info` lists the topics and says why it counts nothing.
    let summary = Summary::of_file(&path).unwrap();
    assert_eq!(summary.topics.len(), 4);
    assert_eq!(summary.events, 0);
    assert!(
        summary
            .selection
            .as_deref()
            .unwrap_or("")
            .contains("2 event topics"),
        "{summary:?}"
    );
}

/// The message of the error reading `path` with `selection`.
fn error(path: &Path, selection: &StreamSelection) -> (Error, String) {
    let err = evtac_formats::open_with(path, selection)
        .and_then(|r| r.into_recording())
        .expect_err("must fail");
    let text = err.to_string();
    (err, text)
}

#[test]
fn a_missing_or_wrong_topic_is_an_error_naming_it() {
    let Some(dir) = written() else { return };
    let path = dir.path().join("stereo.bag");
    let (err, text) = error(&path, &choose(Some("/cam2/events"), None));
    assert!(matches!(err, Error::Streams { .. }), "{err:?}");
    assert!(
        text.contains("stereo.bag")
            && text.contains("--stream /cam2/events: the bag has no topic of that name")
            && text.contains("/cam1/imu: sensor_msgs/Imu, 6 messages"),
        "{text}"
    );
    let (_, text) = error(&path, &choose(Some("/cam0/imu"), None));
    assert!(
        text.contains("--stream /cam0/imu: the topic holds sensor_msgs/Imu, not events"),
        "{text}"
    );
    let (_, text) = error(&path, &choose(Some("/cam0/events"), Some("/cam1/events")));
    assert!(
        text.contains("--imu-stream /cam1/events: the topic holds dvs_msgs/EventArray, not IMU"),
        "{text}"
    );
    // Other formats hold one stream of each kind: a topic is no choice there.
    let csv = dir.path().join("dvs1.events.csv");
    let (_, text) = error(&csv, &choose(Some("/dvs/events"), None));
    assert!(text.contains("only AEDAT4 files and ROS bags"), "{text}");
}

#[test]
fn a_truncated_bag_is_an_error_naming_the_file() {
    let Some(dir) = written() else { return };
    let d = dir.path();
    let (err, text) = error(&d.join("cut.bag"), &StreamSelection::default());
    assert!(matches!(err, Error::Ros { .. }), "{err:?}");
    assert!(
        text.contains("cut.bag") && text.contains("cut short") && text.contains("byte offset"),
        "{text}"
    );
    let (err, text) = error(&d.join("cut.mcap"), &StreamSelection::default());
    assert!(matches!(err, Error::Ros { .. }), "{err:?}");
    assert!(text.contains("cut.mcap") && text.contains("MCAP"), "{text}");
    // Any other cut of a bag is refused too, never read as a shorter bag.
    let whole = std::fs::read(d.join("dvs_bz2.bag")).unwrap();
    for keep in [20, 4100, whole.len() / 2, whole.len() - 1] {
        let path = d.join(format!("cut_{keep}.bag"));
        std::fs::write(&path, &whole[..keep]).unwrap();
        let (err, text) = error(&path, &StreamSelection::default());
        assert!(
            matches!(err, Error::Ros { .. }) && text.contains(&format!("cut_{keep}.bag")),
            "{keep}: {text}"
        );
    }
}

#[test]
fn an_unknown_packet_encoding_names_topic_message_and_encoding() {
    let Some(dir) = written() else { return };
    let (err, text) = error(&dir.path().join("evt4.mcap"), &StreamSelection::default());
    assert!(matches!(err, Error::Ros { .. }), "{err:?}");
    assert!(
        text.contains("evt4.mcap")
            && text.contains("topic /mono/events, message 2")
            && text.contains("unknown EventPacket encoding `evt4`"),
        "{text}"
    );
}

#[test]
fn the_fuzz_entry_points_decode_whole_bags() {
    let Some(dir) = written() else { return };
    let d = dir.path();
    let rec = evtac_formats::read_recording(d.join("dvs_bz2.bag")).unwrap();
    let bag = std::fs::read(d.join("dvs_bz2.bag")).unwrap();
    assert_eq!(
        evtac_formats::ros::fuzz_decode_rosbag(&bag),
        rec.events.len() + rec.imu.len()
    );
    let rec = evtac_formats::read_recording(d.join("dvs2_zstd")).unwrap();
    let mcap = std::fs::read(d.join("dvs2_zstd/dvs2_zstd.mcap")).unwrap();
    assert_eq!(
        evtac_formats::ros::fuzz_decode_mcap(&mcap),
        rec.events.len() + rec.imu.len()
    );
    // Each entry point refuses the other container.
    assert_eq!(evtac_formats::ros::fuzz_decode_rosbag(&mcap), 0);
    assert_eq!(evtac_formats::ros::fuzz_decode_mcap(&bag), 0);
}

/// Found by the `mcap` fuzz target: a record inside a chunk declaring 5 PB made the `mcap`
/// crate's message stream reserve it (the process aborted on the failed allocation); a schema
/// name declaring 2 GiB is reserved by the crate before it is checked. Both are errors naming
/// the file, and the first allocates no more than the file backs. (Since evtac opens chunks
/// itself, the damaged lz4 chunk around the 5 PB record is refused before its records are read:
/// its frame holds fewer bytes than its header declares.)
#[test]
fn damaged_mcap_lengths_are_errors_not_aborts() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/formats/regressions");
    let huge = dir.join("mcap-record-of-5-petabytes.mcap");
    let (result, largest) =
        crate::alloc::largest_allocation_during(|| evtac_formats::read_recording(&huge));
    let err = result.unwrap_err().to_string();
    assert!(
        err.contains("mcap-record-of-5-petabytes.mcap") && err.contains("broken MCAP container"),
        "{err}"
    );
    assert!(largest < 64 << 20, "allocated {largest} bytes");
    let string = dir.join("mcap-string-of-2-gibibytes.mcap");
    let err = evtac_formats::read_recording(&string)
        .unwrap_err()
        .to_string();
    assert!(err.contains("mcap-string-of-2-gibibytes.mcap"), "{err}");
}

/// Found by the `mcap` fuzz target on November 27 (an input of its committed corpus, once
/// allocations above 512 MB counted as crashes): a channel record of a few bytes whose
/// metadata map holds a string declaring 4 GiB, which the `mcap` crate reserved before reading
/// it. Every string of a record is now checked against the record before the crate parses it.
#[test]
fn a_channel_string_longer_than_its_record_is_an_error_not_a_reservation() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/formats/regressions/mcap-channel-metadata-string-of-4-gibibytes.mcap");
    let (result, largest) =
        crate::alloc::largest_allocation_during(|| evtac_formats::read_recording(&path));
    let err = result.unwrap_err().to_string();
    assert!(
        err.contains("mcap-channel-metadata-string-of-4-gibibytes.mcap")
            && err.contains("holds a string longer than the record"),
        "{err}"
    );
    assert!(largest < 64 << 20, "allocated {largest} bytes");
}

/// Found by the `mcap` fuzz target on November 27, after the fix above: a record the scan has
/// no use for (an index or attachment record before the data end) with a string declaring
/// 1.4 GB, reserved by the `mcap` crate as it parsed the record. Only the records the scan uses
/// are parsed now; the file reads or fails without the reservation.
#[test]
fn a_string_in_a_record_evtac_does_not_use_is_not_reserved() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/formats/regressions/mcap-index-string-of-1-gibibyte.mcap");
    let (_, largest) =
        crate::alloc::largest_allocation_during(|| evtac_formats::read_recording(&path));
    assert!(largest < 64 << 20, "allocated {largest} bytes");
    let bytes = std::fs::read(&path).unwrap();
    let (_, largest) =
        crate::alloc::largest_allocation_during(|| evtac_formats::ros::fuzz_decode_mcap(&bytes));
    assert!(largest < 64 << 20, "allocated {largest} bytes");
}

/// Found by the `mcap` fuzz target on November 27: a record inside an uncompressed chunk whose
/// length reaches past the chunk made the `mcap` crate's linear reader subtract past zero (an
/// overflow panic where overflow is checked; elsewhere a wrapped count, and records read from
/// outside the chunk). evtac now walks a chunk's records itself, every length checked.
#[test]
fn a_record_reaching_past_its_chunk_is_an_error_not_a_panic() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/formats/regressions/mcap-chunk-record-past-its-chunk.mcap");
    let err = evtac_formats::read_recording(&path)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("mcap-chunk-record-past-its-chunk.mcap")
            && err.contains("past the chunk's end"),
        "{err}"
    );
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(evtac_formats::ros::fuzz_decode_mcap(&bytes), 0);
}
