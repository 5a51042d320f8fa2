//! Tests of `evtac info`.

use crate::common::{evtac, run_ok};
use evtac_testkit::real_fixture;

#[test]
fn dvxplorer_json_has_the_expected_figures() {
    let Some(path) = real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let out = run_ok(&["info", path.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    assert_eq!(v["format"], "AEDAT4");
    assert_eq!(v["source"], "DVXplorer_DXB00010");
    assert_eq!(v["width"], 320);
    assert_eq!(v["height"], 240);
    assert_eq!(v["events"], 111_954);
    assert_eq!(v["on_events"], 55_023);
    assert_eq!(v["first_t_us"], 1_605_537_493_718_345_i64);
    assert_eq!(v["last_t_us"], 1_605_537_494_308_262_i64);
    assert_eq!(v["imu_samples"], 475);
    assert_eq!(v["first_imu_t_us"], 1_605_537_493_718_788_i64);
    assert_eq!(v["last_imu_t_us"], 1_605_537_494_307_448_i64);
    let rate = v["imu_rate_hz"].as_f64().unwrap();
    assert!((rate - 805.0).abs() < 5.0, "{rate}");
}

#[test]
fn human_output_names_the_figures() {
    let Some(path) = real_fixture("prophesee_gen3_640x480.evt2.raw") else {
        return;
    };
    let out = run_ok(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("format:      EVT2"), "{text}");
    assert!(text.contains("resolution:  640x480"), "{text}");
    assert!(text.contains("events:      521252"), "{text}");
    assert!(text.contains("913716224 .. 913812095 us"), "{text}");
    // Progress bars stay off when stderr is not a terminal.
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn broken_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.npy");
    std::fs::write(&path, b"\x93NUMPY\x01\x00\x40").unwrap();
    let out = evtac()
        .args(["info", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cut.npy") && err.contains("cut off"), "{err}");
}

#[test]
fn triggers_are_counted() {
    use evtac_events::{Resolution, Trigger};
    use evtac_formats::aedat::{AedatWriter, WriterConfig};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sync.aedat4");
    let mut w =
        AedatWriter::create(&path, WriterConfig::new(Resolution::new(8, 8), "cam")).unwrap();
    let triggers: Vec<Trigger> = (0..150)
        .map(|i| Trigger {
            t: i * 700,
            kind: 1,
        })
        .collect();
    w.write_triggers(&triggers).unwrap();
    w.finish().unwrap();
    let out = run_ok(&["info", path.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    assert_eq!(v["triggers"], 150);
    assert_eq!(v["events"], 0);
    let out = run_ok(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("triggers:    150"), "{text}");
}
