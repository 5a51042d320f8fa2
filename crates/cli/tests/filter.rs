//! Tests of `evtac filter`: the command applies the chain the library builds (whose filters are
//! tested against dv-processing in `crates/filters`), keeps the IMU and triggers, says what each
//! filter removed, and writes nothing for a SPEC that cannot run.

use std::path::Path;

use crate::common::{run_err, run_ok};
use evtac_filters::{Chain, Filter, FilterSpec};
use evtac_formats::read_recording;
use evtac_testkit::real_fixture;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn a_chain_on_the_real_recording_is_the_librarys_and_keeps_imu_and_triggers() {
    let Some(src) = real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("clean.aedat4");
    let specs = ["background-activity=10ms", "region=40,0,240,240"];
    let run = run_ok(&[
        "filter",
        s(&src),
        s(&out),
        "--filter",
        specs[0],
        "--filter",
        specs[1],
    ]);
    let said = String::from_utf8_lossy(&run.stderr);
    let original = read_recording(&src).unwrap();
    let filtered = read_recording(&out).unwrap();
    // The same chain over the whole recording at once: chunking does not change the output.
    let parsed: Vec<FilterSpec> = specs.iter().map(|s| s.parse().unwrap()).collect();
    let mut chain = Chain::build(&parsed, original.resolution.unwrap()).unwrap();
    let mut expected = Vec::new();
    chain.retain(&original.events, &mut expected);
    assert_eq!(filtered.events, expected);
    assert!(!expected.is_empty() && expected.len() < original.events.len());
    assert_eq!(filtered.imu, original.imu);
    assert_eq!(filtered.triggers, original.triggers);
    assert_eq!(filtered.resolution, original.resolution);
    for (f, spec) in chain.filters().iter().zip(specs) {
        let line = format!("{spec}: removed {} events", f.removed());
        assert!(said.contains(&line), "{said:?} does not say {line:?}");
    }
    assert!(said.contains(&format!(
        "wrote {} of {} events",
        expected.len(),
        original.events.len()
    )));
}

#[test]
fn a_bad_spec_is_named_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    std::fs::write(&input, "t,x,y,p\n0,1,1,1\n10,2,2,0\n").unwrap();
    let out = dir.path().join("out.csv");
    for (spec, says) in [
        ("speckle=3ms", "speckle"),
        ("background-activity=0ms", "background-activity=0ms"),
        ("background-activity=-5ms", "background-activity=-5ms"),
    ] {
        let err = run_err(&[
            "filter",
            s(&input),
            s(&out),
            "--sensor",
            "32x32",
            "--filter",
            spec,
        ]);
        assert!(err.contains(says), "{spec}: {err}");
        assert!(!out.exists(), "{spec} wrote {}", out.display());
    }
    // A region outside the sensor is found when the chain is built for it: still nothing written.
    let err = run_err(&[
        "filter",
        s(&input),
        s(&out),
        "--sensor",
        "32x32",
        "--filter",
        "region=30,30,8,8",
    ]);
    assert!(err.contains("region=30,30,8,8"), "{err}");
    assert!(!out.exists());
    // The input is never the output.
    let err = run_err(&[
        "filter",
        s(&input),
        s(&input),
        "--sensor",
        "32x32",
        "--filter",
        "polarity=on",
    ]);
    assert!(err.contains("in.csv"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&input).unwrap(),
        "t,x,y,p\n0,1,1,1\n10,2,2,0\n"
    );
}
