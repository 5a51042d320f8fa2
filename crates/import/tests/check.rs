//! `evtac check`'s library half: a simulated dataset passes, and each kind of damage gives its
//! row (file, line, field).

use crate::simulate;
use evtac_events::manifest::Manifest;
use evtac_formats::{EventWriter, read_recording};
use evtac_import::check::{CheckReport, check};
use evtac_import::inputs::Inputs;
use evtac_sim::Protocol;
use std::path::Path;

fn run(dir: &Path, inputs: Inputs) -> CheckReport {
    check(dir, &inputs, &|_| {})
}

/// Each problem as (file name, line, field, problem text).
fn rows(r: &CheckReport) -> Vec<(String, Option<usize>, String, String)> {
    r.problems
        .iter()
        .map(|p| {
            let name = p.file.file_name().unwrap().to_string_lossy().into_owned();
            (
                name,
                p.line,
                p.field.clone().unwrap_or_default(),
                p.problem.clone(),
            )
        })
        .collect()
}

/// Rewrites the recording `name` with its events and every `keep`-th IMU sample (none for 0).
fn rewrite_imu(dir: &Path, name: &str, keep: usize) {
    let path = dir.join(name);
    let rec = read_recording(&path).unwrap();
    let mut w = EventWriter::create(&path, rec.resolution, None).unwrap();
    w.write_events(&rec.events).unwrap();
    if keep > 0 {
        let imu: Vec<_> = rec.imu.iter().step_by(keep).copied().collect();
        w.write_imu(&imu).unwrap();
    }
    w.finish().unwrap();
}

#[test]
fn a_simulated_dataset_passes_and_each_damage_gives_its_row() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("exp3-speed");
    simulate(&ds, Protocol::Exp3Speed, 6);
    let clean = run(&ds, Inputs::FROM_FILES);
    assert_eq!(clean.problems, [], "a simulated dataset has no problems");
    assert_eq!(clean.datasets, [(ds.clone(), 6)]);
    assert_eq!(
        clean.recordings, 7,
        "six trials and the no-contact recording"
    );
    // The folder above is checked as `reproduce --data` reads it: exp3-speed/ is found, and
    // the Experiment 1 dataset it needs is missing.
    let above = run(dir.path(), Inputs::FROM_FILES);
    assert_eq!(
        above.datasets,
        [(dir.path().join("exp1"), 0), (ds.clone(), 6)]
    );
    assert_eq!(rows(&above).len(), 1);
    assert!(above.problems[0].file.ends_with("exp1/trials.csv"));

    let mut m = Manifest::read(&ds).unwrap();
    m.trials[0].speed_deg_s = -2.0; // line 2
    std::fs::remove_file(ds.join(&m.trials[1].file)).unwrap(); // line 3
    m.trials[2].motion_start_us += 60_000_000; // line 4: the window is after the recording
    m.trials[2].motion_end_us += 60_000_000;
    m.trials[3].stop_deg = Some(5.0); // line 5: a stop without its times
    m.trials[4].group = Some("maybe".into()); // line 6
    m.write(&ds).unwrap();
    rewrite_imu(&ds, &m.trials[5].file.display().to_string(), 0); // line 7: no IMU
    std::fs::remove_file(ds.join("calibration.json")).unwrap();
    std::fs::remove_file(ds.join("no_contact.aedat4")).unwrap();

    let damaged = run(&ds, Inputs::FROM_FILES);
    let found = rows(&damaged);
    let keys: Vec<(&str, Option<usize>, &str)> = found
        .iter()
        .map(|(f, l, field, _)| (f.as_str(), *l, field.as_str()))
        .collect();
    assert_eq!(
        keys,
        [
            ("calibration.json", None, ""),
            ("no_contact.aedat4", None, ""),
            ("trials.csv", Some(2), "speed_deg_s"),
            ("t0001.aedat4", Some(3), "file"),
            ("t0002.aedat4", Some(4), "motion_end_us"),
            ("t0002.aedat4", Some(4), "motion_end_us"),
            ("trials.csv", Some(5), "stop_start_us"),
            ("trials.csv", Some(5), "stop_end_us"),
            ("trials.csv", Some(6), "group"),
            ("t0005.aedat4", Some(7), "file"),
        ],
        "{found:#?}"
    );
    let text = |i: usize| found[i].3.as_str();
    assert_eq!(text(3), "missing");
    assert!(text(4).contains("events span") && text(4).contains("does not cover"));
    assert!(text(5).contains("IMU samples span"));
    assert!(text(9).contains("no IMU samples"));
    for p in &damaged.problems {
        assert!(!p.fix.is_empty(), "{p:?} has no fix");
    }
    assert!(damaged.problems[0].fix.contains("--identity-calibration"));
    assert!(damaged.problems[1].fix.contains("--no-mask"));

    // The opt-outs silence the two missing files and nothing else.
    let opted = run(&ds, Inputs::from_flags(true, true));
    assert_eq!(rows(&opted)[..], found[2..]);
}

#[test]
fn a_slow_imu_a_broken_file_a_bad_header_and_a_data_folder() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("exp1");
    simulate(&ds, Protocol::Exp1, 2);
    // 800 Hz / 8 = 100 Hz: too few samples for the labels' 100 ms still segment.
    rewrite_imu(&ds, "t0000.aedat4", 8);
    let path = ds.join("t0001.aedat4");
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    // The data folder is checked as `reproduce --data` reads it: its exp1/.
    let r = run(dir.path(), Inputs::FROM_FILES);
    assert_eq!(r.datasets, [(ds.clone(), 2)]);
    let found = rows(&r);
    assert_eq!(found.len(), 2, "{found:#?}");
    assert_eq!((found[0].0.as_str(), found[0].1), ("t0000.aedat4", Some(2)));
    assert!(found[0].3.contains("IMU at 100.0 Hz"), "{}", found[0].3);
    assert_eq!((found[1].0.as_str(), found[1].1), ("t0001.aedat4", Some(3)));
    assert!(found[1].3.starts_with("unreadable"), "{}", found[1].3);

    let manifest = ds.join("trials.csv");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let broken = text.replacen("depth_mm", "depth", 1);
    std::fs::write(&manifest, broken).unwrap();
    let found = rows(&run(&ds, Inputs::FROM_FILES));
    let header: Vec<_> = found.iter().filter(|r| r.2 == "header").collect();
    assert_eq!(header.len(), 1, "{found:#?}");
    assert_eq!(
        header[0].3, "missing columns depth_mm; unknown columns depth",
        "{found:#?}"
    );
}
