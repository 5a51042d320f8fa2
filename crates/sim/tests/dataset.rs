//! The dataset folder: complete, deterministic, and readable by dv-processing.

use std::path::Path;

use crate::{config, three_runs};
use evtac_events::manifest::Manifest;
use evtac_formats::aedat::AedatReader;
use evtac_labels::geometry::{Calibration, axial_rate};
use evtac_sim::{Protocol, simulate_dataset};

#[test]
fn same_seed_same_bytes_different_seed_different_bytes() {
    let done = std::sync::atomic::AtomicUsize::new(0);
    let manifest = std::sync::Mutex::new(None);
    let [fa, fb, fc] = three_runs(5, |seed, dir| {
        let m = simulate_dataset(&config(Protocol::Exp2, seed, 2), dir, |_| {
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
        manifest.lock().unwrap().get_or_insert(m);
    });
    assert_eq!(done.into_inner(), 6);
    let names: Vec<&str> = fa.iter().map(|f| f.0.as_str()).collect();
    assert_eq!(
        names,
        [
            "calibration.json",
            "no_contact.aedat4",
            "simulator.json",
            "t0000.aedat4",
            "t0001.aedat4",
            "trials.csv",
            "truth/t0000.csv",
            "truth/t0001.csv"
        ]
    );
    assert!(fa == fb, "same seed gave different bytes");
    let get =
        |f: &[(String, Vec<u8>)], name: &str| f.iter().find(|x| x.0 == name).unwrap().1.clone();
    let differs = |name: &str| get(&fa, name) != get(&fc, name);
    assert!(differs("t0000.aedat4") && differs("no_contact.aedat4") && differs("trials.csv"));

    // The manifest on disk is the one returned, with the stop columns filled in.
    let manifest = manifest.into_inner().unwrap().unwrap();
    let text = String::from_utf8(get(&fa, "trials.csv")).unwrap();
    assert_eq!(
        Manifest::parse(&text, Path::new("trials.csv")).unwrap(),
        manifest
    );
    for t in &manifest.trials {
        let (s0, s1) = (t.stop_start_us.unwrap(), t.stop_end_us.unwrap());
        assert!(t.motion_start_us < s0 && s1 - s0 == 500_000 && s1 < t.motion_end_us);
        assert_eq!(t.total_deg, 10.0);
        let truth = get(&fa, t.truth.as_ref().unwrap().to_str().unwrap());
        let truth = String::from_utf8(truth).unwrap();
        assert!(truth.starts_with("t_us,theta_deg,pitch_deg,roll_deg\n0,0.000000,"));
    }
    let cal: Calibration = serde_json::from_slice(&get(&fa, "calibration.json")).unwrap();
    assert_ne!(
        cal,
        Calibration::default(),
        "the IMU must be mounted off-axis"
    );
}

/// Reads `path` with our AEDAT4 reader: (events, IMU samples).
fn read(path: &Path) -> (Vec<evtac_events::Event>, Vec<evtac_events::ImuSample>) {
    let bytes = std::fs::read(path).unwrap();
    let mut reader = AedatReader::from_slice(&bytes).unwrap();
    assert_eq!(
        reader.resolution(),
        Some(evtac_events::Resolution::new(640, 480))
    );
    let (mut events, mut imu) = (Vec::new(), Vec::new());
    while let Some(chunk) = reader.next_chunk().unwrap() {
        events.extend_from_slice(chunk.events);
        imu.extend_from_slice(chunk.imu);
    }
    (events, imu)
}

#[test]
fn dv_processing_reads_every_file_and_the_gyro_integrates_to_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = simulate_dataset(&config(Protocol::Exp1, 11, 2), dir.path(), |_| {}).unwrap();
    let cal: Calibration =
        serde_json::from_slice(&std::fs::read(dir.path().join("calibration.json")).unwrap())
            .unwrap();

    let mut paths = vec![dir.path().join("no_contact.aedat4")];
    for t in &manifest.trials {
        let path = dir.path().join(&t.file);
        let (events, imu) = read(&path);
        assert!(!events.is_empty());
        paths.push(path);

        // Remove the bias seen at rest, integrate the rate about the rolling axis and compare
        // with the truth at every truth sample (within the gyroscope's 1 % scale error).
        let rest: Vec<_> = imu.iter().filter(|s| s.t < t.motion_start_us).collect();
        let bias: [f64; 3] = std::array::from_fn(|i| {
            rest.iter().map(|s| f64::from(s.gyroscope[i])).sum::<f64>() / rest.len() as f64
        });
        let truth = std::fs::read_to_string(dir.path().join(t.truth.as_ref().unwrap())).unwrap();
        let truth: Vec<(i64, f64)> = truth
            .lines()
            .skip(1)
            .map(|l| {
                let mut c = l.split(',');
                let t: i64 = c.next().unwrap().parse().unwrap();
                (t, c.next().unwrap().parse().unwrap())
            })
            .collect();
        let (mut theta, mut k, mut worst) = (0.0, 0, 0f64);
        for w in imu.windows(2) {
            let omega: [f64; 3] = std::array::from_fn(|i| f64::from(w[0].gyroscope[i]) - bias[i]);
            theta += axial_rate(cal.imu_to_sensor(omega), t.direction_deg)
                * (w[1].t - w[0].t) as f64
                * 1e-6;
            while k < truth.len() && truth[k].0 <= w[1].t {
                worst = worst.max((truth[k].1 - theta).abs());
                k += 1;
            }
        }
        assert!(
            worst < 0.8,
            "{}: integrated gyro off by {worst} deg",
            t.trial
        );
    }

    let script = r#"
import sys
import dv_processing as dv
for path in sys.argv[1:]:
    rec = dv.io.MonoCameraRecording(path)
    assert rec.isEventStreamAvailable() and rec.isImuStreamAvailable()
    res = rec.getEventResolution()
    events = imu = 0
    last = -1
    while True:
        batch = rec.getNextEventBatch()
        if batch is None:
            break
        if batch.size() > 0:
            assert batch.getLowestTime() >= last
            last = batch.getHighestTime()
        events += batch.size()
    while True:
        batch = rec.getNextImuBatch()
        if batch is None:
            break
        imu += len(batch)
    print(res[0], res[1], events, imu)
"#;
    let args: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let Some(out) = evtac_testkit::run_python(script, &args) else {
        return;
    };
    for (line, path) in out.lines().zip(&paths) {
        let (events, imu) = read(path);
        assert_eq!(
            line,
            format!("640 480 {} {}", events.len(), imu.len()),
            "{}",
            path.display()
        );
    }
    assert_eq!(out.lines().count(), paths.len());
}
