//! Tests of `evtac convert`.

use std::path::Path;

use crate::common::{evtac, run_ok};
use evtac_events::Event;
use evtac_formats::read_recording;
use evtac_testkit::real_fixture;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn aedat4_to_csv_to_npy_to_aedat4_is_identical() {
    let Some(src) = real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (csv, npy, back, imu) = (
        dir.path().join("a.csv"),
        dir.path().join("a.npy"),
        dir.path().join("back.aedat4"),
        dir.path().join("imu.csv"),
    );
    run_ok(&["convert", s(&src), s(&csv), "--imu", s(&imu)]);
    run_ok(&["convert", s(&csv), s(&npy), "--sensor", "320x240"]);
    // `--resolution`, the flag's name before `--sensor`, still works.
    run_ok(&["convert", s(&npy), s(&back), "--resolution", "320x240"]);
    let original = read_recording(&src).unwrap();
    let round = read_recording(&back).unwrap();
    assert_eq!(round.events, original.events);
    assert_eq!(round.resolution, original.resolution);
    let imu_text = std::fs::read_to_string(&imu).unwrap();
    let mut lines = imu_text.lines();
    assert_eq!(lines.next(), Some("t,ax,ay,az,gx,gy,gz,temperature"));
    assert_eq!(lines.count(), 475);
    let csv_text = std::fs::read_to_string(&csv).unwrap();
    assert!(
        csv_text.starts_with("t,x,y,p\n1605537493718345,"),
        "{}",
        &csv_text[..40]
    );
}

#[test]
fn aedat4_keeps_imu_and_source() {
    let Some(src) = real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("copy.aedat4");
    run_ok(&["convert", s(&src), s(&out)]);
    let (a, b) = (read_recording(&src).unwrap(), read_recording(&out).unwrap());
    assert_eq!(b.events, a.events);
    assert_eq!(b.imu, a.imu);
    assert_eq!(b.source, a.source);
}

#[test]
fn roi_crops_centered_and_maps_coordinates() {
    let Some(src) = real_fixture("prophesee_gen3_640x480.evt2.raw") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("roi.aedat4");
    run_ok(&["convert", s(&src), s(&out), "--roi", "240x240"]);
    let original = read_recording(&src).unwrap();
    let cropped = read_recording(&out).unwrap();
    assert_eq!(
        cropped.resolution,
        Some(evtac_events::Resolution::new(240, 240))
    );
    let expected: Vec<Event> = original
        .events
        .iter()
        .filter(|e| (200..440).contains(&e.x) && (120..360).contains(&e.y))
        .map(|e| Event {
            x: e.x - 200,
            y: e.y - 120,
            ..*e
        })
        .collect();
    assert!(!expected.is_empty() && expected.len() < original.events.len());
    assert_eq!(cropped.events, expected);
}

#[test]
fn missing_or_wrong_resolution_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("e.csv");
    std::fs::write(&csv, "t,x,y,p\n1,10,10,1\n2,700,10,0\n").unwrap();
    let out_path = dir.path().join("o.aedat4");
    let out = evtac()
        .args(["convert", s(&csv), s(&out_path)])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--sensor"), "{err}");
    let out = evtac()
        .args(["convert", s(&csv), s(&out_path), "--sensor", "640x480"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("event 1 at (x=700, y=10)") && err.contains("640x480"),
        "{err}"
    );
}

/// An AEDAT4 file with events, IMU and triggers over 2 s; with a data table unless `table` is
/// false.
fn with_triggers(path: &Path, table: bool) -> evtac_formats::Recording {
    use evtac_events::{ImuSample, Resolution, Trigger};
    use evtac_formats::aedat::{AedatWriter, WriterConfig};
    let t0 = 1_700_000_000_000_000i64;
    let events: Vec<Event> = (0..200_000i64)
        .map(|i| Event {
            t: t0 + i * 10,
            x: (i % 64) as u16,
            y: (i % 48) as u16,
            polarity: i % 3 == 0,
        })
        .collect();
    let imu: Vec<ImuSample> = (0..2000i64)
        .map(|i| ImuSample {
            t: t0 + i * 1000,
            ..Default::default()
        })
        .collect();
    let triggers: Vec<Trigger> = (0..200i64)
        .map(|i| Trigger {
            t: t0 + i * 10_000 + 3,
            kind: (i % 2 + 1) as i8,
        })
        .collect();
    fn fill<W: std::io::Write>(mut w: AedatWriter<W>, e: &[Event], i: &[ImuSample], t: &[Trigger]) {
        w.write_events(e).unwrap();
        w.write_imu(i).unwrap();
        w.write_triggers(t).unwrap();
        w.finish().unwrap();
    }
    let config = WriterConfig::new(Resolution::new(64, 48), "DVXplorer_SYNC");
    let file = std::fs::File::create(path).unwrap();
    if table {
        let w = AedatWriter::new_seekable(file, config).unwrap();
        fill(w, &events, &imu, &triggers);
    } else {
        fill(
            AedatWriter::new(file, config).unwrap(),
            &events,
            &imu,
            &triggers,
        );
    }
    read_recording(path).unwrap()
}

#[test]
fn aedat4_keeps_triggers() {
    let dir = tempfile::tempdir().unwrap();
    let (src, out) = (
        dir.path().join("sync.aedat4"),
        dir.path().join("copy.aedat4"),
    );
    let original = with_triggers(&src, true);
    assert_eq!(original.triggers.len(), 200);
    run_ok(&["convert", s(&src), s(&out)]);
    let copy = read_recording(&out).unwrap();
    assert_eq!(copy.triggers, original.triggers);
    assert_eq!(copy.events, original.events);
    assert_eq!(copy.imu, original.imu);
    // Event-only formats say what they leave out.
    let csv = dir.path().join("e.csv");
    let o = run_ok(&["convert", s(&src), s(&csv)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("200 triggers were not written"), "{err}");
}

/// Runs `evtac convert SRC OUT --from-us FROM --to-us TO` (plus `extra`); returns its stderr.
fn convert_range(src: &Path, out: &Path, from: i64, to: i64, extra: &[&str]) -> String {
    let (from, to) = (from.to_string(), to.to_string());
    let mut args = vec![
        "convert",
        s(src),
        s(out),
        "--from-us",
        &from,
        "--to-us",
        &to,
    ];
    args.extend_from_slice(extra);
    String::from_utf8_lossy(&run_ok(&args).stderr).into_owned()
}

/// `rec` cut to `[from, to)` by filtering what was read whole.
fn filtered(rec: &evtac_formats::Recording, from: i64, to: i64) -> evtac_formats::Recording {
    let inside = |t: i64| from <= t && t < to;
    evtac_formats::Recording {
        events: rec.events.iter().copied().filter(|e| inside(e.t)).collect(),
        imu: rec.imu.iter().copied().filter(|s| inside(s.t)).collect(),
        triggers: rec
            .triggers
            .iter()
            .copied()
            .filter(|t| inside(t.t))
            .collect(),
        ..rec.clone()
    }
}

#[test]
fn time_range_keeps_exactly_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let (src, out) = (
        dir.path().join("sync.aedat4"),
        dir.path().join("cut.aedat4"),
    );
    let original = with_triggers(&src, true);
    let (from, to) = (
        original.events[0].t + 500_003,
        original.events[0].t + 750_000,
    );
    let err = convert_range(&src, &out, from, to, &[]);
    assert!(!err.contains("warning"), "{err}");
    let expected = filtered(&original, from, to);
    assert_eq!(
        (expected.events.len(), expected.triggers.len()),
        (24_999, 25)
    );
    assert_eq!(read_recording(&out).unwrap(), expected);
}

#[test]
fn time_range_of_the_real_recording_and_of_a_csv() {
    let Some(src) = real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (out, csv, csv_cut) = (
        dir.path().join("cut.aedat4"),
        dir.path().join("all.csv"),
        dir.path().join("cut.csv"),
    );
    let (from, to) = (1_605_537_493_900_000, 1_605_537_494_000_000);
    convert_range(&src, &out, from, to, &[]);
    let original = read_recording(&src).unwrap();
    let expected = filtered(&original, from, to);
    assert!(!expected.events.is_empty() && expected.events.len() < original.events.len());
    assert!(!expected.imu.is_empty());
    assert_eq!(read_recording(&out).unwrap(), expected);
    // A format without an index is cut the same way, without a warning.
    run_ok(&["convert", s(&src), s(&csv)]);
    let err = convert_range(&csv, &csv_cut, from, to, &["--sensor", "320x240"]);
    assert!(!err.contains("warning"), "{err}");
    assert_eq!(read_recording(&csv_cut).unwrap().events, expected.events);
}

#[test]
fn time_range_without_a_usable_data_table_warns_once_and_gives_the_same_result() {
    let dir = tempfile::tempdir().unwrap();
    let (missing, damaged, out) = (
        dir.path().join("notable.aedat4"),
        dir.path().join("damaged.aedat4"),
        dir.path().join("cut.aedat4"),
    );
    let original = with_triggers(&missing, false);
    // The same data with a table, whose LZ4 frame is then broken.
    with_triggers(&damaged, true);
    let mut bytes = std::fs::read(&damaged).unwrap();
    let table = evtac_formats::aedat::AedatReader::from_slice(&bytes)
        .unwrap()
        .header()
        .data_table_position
        .unwrap() as usize;
    bytes[table..table + 4].copy_from_slice(b"junk");
    std::fs::write(&damaged, bytes).unwrap();
    let (from, to) = (
        original.events[0].t + 100_000,
        original.events[0].t + 200_000,
    );
    let expected = filtered(&original, from, to);
    assert_eq!(expected.triggers.len(), 10);
    for (src, why) in [(&missing, "no data table"), (&damaged, "is unusable")] {
        let err = convert_range(src, &out, from, to, &[]);
        assert_eq!(err.matches("warning").count(), 1, "{err}");
        let name = src.file_name().unwrap().to_str().unwrap();
        assert!(err.contains(name) && err.contains(why), "{err}");
        assert_eq!(read_recording(&out).unwrap(), expected);
    }
}

#[test]
fn empty_time_range_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("sync.aedat4");
    with_triggers(&src, true);
    let out_path = dir.path().join("o.aedat4");
    let out = evtac()
        .args([
            "convert",
            s(&src),
            s(&out_path),
            "--from-us",
            "500",
            "--to-us",
            "500",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("sync.aedat4") && err.contains("--from-us 500 is not before --to-us 500"),
        "{err}"
    );
    // Negative times are times, not options.
    run_ok(&[
        "convert",
        s(&src),
        s(&out_path),
        "--from-us",
        "-5",
        "--to-us",
        "1700000000000100",
    ]);
    assert_eq!(read_recording(&out_path).unwrap().events.len(), 10);
}
