//! Tests of `evtac convert`.

use std::path::Path;

use crate::common::{evtac, run_ok};
use evtac_events::{Event, read_recording};
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
    run_ok(&["convert", s(&csv), s(&npy), "--resolution", "320x240"]);
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
    assert!(err.contains("--resolution"), "{err}");
    let out = evtac()
        .args(["convert", s(&csv), s(&out_path), "--resolution", "640x480"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("event 1 at (x=700, y=10)") && err.contains("640x480"),
        "{err}"
    );
}
