//! `evtac import`'s library half end to end: a session made by concatenating the trials of a
//! simulated dataset (with gaps, behind a no-contact recording) and a log on a shifted clock are
//! imported back into trials equal to the originals; bad logs fail naming the log's line and
//! leave nothing behind.

use crate::simulate;
use evtac_events::manifest::Manifest;
use evtac_events::{Event, ImuSample, Trigger};
use evtac_formats::{EventWriter, Recording, read_recording};
use evtac_import::check::check;
use evtac_import::import::{ImportConfig, ImportError, NoContact, import_session};
use evtac_import::inputs::Inputs;
use evtac_import::robot_log::RobotLog;
use evtac_sim::Protocol;
use std::path::Path;

/// The recording's clock minus the robot's.
const CLOCK_OFFSET_US: i64 = 123_456;

fn shifted(rec: &Recording, by: i64) -> (Vec<Event>, Vec<ImuSample>) {
    let events = rec
        .events
        .iter()
        .map(|e| Event { t: e.t + by, ..*e })
        .collect();
    let imu = rec
        .imu
        .iter()
        .map(|s| ImuSample { t: s.t + by, ..*s })
        .collect();
    (events, imu)
}

/// Writes `session.aedat4` (the no-contact recording at 0, then each trial 2 s after the one
/// before) and `log.csv` (columns reordered, times on the robot's clock) from the dataset `ds`;
/// returns each trial's offset.
fn make_session(ds: &Path, dir: &Path) -> Vec<i64> {
    let manifest = Manifest::read(ds).unwrap();
    let no_contact = read_recording(ds.join("no_contact.aedat4")).unwrap();
    let mut w =
        EventWriter::create(dir.join("session.aedat4"), no_contact.resolution, None).unwrap();
    w.write_events(&no_contact.events).unwrap();
    w.write_imu(&no_contact.imu).unwrap();
    let mut end = no_contact
        .imu
        .last()
        .unwrap()
        .t
        .max(no_contact.events.last().unwrap().t);
    let mut offsets = Vec::new();
    let mut log = String::from(
        "trial,motion_start_us,motion_end_us,direction_deg,speed_deg_s,depth_mm,total_deg,\
         stop_deg,stop_start_us,stop_end_us\n",
    );
    for t in &manifest.trials {
        let rec = read_recording(ds.join(&t.file)).unwrap();
        let offset = end + 2_000_000;
        let (events, imu) = shifted(&rec, offset);
        w.write_events(&events).unwrap();
        w.write_imu(&imu).unwrap();
        // The robot's trigger at the motion's onset.
        let onset = Trigger {
            t: t.motion_start_us + offset,
            kind: 1,
        };
        w.write_triggers(&[onset]).unwrap();
        end = events.last().unwrap().t.max(imu.last().unwrap().t);
        let robot = |us: i64| us + offset - CLOCK_OFFSET_US;
        let opt = |v: Option<i64>| v.map(|v| robot(v).to_string()).unwrap_or_default();
        log.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            t.trial,
            robot(t.motion_start_us),
            robot(t.motion_end_us),
            t.direction_deg,
            t.speed_deg_s,
            t.depth_mm,
            t.total_deg,
            t.stop_deg.map(|v| v.to_string()).unwrap_or_default(),
            opt(t.stop_start_us),
            opt(t.stop_end_us),
        ));
        offsets.push(offset);
    }
    w.finish().unwrap();
    std::fs::write(dir.join("log.csv"), log).unwrap();
    offsets
}

fn config(ds: &Path, no_contact_end: i64) -> ImportConfig {
    ImportConfig {
        pre_us: 1_000_000,
        post_us: 300_000,
        no_contact: Some(NoContact::Range(0, no_contact_end)),
        calibration: Some(ds.join("calibration.json")),
        labels: evtac_labels::LabelSource::Imu,
        filters: Vec::new(),
    }
}

#[test]
fn an_imported_session_gives_back_the_simulated_trials() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("sim");
    simulate(&ds, Protocol::Exp2, 3);
    let offsets = make_session(&ds, dir.path());
    let log = RobotLog::read(&dir.path().join("log.csv"), CLOCK_OFFSET_US).unwrap();
    let out = dir.path().join("imported");
    let done = std::sync::atomic::AtomicUsize::new(0);
    let summary = import_session(
        &dir.path().join("session.aedat4"),
        &log,
        &out,
        &config(&ds, offsets[0] - 1_000_000),
        &|| {
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        },
    )
    .unwrap();
    assert_eq!((summary.trials, done.into_inner()), (3, 3));
    // Cut in the one pass: no trial read again through the data table (a trailing trigger
    // packet keeps its trial open rather than making it be cut again by a range read).
    assert!(summary.index.is_none(), "{:?}", summary.index);

    let original = Manifest::read(&ds).unwrap();
    let imported = Manifest::read(&out).unwrap();
    let mut events = 0;
    for ((a, b), offset) in original.trials.iter().zip(&imported.trials).zip(&offsets) {
        assert_eq!(b.trial, a.trial);
        assert_eq!(b.file, a.file);
        assert_eq!(b.truth, None);
        let times = |t: &evtac_events::manifest::TrialMeta| {
            [
                Some(t.motion_start_us),
                Some(t.motion_end_us),
                t.stop_start_us,
                t.stop_end_us,
            ]
        };
        assert_eq!(times(b), times(a).map(|t| t.map(|t| t + offset)));
        assert_eq!(b.stop_deg, a.stop_deg);
        let want = shifted(&read_recording(ds.join(&a.file)).unwrap(), *offset);
        let got = read_recording(out.join(&b.file)).unwrap();
        let span = |v: &[ImuSample]| (v.len(), v.first().map(|s| s.t), v.last().map(|s| s.t));
        assert_eq!(got.events.len(), want.0.len(), "{}: events", a.trial);
        assert!(got.events == want.0, "{}: events differ", a.trial);
        assert_eq!(span(&got.imu), span(&want.1), "{}: IMU", a.trial);
        assert!(got.imu == want.1, "{}: IMU differs", a.trial);
        let onset = got.triggers.iter().map(|t| t.t).collect::<Vec<_>>();
        assert_eq!(onset, [b.motion_start_us], "{}: triggers", a.trial);
        events += got.events.len() as u64;
    }
    assert_eq!(summary.events, events);
    let no_contact = read_recording(out.join("no_contact.aedat4")).unwrap();
    assert_eq!(
        no_contact.events,
        read_recording(ds.join("no_contact.aedat4")).unwrap().events
    );
    assert_eq!(
        std::fs::read(out.join("calibration.json")).unwrap(),
        std::fs::read(ds.join("calibration.json")).unwrap()
    );
    assert_eq!(check(&out, &Inputs::FROM_FILES, &|_| {}).problems, []);
    let leftovers = std::fs::read_dir(dir.path())
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .contains(".import-")
        })
        .count();
    assert_eq!(leftovers, 0);
    // An existing folder is never overwritten.
    let again = import_session(
        &dir.path().join("session.aedat4"),
        &log,
        &out,
        &config(&ds, 1),
        &|| {},
    );
    assert!(matches!(again, Err(ImportError::Exists(_))));
}

#[test]
fn a_motion_outside_the_session_names_the_log_line_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("sim");
    simulate(&ds, Protocol::Exp1, 2);
    let offsets = make_session(&ds, dir.path());
    let log_path = dir.path().join("log.csv");
    // Without the clock offset the motions are 123 ms early: the second trial's still lead-in is
    // fine, so move its motion far past the session's end instead.
    let text = std::fs::read_to_string(&log_path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[2].split(',').map(String::from).collect();
    for c in &mut cells[1..3] {
        *c = (c.parse::<i64>().unwrap() + 600_000_000).to_string();
    }
    lines[2] = cells.join(",");
    std::fs::write(&log_path, lines.join("\n") + "\n").unwrap();
    let log = RobotLog::read(&log_path, CLOCK_OFFSET_US).unwrap();
    let out = dir.path().join("imported");
    let err = import_session(
        &dir.path().join("session.aedat4"),
        &log,
        &out,
        &config(&ds, offsets[0] - 1_000_000),
        &|| {},
    )
    .unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, ImportError::Problems(_)), "{text}");
    assert!(text.contains("log.csv:3: column `motion_"), "{text}");
    assert!(text.contains("lies outside the recording"), "{text}");
    assert!(!text.contains("log.csv:2:"), "{text}");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(!out.exists());
    assert!(names.iter().all(|n| !n.contains("import")), "{names:?}");
}
