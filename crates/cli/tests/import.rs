//! Tests of `evtac import`: a one-trial session imported back into a dataset that `evtac check`
//! passes, bad logs failing with the log's line and column, writing nothing, and a simulated
//! session imported by each sync mode and reproduced.

use crate::common::{evtac, run_err, run_ok, simulate_session_tiny, simulate_tiny};
use evtac_events::manifest::Manifest;
use evtac_formats::read_recording;

#[test]
fn imports_a_session_and_refuses_bad_logs() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("sim");
    simulate_tiny("exp1", 2, &ds, 1);
    // The trial's own recording is a session of one motion; the log is on a clock 5 s behind.
    let t = &Manifest::read(&ds).unwrap().trials[0];
    let log = dir.path().join("log.csv");
    let write_log = |speed: f64| {
        let text = format!(
            "trial,direction_deg,speed_deg_s,depth_mm,total_deg,motion_start_us,motion_end_us\n\
             {},{},{speed},{},{},{},{}\n",
            t.trial,
            t.direction_deg,
            t.depth_mm,
            t.total_deg,
            t.motion_start_us - 5_000_000,
            t.motion_end_us - 5_000_000
        );
        std::fs::write(&log, text).unwrap();
    };
    write_log(t.speed_deg_s);
    let session = ds.join(&t.file);
    let out = dir.path().join("imported");
    let (session_s, log_s, out_s) = (
        session.to_str().unwrap(),
        log.to_str().unwrap(),
        out.to_str().unwrap(),
    );
    let no_contact = ds.join("no_contact.aedat4");
    let calibration = ds.join("calibration.json");
    let args = [
        "import",
        session_s,
        "--log",
        log_s,
        "--out",
        out_s,
        "--clock-offset-us",
        "5000000",
        "--no-contact",
        no_contact.to_str().unwrap(),
        "--calibration",
        calibration.to_str().unwrap(),
    ];
    let stdout = String::from_utf8(run_ok(&args).stdout).unwrap();
    assert!(stdout.starts_with("imported 1 trials ("), "{stdout}");
    let (a, b) = (
        read_recording(&session).unwrap(),
        read_recording(out.join(&t.file)).unwrap(),
    );
    assert!(
        a.events == b.events && a.imu == b.imu,
        "the trial changed on import"
    );
    assert_eq!(
        Manifest::read(&out).unwrap().trials[0].motion_start_us,
        t.motion_start_us
    );
    run_ok(&["check", out_s]);

    // With --filter, every written recording goes through the chain on its own: the trial and
    // the no-contact recording equal the same files filtered by `evtac filter`.
    let filtered = dir.path().join("filtered");
    let mut with_filter = args.to_vec();
    with_filter[5] = filtered.to_str().unwrap();
    with_filter.extend([
        "--filter",
        "background-activity=10ms",
        "--filter",
        "polarity=on",
    ]);
    let said = run_ok(&with_filter);
    // The imported trial (unfiltered, above) and the no-contact recording, filtered by hand.
    for (from, imported) in [
        (out.join(&t.file), filtered.join(&t.file)),
        (no_contact.clone(), filtered.join("no_contact.aedat4")),
    ] {
        let by_hand = dir.path().join("by-hand.aedat4");
        run_ok(&[
            "filter",
            from.to_str().unwrap(),
            by_hand.to_str().unwrap(),
            "--filter",
            "background-activity=10ms",
            "--filter",
            "polarity=on",
        ]);
        let source = read_recording(&from).unwrap();
        let (want, got) = (
            read_recording(&by_hand).unwrap(),
            read_recording(&imported).unwrap(),
        );
        assert_eq!(got.events, want.events, "{}", from.display());
        assert!(got.events.len() < source.events.len(), "{}", from.display());
        assert_eq!(got.imu, source.imu, "{}", from.display());
        std::fs::remove_file(by_hand).unwrap();
    }
    let stderr = String::from_utf8_lossy(&said.stderr);
    assert!(
        stderr.contains("background-activity=10ms: removed "),
        "{stderr}"
    );
    std::fs::remove_dir_all(&filtered).unwrap();

    // Writing over an existing folder, a negative speed, a missing column: errors, nothing new.
    let fails = |args: &[&str], want: &str| {
        let o = evtac().args(args).output().unwrap();
        assert!(!o.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(want), "{want}: {err}");
    };
    fails(&args, "exists already");
    let fresh = dir.path().join("fresh");
    let mut again = args;
    again[5] = fresh.to_str().unwrap();
    write_log(-2.0);
    fails(&again, "log.csv:2: column `speed_deg_s`");
    std::fs::write(&log, "trial,direction_deg\n").unwrap();
    fails(&again, "log.csv:1: column `speed_deg_s` is missing");
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["imported", "log.csv", "sim"]);
}

/// `evtac simulate --session` writes what `evtac import --sync trigger` and `--sync imu` read,
/// without an offset (giving one too is refused), and what an import without the log cuts by
/// the gyroscope; the imported dataset reproduces.
#[test]
fn a_simulated_session_imports_by_its_triggers_or_its_imu_and_reproduces() {
    let dir = tempfile::tempdir().unwrap();
    let session = dir.path().join("session");
    simulate_session_tiny("exp1", 4, &session, None);
    let data = dir.path().join("data");
    let out = data.join("exp1");
    let (file, log, no_contact, calibration) = (
        session.join("session.aedat4"),
        session.join("robot_log.csv"),
        session.join("no_contact.aedat4"),
        session.join("calibration.json"),
    );
    let mut args = vec![
        "import",
        file.to_str().unwrap(),
        "--log",
        log.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--sync",
        "trigger",
        "--no-contact",
        no_contact.to_str().unwrap(),
        "--calibration",
        calibration.to_str().unwrap(),
    ];
    let o = run_ok(&args);
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("imported 16 trials ("));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("clock offsets from the triggers: median "),
        "{err}"
    );
    run_ok(&["check", out.to_str().unwrap()]);
    // No trigger wiring: the gyroscope.
    let by_imu = dir.path().join("by-imu");
    let mut imu_args = args.clone();
    imu_args[5] = by_imu.to_str().unwrap();
    imu_args[7] = "imu";
    let err = String::from_utf8(run_ok(&imu_args).stderr).unwrap();
    assert!(err.contains("clock offset from the IMU: "), "{err}");
    run_ok(&["check", by_imu.to_str().unwrap()]);
    // No log at all: the motions are found in the gyroscope and listed for review.
    let log_free = dir.path().join("log-free");
    let mut free_args = vec![
        "import",
        file.to_str().unwrap(),
        "--out",
        log_free.to_str().unwrap(),
        "--no-contact",
        no_contact.to_str().unwrap(),
        "--calibration",
        calibration.to_str().unwrap(),
    ];
    let o = evtac().args(&free_args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("--depth-mm is needed"),
        "{err}"
    );
    free_args.extend(["--depth-mm", "1.5"]);
    let stdout = String::from_utf8(run_ok(&free_args).stdout).unwrap();
    assert!(
        stdout.starts_with("16 motions found in the gyroscope of "),
        "{stdout}"
    );
    assert!(stdout.contains("imported 16 trials ("), "{stdout}");
    let review = std::fs::read_to_string(log_free.join("motions.csv")).unwrap();
    assert_eq!(review.lines().count(), 17, "{review}");
    assert!(
        review.lines().nth(1).unwrap().starts_with("m0000,"),
        "{review}"
    );
    run_ok(&["check", log_free.to_str().unwrap()]);
    // The imported Experiment 1 dataset goes through the whole protocol (the end-to-end
    // path: simulate a session, import, check, label, reproduce).
    let report = dir.path().join("out");
    run_ok(&[
        "reproduce",
        "--scale",
        "tiny",
        "--data",
        data.to_str().unwrap(),
        "--out",
        report.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(
        text.contains("Calibration: calibration.json. No-contact mask: no_contact.aedat4."),
        "{text}"
    );
    // A recorded dataset has no camera frames: the sensor figure shows event counts, and says so.
    assert!(
        text.contains("(figures/sensor.png)") && text.contains("these are event-count images"),
        "{text}"
    );
    let again = dir.path().join("again");
    args[5] = again.to_str().unwrap();
    args.extend(["--clock-offset-us", "5"]);
    let o = evtac().args(&args).output().unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--clock-offset-us is for --sync offset"),
        "{err}"
    );
}

/// The trial names of the dataset in `dir`, in manifest order.
fn trial_names(dir: &std::path::Path) -> Vec<String> {
    let manifest = Manifest::read(dir).unwrap();
    manifest.trials.into_iter().map(|t| t.trial).collect()
}

/// Several sessions into one dataset (each with its log, or their motions found in the
/// gyroscope), and a folder of per-trial files (cut by a log on each file's clock, or each
/// file's motion found).
#[test]
fn several_sessions_and_a_folder_of_trials_import_into_one_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    for (name, seed) in [("a", 1), ("b", 2)] {
        simulate_session_tiny("exp1", seed, &dir.path().join(name), Some(2));
    }
    let (a, b) = (p("a/session.aedat4"), p("b/session.aedat4"));
    let calibration = p("a/calibration.json");
    // Both sessions name their trials t0000, t0001: refused, naming both logs' lines.
    let (log_a, log_b) = (p("a/robot_log.csv"), p("b/robot_log.csv"));
    let out = p("both");
    let mut args = vec![
        "import",
        &a,
        &b,
        "--log",
        &log_a,
        "--log",
        &log_b,
        "--sync",
        "trigger",
        "--out",
        &out,
        "--calibration",
        &calibration,
    ];
    let o = evtac().args(&args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("robot_log.csv:2: column `trial`: `t0000` is also "),
        "{err}"
    );
    assert!(err.contains("--trial-prefix"), "{err}");
    let prefixed = p("prefixed");
    let mut with_prefixes = args.clone();
    with_prefixes[10] = &prefixed;
    with_prefixes.extend(["--trial-prefix", "s0_", "--trial-prefix", "s1_"]);
    run_ok(&with_prefixes);
    assert_eq!(
        trial_names(&dir.path().join("prefixed")),
        ["s0_t0000", "s0_t0001", "s1_t0000", "s1_t0001"]
    );
    assert!(dir.path().join("prefixed/s1_t0001.aedat4").is_file());
    let renamed = p("b/renamed.csv");
    let text = std::fs::read_to_string(&log_b).unwrap();
    std::fs::write(&renamed, text.replace("\nt00", "\nu00")).unwrap();
    args[6] = &renamed;
    run_ok(&args);
    assert_eq!(
        trial_names(&dir.path().join("both")),
        ["t0000", "t0001", "u0000", "u0001"]
    );
    run_ok(&["check", &out, "--no-mask"]);
    // One log for two sessions is ambiguous.
    let o = evtac()
        .args(["import", &a, &b, "--log", &log_a, "--out", &p("one-log")])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&o.stderr).contains("2 sessions and 1 logs"));

    // Without logs: the motions of both, numbered on.
    let free = p("free");
    let stdout = String::from_utf8(
        run_ok(&[
            "import",
            &a,
            &b,
            "--out",
            &free,
            "--calibration",
            &calibration,
            "--depth-mm",
            "2",
        ])
        .stdout,
    )
    .unwrap();
    assert!(stdout.contains("imported 4 trials ("), "{stdout}");
    let review = std::fs::read_to_string(dir.path().join("free/motions.csv")).unwrap();
    let rows: Vec<&str> = review.lines().skip(1).collect();
    assert!(
        rows[2].starts_with("m0002,") && rows[2].contains("b/session.aedat4"),
        "{review}"
    );

    // A folder of per-trial files (a simulated dataset): by a log on each file's clock, the
    // trials come out as they went in; without a log, each file's motion is found and named
    // after it, and the no-contact recording is passed over.
    let trials = dir.path().join("trials");
    simulate_tiny("exp1", 5, &trials, 2);
    let manifest = Manifest::read(&trials).unwrap();
    let log = p("trials.csv");
    std::fs::write(&log, manifest.to_log_csv().unwrap()).unwrap();
    let (folder, by_log, cal) = (p("trials"), p("by-log"), p("trials/calibration.json"));
    run_ok(&[
        "import",
        &folder,
        "--log",
        &log,
        "--out",
        &by_log,
        "--calibration",
        &cal,
    ]);
    for t in &manifest.trials {
        let (x, y) = (
            read_recording(trials.join(&t.file)).unwrap(),
            read_recording(dir.path().join("by-log").join(&t.file)).unwrap(),
        );
        assert!(
            x.events == y.events && x.imu == y.imu,
            "{} changed",
            t.trial
        );
    }
    let found = p("found");
    let stdout = String::from_utf8(
        run_ok(&[
            "import",
            &folder,
            "--out",
            &found,
            "--calibration",
            &cal,
            "--depth-mm",
            "2",
        ])
        .stdout,
    )
    .unwrap();
    assert!(stdout.contains("no_contact.aedat4: no motion in its gyroscope, passed over"));
    let imported = Manifest::read(dir.path().join("found")).unwrap().trials;
    let names: Vec<&str> = imported.iter().map(|t| t.trial.as_str()).collect();
    assert_eq!(names, ["t0000", "t0001"]);
    for (i, t) in imported.iter().zip(&manifest.trials) {
        assert!(
            (i.motion_start_us - t.motion_start_us).abs() <= 20_000,
            "{i:?}"
        );
    }
}

/// `--no-contact-range` with units counts from the recording's first event; plain numbers are
/// on its clock, and a range there that holds nothing is an error, not an empty recording.
#[test]
fn a_no_contact_range_with_units_counts_from_the_recordings_start() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    simulate_session_tiny("exp1", 3, &dir.path().join("s"), Some(2));
    let start = read_recording(p("s/session.aedat4")).unwrap().events[0].t;
    let import = |out: &str, range: &str| {
        evtac()
            .args([
                "import",
                &p("s/session.aedat4"),
                "--log",
                &p("s/robot_log.csv"),
            ])
            .args([
                "--sync",
                "trigger",
                "--out",
                &p(out),
                "--no-contact-range",
                range,
            ])
            .args(["--calibration", &p("s/calibration.json")])
            .output()
            .unwrap()
    };
    for (out, range) in [("rel", "0s..2s"), ("rel_ms", "0ms..2000ms")] {
        let o = import(out, range);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let nc = read_recording(dir.path().join(out).join("no_contact.aedat4")).unwrap();
        assert!(!nc.events.is_empty());
        assert!(nc.events[0].t >= start && nc.events.last().unwrap().t < start + 2_000_000);
    }
    let absolute = format!("{}..{}", start, start + 2_000_000);
    let o = import("abs", &absolute);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a = read_recording(dir.path().join("abs/no_contact.aedat4")).unwrap();
    let r = read_recording(dir.path().join("rel/no_contact.aedat4")).unwrap();
    assert_eq!(a.events, r.events);
    for bad in ["0s..2000000", "2s..1s", "0..x"] {
        let o = import("bad", bad);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(bad), "{bad}: {err}");
    }
}

/// The NeuroTac lab's per-trial pickles (no IMU), as its collection script saves them, with the
/// robot's log on their clock: refused with the IMU's labels, imported with the commanded
/// motion's, which `check` accepts and which follow the simulator's true angles to within what
/// the simulated robot adds to its command.
#[test]
fn lab_pickles_import_with_labels_from_the_commanded_motion() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("sim");
    // Experiment 2: its stops are in the log, and the labels hold them.
    simulate_tiny("exp2", 5, &ds, 3);
    let lab = dir.path().join("lab");
    let script = include_str!("aedat_to_neurotac.py");
    let (ds_s, lab_s) = (ds.to_str().unwrap(), lab.to_str().unwrap());
    if evtac_testkit::run_python(script, &[ds_s, lab_s]).is_none() {
        return;
    }
    let log = lab.join("robot_log.csv");
    let no_contact = ds.join("no_contact.aedat4");
    let out = dir.path().join("data/exp2");
    let args = |labels: &'static str| {
        vec![
            "import".to_string(),
            lab_s.to_string(),
            "--log".into(),
            log.to_str().unwrap().into(),
            "--out".into(),
            out.to_str().unwrap().into(),
            "--no-contact".into(),
            no_contact.to_str().unwrap().into(),
            "--labels".into(),
            labels.into(),
        ]
    };
    let imu = args("imu");
    let err = run_err(&as_str(&imu));
    assert!(
        err.contains("no IMU samples") && err.contains("--labels commanded"),
        "{err}"
    );
    assert!(!out.exists(), "a failed import leaves nothing");

    let commanded = args("commanded");
    let stdout = String::from_utf8(run_ok(&as_str(&commanded)).stdout).unwrap();
    assert!(stdout.contains("imported 3 trials"), "{stdout}");
    assert!(stdout.contains("from the commanded motion"), "{stdout}");
    run_ok(&["check", out.to_str().unwrap()]);
    let stdout = String::from_utf8(run_ok(&["labels", out.to_str().unwrap()]).stdout).unwrap();
    assert!(stdout.contains("not the IMU: no stop check"), "{stdout}");

    // Each trial's labels against the simulator's truth, on the lab's clock (the pickles count
    // from the trial's first event: the log's times say by how much).
    let sim = Manifest::read(&ds).unwrap();
    let imported = Manifest::read(&out).unwrap();
    for (s, t) in sim.trials.iter().zip(&imported.trials) {
        assert_eq!(s.trial, t.trial);
        let shift = s.motion_start_us - t.motion_start_us;
        let truth =
            evtac_labels::LabelSeries::read_csv(ds.join(s.truth.as_ref().unwrap())).unwrap();
        let labels = evtac_labels::LabelSeries::read_csv(
            out.join("labels").join(format!("{}.csv", t.trial)),
        )
        .unwrap();
        let (mut sum, mut n) = (0.0, 0);
        for (k, &tt) in truth.t_us.iter().enumerate() {
            if tt < s.motion_start_us - 500_000 || tt > s.motion_end_us + 300_000 {
                continue;
            }
            let (pitch, roll) = labels.at(tt - shift);
            sum += (pitch - truth.pitch_deg[k]).powi(2) + (roll - truth.roll_deg[k]).powi(2);
            n += 2;
        }
        let rms = (sum / f64::from(n)).sqrt();
        // The simulated robot's deviations from its command (0.03-0.08 deg RMS per trial over
        // 16 Experiment 1 trials); a label on the wrong clock or axis is degrees off.
        assert!(rms < 0.15, "{}: {rms} deg RMS against the truth", t.trial);
        let stop = (t.stop_start_us.unwrap() + t.stop_end_us.unwrap()) / 2;
        assert!((labels.theta_at(stop) - t.stop_deg.unwrap()).abs() < 1e-9);
    }
}

/// `args` as the `&str`s `run_ok` and `run_err` take.
fn as_str(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}
