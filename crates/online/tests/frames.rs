//! The representation's frames taken during a run (`Estimator::capture_frames`, `--mcap-frames`)
//! against frames built offline: for every representation, each frame set at an estimate's
//! time equals, pixel for pixel, a fresh extractor's frame after the same events, the static
//! and dynamic parts of the combined representation equal the frames of a static-only and a
//! dynamic-only extractor with the same settings, and capturing frames changes no estimate.
//! The frames logged to MCAP are then read back by the `mcap` crate and `rosbags`, pixel for
//! pixel as 0 and 255 `mono8` images.

use crate::support::{self, SENSOR, Synthetic};
use evtac_events::Event;
use evtac_learn::Model;
use evtac_online::frames::{FrameSet, Part};
use evtac_online::input::MemorySource;
use evtac_online::mcap_log::McapLog;
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::{Estimate, Estimator};
use evtac_repr::{CROP, FeatureExtractor, ReprConfig};
use std::ops::ControlFlow;

/// The estimates and frame sets of `events` replayed in chunks of 3,000, frames every
/// `every_us` when given.
fn run(model: &Model, events: &[Event], every_us: Option<i64>) -> (Vec<Estimate>, Vec<FrameSet>) {
    let mut estimator = Estimator::for_model(model, SENSOR, 1000).unwrap();
    if let Some(every) = every_us {
        estimator.capture_frames(every).unwrap();
    }
    let (mut estimates, mut frames) = (Vec::new(), Vec::new());
    pipeline::run(
        MemorySource::new(events.to_vec(), 3000),
        estimator,
        &PipelineConfig::default(),
        |out| {
            match out {
                Output::Estimate(e) => estimates.push(e),
                Output::Frames(f) => frames.push(f),
                Output::Notice(_) => {}
            }
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    (estimates, frames)
}

/// The frame of a fresh extractor for `config` after the events up to `t_us` (cropped to the
/// centered crop as the estimator crops them).
fn offline_frame(config: &ReprConfig, events: &[Event], t_us: i64) -> Vec<u8> {
    let roi = evtac_repr::centered_crop(SENSOR).unwrap();
    let mut fx = FeatureExtractor::new(std::slice::from_ref(config), CROP, None).unwrap();
    let upto: Vec<Event> = events.iter().copied().filter(|e| e.t <= t_us).collect();
    fx.push_with_roi(&upto, &roi).unwrap();
    fx.advance_to(t_us).unwrap();
    fx.frame(0).to_vec()
}

#[test]
fn frames_equal_offline_frames_and_change_no_estimate() {
    let events = Synthetic::new(31, 300_000.0, 1000, 700_000).collect();
    for (name, repr) in support::representations() {
        let dir = tempfile::tempdir().unwrap();
        support::seeded_bundle(dir.path(), 5, &repr, None);
        let model = Model::load(dir.path()).unwrap();
        let (plain, none) = run(&model, &events, None);
        assert!(none.is_empty(), "{name}: frames without asking");
        let (estimates, frames) = run(&model, &events, Some(100_000));
        support::assert_same_estimates(&plain, &estimates);
        // At the first estimate, then at the first estimate 100 ms or more after the last.
        let times: Vec<i64> = frames.iter().map(|f| f.t_us).collect();
        let first = estimates[0].t_us;
        let want: Vec<i64> = (0..7).map(|k| first + k * 100_000).collect();
        assert_eq!(times, want, "{name}");
        let parts = |set: &FrameSet| set.frames.iter().map(|f| f.part).collect::<Vec<_>>();
        for set in &frames {
            let whole = offline_frame(&repr, &events, set.t_us);
            for f in &set.frames {
                assert_eq!((f.width, f.height), (240, 240), "{name} {:?}", f.part);
                assert!(f.pixels.iter().all(|&p| p <= 1));
            }
            let get = |part| &set.frames.iter().find(|f| f.part == part).unwrap().pixels;
            match repr {
                ReprConfig::Static(_) => {
                    assert_eq!(parts(set), [Part::Static]);
                    assert!(*get(Part::Static) == whole);
                }
                ReprConfig::Dynamic(_) => {
                    assert_eq!(parts(set), [Part::Dynamic]);
                    assert!(*get(Part::Dynamic) == whole);
                }
                ReprConfig::Combined {
                    static_part,
                    dynamic_part,
                } => {
                    assert_eq!(parts(set), [Part::Static, Part::Dynamic, Part::Combined]);
                    assert!(*get(Part::Combined) == whole, "t = {}", set.t_us);
                    let s = offline_frame(&ReprConfig::Static(static_part), &events, set.t_us);
                    let d = offline_frame(&ReprConfig::Dynamic(dynamic_part), &events, set.t_us);
                    assert!(*get(Part::Static) == s, "static part at {}", set.t_us);
                    assert!(*get(Part::Dynamic) == d, "dynamic part at {}", set.t_us);
                    let or: Vec<u8> = s.iter().zip(&d).map(|(a, b)| a | b).collect();
                    assert!(whole == or);
                }
                ReprConfig::TimeSurface(_)
                | ReprConfig::Histogram(_)
                | ReprConfig::VoxelGrid(_) => panic!("{name}: frames of a real-valued kind"),
                ReprConfig::Stacked { .. } | ReprConfig::Late { .. } => {
                    assert_eq!(parts(set), [Part::Static, Part::Dynamic]);
                    assert!(*get(Part::Static) == whole[..240 * 240]);
                    assert!(*get(Part::Dynamic) == whole[240 * 240..]);
                }
            }
        }
        // Not blank: the check would be weak on empty frames.
        let set_pixels: usize = frames
            .iter()
            .flat_map(|s| &s.frames)
            .map(|f| f.pixels.iter().filter(|&&p| p == 1).count())
            .sum();
        assert!(set_pixels > 1000, "{name}: {set_pixels} pixels set in all");
    }
}

#[test]
fn frames_asked_for_mid_stream_are_refused() {
    let (_, repr) = support::representations()[2];
    let dir = tempfile::tempdir().unwrap();
    support::seeded_bundle(dir.path(), 5, &repr, None);
    let model = Model::load(dir.path()).unwrap();
    let mut estimator = Estimator::for_model(&model, SENSOR, 1000).unwrap();
    let events = Synthetic::new(3, 300_000.0, 1000, 5_000).collect();
    estimator
        .process(&events, None, std::time::Instant::now(), &mut |_| {})
        .unwrap();
    let err = estimator.capture_frames(100_000).unwrap_err();
    assert!(err.to_string().contains("before the first events"), "{err}");
}

/// Prints, for every image message of the MCAP file `argv[1]`: the reader, topic, type, log
/// time, stamp, size, encoding, step and a hash of the pixels.
const READ_IMAGES: &str = r#"
import hashlib, sys
from pathlib import Path
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

path = Path(sys.argv[1])
with open(path, 'rb') as f:
    for schema, channel, message in make_reader(f).iter_messages(log_time_order=False):
        if schema.name == 'sensor_msgs/msg/Image':
            print('mcap', channel.topic, schema.encoding, message.log_time)
with AnyReader([path]) as reader:
    for connection, timestamp, rawdata in reader.messages():
        if connection.msgtype != 'sensor_msgs/msg/Image':
            continue
        m = reader.typestore.deserialize_cdr(rawdata, connection.msgtype)
        assert set(m.data.tolist()) <= {0, 255}
        print('rosbags', connection.topic, timestamp, m.header.stamp.sec, m.header.stamp.nanosec,
              m.header.frame_id, m.height, m.width, m.encoding, m.is_bigendian, m.step,
              hashlib.sha256(bytes(m.data)).hexdigest())
"#;

#[test]
fn logged_frames_read_back_as_mono8_images() {
    let events = Synthetic::new(37, 300_000.0, 1000, 400_000).collect();
    let (_, repr) = support::representations()[2];
    let dir = tempfile::tempdir().unwrap();
    support::seeded_bundle(dir.path(), 7, &repr, None);
    let model = Model::load(dir.path()).unwrap();
    let (estimates, frames) = run(&model, &events, Some(50_000));
    let path = dir.path().join("run.mcap");
    let mut log = McapLog::create(&path, &[] as &[&str], "/contact_angle", "left").unwrap();
    // As the CLI writes them: each frame set after the estimate of its time.
    let mut sets = frames.iter().peekable();
    for e in &estimates {
        log.write(e).unwrap();
        while let Some(set) = sets.next_if(|s| s.t_us <= e.t_us) {
            log.write_frames(set).unwrap();
        }
    }
    assert_eq!(log.frame_sets_written() as usize, frames.len());
    log.finish().unwrap();

    let Some(python) = evtac_testkit::python_with("rosbags") else {
        return;
    };
    let script = dir.path().join("read_images.py");
    std::fs::write(&script, READ_IMAGES).unwrap();
    let out = std::process::Command::new(python)
        .arg(&script)
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut want_mcap = Vec::new();
    let mut want_rosbags = Vec::new();
    for set in &frames {
        for f in &set.frames {
            let topic = format!("/contact_angle/frames/{}", f.part.name());
            let ns = set.t_us * 1000;
            want_mcap.push(format!("mcap {topic} ros2msg {ns}"));
            let mono8: Vec<u8> = f.pixels.iter().map(|&p| p * 255).collect();
            let hash = sha256_hex(&mono8);
            want_rosbags.push(format!(
                "rosbags {topic} {ns} {} {} left 240 240 mono8 0 240 {hash}",
                set.t_us / 1_000_000,
                (set.t_us % 1_000_000) * 1000
            ));
        }
    }
    let got = |reader: &str| -> Vec<String> {
        text.lines()
            .filter(|l| l.starts_with(reader))
            .map(str::to_owned)
            .collect()
    };
    assert_eq!(got("mcap "), want_mcap);
    assert_eq!(got("rosbags "), want_rosbags);
}

/// SHA-256 in hex, to compare pixels with Python's `hashlib` without printing them.
fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}
