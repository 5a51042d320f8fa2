//! The session folder: deterministic, one recording holding the dataset's trials with idle time
//! between them and a trigger at each onset, and a log on the robot's clock.

use crate::{config, three_runs};
use evtac_events::Event;
use evtac_formats::read_recording;
use evtac_sim::{
    DatasetConfig, Protocol, Scale, SessionConfig, simulate_dataset, simulate_session,
};

/// The first `limit` trials of a tiny session, tilting to 10 degrees to keep the test fast.
fn session(seed: u64, limit: usize) -> SessionConfig {
    SessionConfig {
        dataset: config(Protocol::Exp2, seed, limit),
        ..SessionConfig::new(Protocol::Exp2, Scale::Tiny, seed)
    }
}

#[test]
fn same_seed_same_bytes_whatever_the_threads() {
    let offsets = std::sync::Mutex::new(Vec::new());
    let [fa, fb, fc] = three_runs(5, |seed, dir| {
        let record = simulate_session(&session(seed, 3), dir, |_| {}).unwrap();
        offsets.lock().unwrap().push(record.clock_offset_us);
    });
    let names: Vec<&str> = fa.iter().map(|f| f.0.as_str()).collect();
    assert_eq!(
        names,
        [
            "calibration.json",
            "no_contact.aedat4",
            "robot_log.csv",
            "session.aedat4",
            "session.json",
            "truth/t0000.csv",
            "truth/t0001.csv",
            "truth/t0002.csv"
        ]
    );
    assert!(fa == fb, "same seed gave different bytes");
    assert_ne!(fa[2], fc[2], "another seed gave the same log");
    let offsets = offsets.into_inner().unwrap();
    assert!(
        offsets[0] == offsets[1] && offsets[0] != offsets[2],
        "{offsets:?}"
    );
}

#[test]
fn the_session_holds_the_dataset_s_trials_with_triggers_and_a_log_on_the_robot_s_clock() {
    let dir = tempfile::tempdir().unwrap();
    let (session_dir, dataset_dir) = (dir.path().join("s"), dir.path().join("d"));
    let config = session(7, 3);
    let record = simulate_session(&config, &session_dir, |_| {}).unwrap();
    let dataset = DatasetConfig {
        limit: config.dataset.limit,
        ..config.dataset.clone()
    };
    let manifest = simulate_dataset(&dataset, &dataset_dir, |_| {}).unwrap();
    let session = read_recording(session_dir.join("session.aedat4")).unwrap();

    // One IMU at one rate across the session (its stamps jitter by 20 us and shift by each
    // stretch's clock offset, a few hundred us), and events in order.
    let steps: Vec<i64> = session.imu.windows(2).map(|w| w[1].t - w[0].t).collect();
    assert!(steps.iter().all(|&d| d > 0 && (d - 1250).abs() < 5_000));
    let on_rate = steps.iter().filter(|&&d| (d - 1250).abs() <= 200).count();
    assert!(
        on_rate * 100 >= steps.len() * 99,
        "{on_rate} of {}",
        steps.len()
    );
    assert!((session.imu[0].t - config.start_us).abs() < 5_000);
    assert!(session.events.windows(2).all(|w| w[0].t <= w[1].t));
    // A trigger at every onset.
    let onsets: Vec<i64> = record.trials.iter().map(|t| t.motion_start_us).collect();
    let triggers: Vec<i64> = session.triggers.iter().map(|t| t.t).collect();
    assert_eq!(triggers, onsets);
    assert!(session.triggers.iter().all(|t| t.kind == 1));

    let log = std::fs::read_to_string(session_dir.join("robot_log.csv")).unwrap();
    let mut lines = log.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert!(
        !header.contains(&"file") && !header.contains(&"truth"),
        "{header:?}"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let cell = |row: &[&str], column: &str| -> i64 {
        let i = header.iter().position(|c| *c == column).unwrap();
        row[i].parse().unwrap()
    };
    assert_eq!(rows.len(), record.trials.len());
    for ((truth, row), trial) in record.trials.iter().zip(&rows).zip(&manifest.trials) {
        // The same trial as the dataset's, moved to where it lies in the session.
        let shift = truth.motion_start_us - trial.motion_start_us;
        assert!(shift >= config.start_us + 1_000_000, "{shift}");
        assert_eq!(truth.motion_end_us - shift, trial.motion_end_us);
        assert_eq!(truth.stop_deg, trial.stop_deg);
        let own = read_recording(dataset_dir.join(&trial.file)).unwrap();
        let start = own.events.first().unwrap().t + shift;
        let end = own.events.last().unwrap().t + shift;
        let inside: Vec<Event> = session
            .events
            .iter()
            .filter(|e| (start..=end).contains(&e.t))
            .map(|e| Event {
                t: e.t - shift,
                ..*e
            })
            .collect();
        assert!(inside == own.events, "{}: events differ", trial.trial);
        // The log: the robot's clock, each time off by at most the jitter.
        assert_eq!(row[0], truth.trial);
        let pairs = [
            (cell(row, "motion_start_us"), truth.motion_start_us),
            (cell(row, "motion_end_us"), truth.motion_end_us),
            (cell(row, "stop_start_us"), truth.stop_start_us.unwrap()),
            (cell(row, "stop_end_us"), truth.stop_end_us.unwrap()),
        ];
        for (logged, happened) in pairs {
            let error = logged + record.clock_offset_us - happened;
            assert!(error.abs() <= config.jitter_us, "{}: {error}", truth.trial);
        }
        // The truth on the session's clock.
        let text =
            std::fs::read_to_string(session_dir.join(truth.truth.as_ref().unwrap())).unwrap();
        let first = text.lines().nth(1).unwrap();
        assert!(first.starts_with(&format!("{shift},0.000000,")), "{first}");
    }
    assert!(record.clock_offset_us.abs() <= config.max_clock_offset_us);
    assert_eq!(
        std::fs::read(session_dir.join("no_contact.aedat4")).unwrap(),
        std::fs::read(dataset_dir.join("no_contact.aedat4")).unwrap()
    );
}
