//! The data-loss bugs of issue 34: a command never writes over its input, a failed command
//! leaves no output that looks valid, and an AEDAT4 file with two cameras (written by
//! dv-processing's `StereoCameraWriter`) is read one camera at a time.

use std::path::{Path, PathBuf};

use crate::common::{run_err, run_ok};
use evtac_events::{Event, ImuSample, Resolution};
use evtac_formats::{EventWriter, read_recording};
use evtac_testkit::{real_fixture, run_python};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A small AEDAT4 recording with IMU samples, and its bytes.
fn recording(dir: &Path) -> (PathBuf, Vec<u8>) {
    let path = dir.join("x.aedat4");
    let mut w = EventWriter::create(&path, Some(Resolution::new(64, 48)), Some("cam")).unwrap();
    let events: Vec<Event> = (0..5000)
        .map(|i| Event {
            t: 1_000 + i * 7,
            x: (i % 64) as u16,
            y: (i % 48) as u16,
            polarity: i % 3 == 0,
        })
        .collect();
    w.write_events(&events).unwrap();
    let imu: Vec<ImuSample> = (0..40)
        .map(|i| ImuSample {
            t: 1_000 + i * 800,
            ..ImuSample::default()
        })
        .collect();
    w.write_imu(&imu).unwrap();
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    (path, bytes)
}

#[test]
fn convert_refuses_to_write_over_its_input_by_path_or_through_links() {
    let dir = tempfile::tempdir().unwrap();
    let (input, bytes) = recording(dir.path());
    let err = run_err(&["convert", s(&input), s(&input)]);
    assert!(err.contains("refusing to write over it"), "{err}");
    let soft = dir.path().join("soft.aedat4");
    std::os::unix::fs::symlink(&input, &soft).unwrap();
    let err = run_err(&["convert", s(&input), s(&soft)]);
    assert!(err.contains("through a link"), "{err}");
    let hard = dir.path().join("hard.aedat4");
    std::fs::hard_link(&input, &hard).unwrap();
    run_err(&["convert", s(&hard), s(&input)]);
    // The IMU output is checked too.
    let out = dir.path().join("out.aedat4");
    run_err(&["convert", s(&input), s(&out), "--imu", s(&input)]);
    assert!(!out.exists());
    assert_eq!(
        std::fs::read(&input).unwrap(),
        bytes,
        "the recording is intact"
    );

    // A CSV input, the same.
    let csv = dir.path().join("x.csv");
    run_ok(&["convert", s(&input), s(&csv)]);
    let csv_bytes = std::fs::read(&csv).unwrap();
    let err = run_err(&["convert", s(&csv), s(&csv), "--sensor", "64x48"]);
    assert!(err.contains("refusing to write over it"), "{err}");
    assert_eq!(std::fs::read(&csv).unwrap(), csv_bytes);
}

#[test]
fn represent_and_predict_refuse_to_write_over_their_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let samples = dir.path().join("samples.txt");
    std::fs::write(&samples, "2000\n").unwrap();
    let before = std::fs::read(&samples).unwrap();
    let (input, _) = recording(dir.path());
    let err = run_err(&[
        "represent",
        s(&input),
        "--samples",
        s(&samples),
        "--output",
        s(&samples),
        "--roi",
        "none",
    ]);
    assert!(err.contains("refusing to write over it"), "{err}");
    assert_eq!(std::fs::read(&samples).unwrap(), before);
    let features = dir.path().join("f.npy");
    std::fs::write(&features, b"kept").unwrap();
    let err = run_err(&[
        "predict",
        "--model",
        s(dir.path()),
        "--features",
        s(&features),
        "--output",
        s(&features),
    ]);
    assert!(err.contains("refusing to write over it"), "{err}");
    assert_eq!(std::fs::read(&features).unwrap(), b"kept");
}

/// The names in `dir` other than `keep` (temporary files left behind, outputs that should not
/// exist).
fn others(dir: &Path, keep: &[&Path]) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| !keep.contains(&p.as_path()))
        .map(|p| p.display().to_string())
        .collect()
}

#[test]
fn a_failed_convert_leaves_no_output_and_an_earlier_one_untouched() {
    let Some(fixture) = real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let truncated = dir.path().join("cut.aedat4");
    let bytes = std::fs::read(&fixture).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    for name in ["out.npy", "out.aedat4", "out.csv"] {
        let out = dir.path().join(name);
        let err = run_err(&["convert", s(&truncated), s(&out)]);
        assert!(err.contains("cut.aedat4"), "{err}");
        assert!(
            !out.exists(),
            "{name}: a failed conversion wrote {}",
            out.display()
        );
    }
    let imu = dir.path().join("imu.csv");
    let out = dir.path().join("out.npy");
    run_err(&["convert", s(&truncated), s(&out), "--imu", s(&imu)]);
    assert!(!imu.exists());
    assert_eq!(others(dir.path(), &[&truncated]), Vec::<String>::new());

    // An earlier output of the same name stays as it was.
    std::fs::write(&out, b"earlier").unwrap();
    run_err(&["convert", s(&truncated), s(&out)]);
    assert_eq!(std::fs::read(&out).unwrap(), b"earlier");
    run_ok(&["convert", s(&fixture), s(&out)]);
    assert_eq!(
        evtac_formats::read_recording(&out)
            .map(|r| r.events.len())
            .ok(),
        read_recording(&fixture).map(|r| r.events.len()).ok()
    );
    assert_eq!(
        others(dir.path(), &[&truncated, &out]),
        Vec::<String>::new()
    );
}

/// dv-processing's `StereoCameraWriter` records two cameras whose events and IMU samples
/// interleave in time (the right camera 3 us after the left), each dumped raw beside it.
pub(crate) const PY_STEREO: &str = r#"
import sys, numpy as np, dv_processing as dv
out = sys.argv[1]
left, right = (sys.argv[2], sys.argv[3]) if len(sys.argv) > 3 else ("DVXplorer_L", "DAVIS346_R")
def cfg(name, size):
    c = dv.io.MonoCameraWriter.Config(name)
    c.addEventStream(size)
    c.addImuStream()
    return c
w = dv.io.StereoCameraWriter(f"{out}/stereo.aedat4", cfg(left, (640, 480)), cfg(right, (346, 260)))
rng = np.random.default_rng(34)
t0 = 1_600_000_000_000_000
dumps = {}
for side, writer, size, off in (("left", w.left, (640, 480), 0), ("right", w.right, (346, 260), 3)):
    n = 3000
    t = t0 + off + np.arange(n) * 5
    x = rng.integers(0, size[0], n); y = rng.integers(0, size[1], n); p = rng.integers(0, 2, n)
    ti = t0 + off + np.arange(30) * 500
    dumps[side] = (writer, t, x, y, p, ti)
for k in range(0, 3000, 500):
    for side in ("left", "right"):
        writer, t, x, y, p, ti = dumps[side]
        s = dv.EventStore()
        for i in range(k, k + 500):
            s.push_back(int(t[i]), int(x[i]), int(y[i]), bool(p[i]))
        writer.writeEvents(s)
        for j in range(k // 100, k // 100 + 5):
            writer.writeImu(dv.IMU(int(ti[j]), 0.0, float(j), 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
del w
for side in ("left", "right"):
    _, t, x, y, p, ti = dumps[side]
    ev = np.zeros(len(t), dtype=[("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")])
    ev["t"], ev["x"], ev["y"], ev["p"] = t, x, y, p
    ev.tofile(f"{out}/{side}.events")
    ti.astype("<i8").tofile(f"{out}/{side}.imu_t")
"#;

fn raw_events(path: &Path) -> Vec<Event> {
    std::fs::read(path)
        .unwrap()
        .chunks_exact(13)
        .map(|r| Event {
            t: i64::from_le_bytes(r[..8].try_into().unwrap()),
            x: u16::from_le_bytes([r[8], r[9]]),
            y: u16::from_le_bytes([r[10], r[11]]),
            polarity: r[12] != 0,
        })
        .collect()
}

fn raw_times(path: &Path) -> Vec<i64> {
    std::fs::read(path)
        .unwrap()
        .chunks_exact(8)
        .map(|r| i64::from_le_bytes(r.try_into().unwrap()))
        .collect()
}

#[test]
fn a_two_camera_file_is_read_one_camera_at_a_time() {
    let dir = tempfile::tempdir().unwrap();
    if run_python(PY_STEREO, &[s(dir.path())]).is_none() {
        return;
    }
    let stereo = dir.path().join("stereo.aedat4");

    // info lists every stream, and without a choice reports no camera's counts as the file's.
    let out = run_ok(&["info", s(&stereo), "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let streams = info["streams"].as_array().unwrap();
    assert_eq!(streams.len(), 4);
    let row = |id: i64| streams.iter().find(|r| r["id"] == id).unwrap();
    assert_eq!(row(0)["type"], "EVTS");
    assert_eq!(row(0)["source"], "DVXplorer_L");
    assert_eq!(
        (row(0)["width"].as_i64(), row(0)["count"].as_i64()),
        (Some(640), Some(3000))
    );
    assert_eq!(
        (row(2)["width"].as_i64(), row(2)["count"].as_i64()),
        (Some(346), Some(3000))
    );
    assert_eq!(
        (row(1)["type"].as_str(), row(1)["count"].as_i64()),
        (Some("IMUS"), Some(30))
    );
    assert_eq!(info["events"], 0);
    assert!(
        info["selection"].as_str().unwrap().contains("--stream"),
        "{info}"
    );
    let text = String::from_utf8(run_ok(&["info", s(&stereo)]).stdout).unwrap();
    assert!(
        text.contains("id 2: EVTS `events` from DAVIS346_R 346x260: 3000 elements"),
        "{text}"
    );

    // Reading without a choice is an error that lists the streams.
    let plain = dir.path().join("plain.aedat4");
    let err = run_err(&["convert", s(&stereo), s(&plain)]);
    assert!(err.contains("2 event streams"), "{err}");
    assert!(
        err.contains("id 0: EVTS `events` from DVXplorer_L 640x480"),
        "{err}"
    );
    assert!(!plain.exists());

    // Each camera on its own, by camera name or id, with its own IMU.
    for (side, choice, size, source) in [
        (
            "left",
            "DVXplorer_L",
            Resolution::new(640, 480),
            "DVXplorer_L",
        ),
        ("right", "2", Resolution::new(346, 260), "DAVIS346_R"),
    ] {
        let out = dir.path().join(format!("{side}.aedat4"));
        run_ok(&["convert", s(&stereo), s(&out), "--stream", choice]);
        let rec = read_recording(&out).unwrap();
        assert_eq!(
            rec.events,
            raw_events(&dir.path().join(format!("{side}.events")))
        );
        let imu_t: Vec<i64> = rec.imu.iter().map(|s| s.t).collect();
        assert_eq!(imu_t, raw_times(&dir.path().join(format!("{side}.imu_t"))));
        assert_eq!(rec.resolution, Some(size));
        assert_eq!(rec.source.as_deref(), Some(source));
        let info = run_ok(&["info", s(&stereo), "--json", "--stream", choice]);
        let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
        assert_eq!(
            (info["events"].as_i64(), info["imu_samples"].as_i64()),
            (Some(3000), Some(30))
        );
        assert_eq!(info["width"].as_i64(), Some(i64::from(size.width)));
    }
    let err = run_err(&["convert", s(&stereo), s(&plain), "--stream", "events"]);
    assert!(err.contains("2 event streams have that name"), "{err}");
    let err = run_err(&["info", s(&stereo), "--stream", "7"]);
    assert!(err.contains("--stream 7: no event stream"), "{err}");
    // stats reads one camera too (the recording is too short for its noise figures, which is
    // the next thing it says).
    let err = run_err(&["stats", s(&stereo)]);
    assert!(err.contains("2 event streams"), "{err}");
    let err = run_err(&["stats", s(&stereo), "--stream", "DAVIS346_R"]);
    assert!(!err.contains("event streams"), "{err}");
}
