//! The whole-file API: format detection, `read_recording` on every fixture (the `EXPECTED.md`
//! figures), writers by extension.

use evtac_events::{ImuSample, Resolution};
use evtac_formats::{
    Error, EventWriter, Format, RangeIndex, open, read_recording, read_recording_range,
};
use evtac_testkit::real_fixture;

use crate::common::synthetic_events;

#[test]
fn dvxplorer_fixture_has_every_expected_figure() {
    let Some(path) = real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let rec = read_recording(&path).unwrap();
    assert_eq!(rec.format, Format::Aedat4);
    assert_eq!(rec.source.as_deref(), Some("DVXplorer_DXB00010"));
    assert_eq!(rec.resolution, Some(Resolution::new(320, 240)));
    assert_eq!(rec.events.len(), 111_954);
    assert_eq!(rec.events[0].t, 1_605_537_493_718_345);
    assert_eq!(rec.events.last().unwrap().t, 1_605_537_494_308_262);
    let on = rec.events.iter().filter(|e| e.polarity).count();
    assert_eq!(on, 55_023);
    assert_eq!(
        on as f64 / rec.events.len() as f64,
        0.491_478_643_014_095_05
    );
    assert_eq!(rec.imu.len(), 475);
    // EXPECTED.md gives the first sample as dv-processing prints it (f32 widened to f64).
    let first = rec.imu[0];
    let widen = |v: [f32; 3]| v.map(f64::from);
    assert_eq!(first.t, 1_605_537_493_718_788);
    assert_eq!(
        widen(first.accelerometer),
        [0.1263427734375, -0.9951171875, -0.39306640625]
    );
    assert_eq!(
        widen(first.gyroscope),
        [0.4119872748851776, 0.0762939453125, -0.4119872748851776]
    );
    assert_eq!(f64::from(first.temperature), 38.15234375);
    assert_eq!(rec.imu.last().unwrap().t, 1_605_537_494_307_448);
    let span_s = (rec.imu.last().unwrap().t - rec.imu[0].t) as f64 * 1e-6;
    let rate = (rec.imu.len() - 1) as f64 / span_s;
    assert!((rate - 805.0).abs() < 5.0, "IMU rate {rate} Hz");
    assert!(rec.triggers.is_empty());
}

#[test]
fn prophesee_fixtures_through_the_whole_file_api() {
    let Some(evt2) = real_fixture("prophesee_gen3_640x480.evt2.raw") else {
        return;
    };
    let rec = read_recording(&evt2).unwrap();
    assert_eq!(rec.format, Format::Evt2);
    assert_eq!(rec.resolution, Some(Resolution::new(640, 480)));
    assert_eq!(rec.events.len(), 521_252);
    assert_eq!(rec.events[0].t, 913_716_224);
    assert_eq!(rec.events.last().unwrap().t, 913_812_095);
    let Some(evt3) = real_fixture("prophesee_gen4_1280x720.evt3.raw") else {
        return;
    };
    let mut reader = open(&evt3).unwrap();
    assert_eq!(reader.format(), Format::Evt3);
    assert_eq!(reader.source(), Some("hal_plugin_gen41_evk3 00000307"));
    let mut n = 0;
    while let Some(chunk) = reader.next_chunk().unwrap() {
        n += chunk.events.len();
    }
    assert_eq!(n, 219_596);
    assert_eq!(reader.position(), reader.file_len());
    // The plain iterator gives the same events.
    let iterated: Result<Vec<_>, _> = open(&evt3).unwrap().into_events().collect();
    assert_eq!(iterated.unwrap().len(), 219_596);
    // A declared resolution must agree with the one the header implies.
    let mut reader = open(&evt3).unwrap();
    assert!(matches!(
        reader.set_resolution(Resolution::new(640, 480)),
        Err(Error::ResolutionMismatch { .. })
    ));
}

#[test]
fn expected_npy_is_detected_and_read() {
    let Some(npy) = real_fixture("prophesee_gen4_1280x720.evt3.expected.npy") else {
        return;
    };
    let mut reader = open(&npy).unwrap();
    assert_eq!(reader.format(), Format::Npy);
    assert_eq!(reader.resolution(), None);
    reader.set_resolution(Resolution::new(1280, 720)).unwrap();
    let rec = reader.into_recording().unwrap();
    assert_eq!(rec.events.len(), 219_596);
    assert_eq!(rec.resolution, Some(Resolution::new(1280, 720)));
    let mut reader = open(&npy).unwrap();
    reader.set_resolution(Resolution::new(640, 480)).unwrap();
    let err = reader.into_recording().unwrap_err().to_string();
    assert!(err.contains("outside the 640x480 sensor"), "{err}");
}

#[test]
fn writers_by_extension_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let events = synthetic_events(5000, 320, 240);
    let imu = vec![ImuSample {
        t: 1_000_001,
        temperature: 30.5,
        ..ImuSample::default()
    }];
    for name in ["a.aedat4", "a.csv", "a.npy"] {
        let path = dir.path().join(name);
        let mut w =
            EventWriter::create(&path, Some(Resolution::new(320, 240)), Some("cam")).unwrap();
        w.write_events(&events[..1234]).unwrap();
        w.write_events(&events[1234..]).unwrap();
        w.write_imu(&imu).unwrap();
        let stores_imu = w.stores_imu();
        w.finish().unwrap();
        let rec = read_recording(&path).unwrap();
        assert_eq!(rec.events, events, "{name}");
        assert_eq!(rec.imu.len(), usize::from(stores_imu), "{name}");
        if stores_imu {
            assert_eq!(rec.imu, imu);
            assert_eq!(rec.source.as_deref(), Some("cam"));
            assert_eq!(rec.resolution, Some(Resolution::new(320, 240)));
        }
    }
}

#[test]
fn unknown_empty_and_unwritable_files_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.npy");
    std::fs::write(&empty, b"").unwrap();
    let err = open(&empty).unwrap_err().to_string();
    assert!(err.contains("empty.npy") && err.contains("empty"), "{err}");
    let junk = dir.path().join("junk.bin");
    std::fs::write(&junk, b"hello").unwrap();
    assert!(matches!(open(&junk), Err(Error::UnknownFormat { .. })));
    let missing = dir.path().join("missing.aedat4");
    assert!(matches!(open(&missing), Err(Error::Io { .. })));
    assert!(matches!(
        EventWriter::create(dir.path().join("x.raw"), None, None),
        Err(Error::NotWritable { .. })
    ));
    assert!(matches!(
        EventWriter::create(dir.path().join("x.aedat4"), None, None),
        Err(Error::MissingResolution { .. })
    ));
}

/// `recording` with only what lies in `[from, to)`.
fn cut(recording: &evtac_formats::Recording, from: i64, to: i64) -> evtac_formats::Recording {
    let inside = |t: i64| from <= t && t < to;
    evtac_formats::Recording {
        events: recording
            .events
            .iter()
            .copied()
            .filter(|e| inside(e.t))
            .collect(),
        imu: recording
            .imu
            .iter()
            .copied()
            .filter(|s| inside(s.t))
            .collect(),
        triggers: recording
            .triggers
            .iter()
            .copied()
            .filter(|t| inside(t.t))
            .collect(),
        ..recording.clone()
    }
}

#[test]
fn time_ranges_of_every_fixture_equal_the_filtered_whole() {
    for (name, indexed) in [
        ("dvxplorer_320x240_imu.aedat4", true),
        ("prophesee_gen3_640x480.evt2.raw", false),
    ] {
        let Some(path) = real_fixture(name) else {
            return;
        };
        let whole = read_recording(&path).unwrap();
        let (first, last) = (whole.events[0].t, whole.events.last().unwrap().t);
        let mid = first + (last - first) / 3;
        for (from, to) in [(mid, mid + 20_000), (i64::MIN, first + 1), (last, i64::MAX)] {
            let (part, how) = read_recording_range(&path, from, to).unwrap();
            assert_eq!(
                matches!(how, RangeIndex::DataTable { .. }),
                indexed,
                "{name}: {how:?}"
            );
            assert_eq!(how.fallback(), None, "{name}");
            assert!(part == cut(&whole, from, to), "{name}: [{from}, {to})");
            assert!(!part.events.is_empty(), "{name}: [{from}, {to})");
        }
    }
}

#[test]
fn empty_time_range_names_the_file() {
    let Some(path) = real_fixture("prophesee_gen3_640x480.evt2.raw") else {
        return;
    };
    let err = read_recording_range(&path, 10, 5).unwrap_err();
    assert!(
        matches!(
            err,
            Error::EmptyRange {
                from: 10,
                to: 5,
                ..
            }
        ),
        "{err}"
    );
    assert!(
        err.to_string().contains("prophesee_gen3_640x480.evt2.raw"),
        "{err}"
    );
}
