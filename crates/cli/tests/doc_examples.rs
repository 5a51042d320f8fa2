//! Every `evtac` command in the shell examples of the README and the pages of `docs/` listed in
//! [`DOCS`], run as written,
//! so that an example that drifts from the tool fails the build.
//!
//! Each fenced `sh` block runs in a folder of its own, holding a copy of what its document's setup
//! made once: the files the prose assumes (a recording, a session and its log, a trained model): real
//! fixtures from `../shared`, and simulated data. The commands run through `bash` in block
//! order with the `evtac` under test first on the `PATH`; lines that are not `evtac` commands
//! (`sbatch`, `cargo ...`) are not run. Two changes are made, both printed: `--scale small` and
//! `--scale paper` become `--scale tiny` (the pipeline is the same; CI has minutes, not hours),
//! and a few commands are skipped with the reason (a live camera, a Slurm cluster, a job
//! array's task id), each run elsewhere by a test of its own. A command that needs a system
//! tool ([`NEEDS`]: ffmpeg for MP4) follows the testkit's one rule for external tools: where
//! the tool is missing it is skipped with the reason outside CI and fails under CI, so the
//! README's test command passes on a fresh machine with nothing installed by hand.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::run_ok;
use evtac_testkit::{ffmpeg, real_fixture, run_python, workspace_root};

/// Commands not run here, by a piece of their text, with why.
const SKIP: &[(&str, &str)] = &[
    (
        "--input tcp://",
        "a live DV network stream (tests/online.rs serves one on loopback)",
    ),
    (
        "--input ros2://",
        "a ROS 2 camera driver's topic (tests/online.rs and the online crate's tests/ros2.rs \
         publish one on loopback)",
    ),
    (
        "--executor slurm",
        "a Slurm cluster (tests/slurm.rs runs reproduce on a local slurmctld/slurmd)",
    ),
    (
        "SLURM_ARRAY_TASK_ID",
        "inside a Slurm job array (tests/jobs.rs runs exported jobs)",
    ),
    (
        "/shared/",
        "a cluster's shared folder (docs/cluster.md's setting)",
    ),
];

/// The testkit's check for a system tool: `false` outside CI when missing, having said so; a
/// failure under CI.
type ToolCheck = fn() -> bool;

/// Commands that need a system tool, by a piece of their text: the tool, and its check.
const NEEDS: &[(&str, &str, ToolCheck)] = &[(".mp4", "ffmpeg", ffmpeg)];

/// Why `command` cannot run on this machine: a tool in [`NEEDS`] that is missing.
fn missing_tool(command: &str) -> Option<&'static str> {
    NEEDS
        .iter()
        .find(|(text, _, available)| command.contains(text) && !available())
        .map(|(_, tool, _)| *tool)
}

/// One shell command of a block: its text (continuation lines included) and its line.
#[derive(Debug)]
struct Example {
    line: usize,
    text: String,
}

/// The `sh`/`bash` blocks of `markdown`, each as its commands.
fn blocks(markdown: &str) -> Vec<Vec<Example>> {
    let mut out = Vec::new();
    let mut current: Option<Vec<Example>> = None;
    let mut continued = false;
    for (i, line) in markdown.lines().enumerate() {
        let fence = line.trim_start().starts_with("```");
        match (&mut current, fence) {
            (None, true) => {
                let lang = line.trim_start().trim_start_matches('`').trim();
                if lang == "sh" || lang == "bash" {
                    current = Some(Vec::new());
                }
            }
            (Some(_), true) => out.push(current.take().unwrap_or_default()),
            (Some(commands), false) => {
                let code = strip_comment(line);
                if continued {
                    if let Some(last) = commands.last_mut() {
                        last.text.push('\n');
                        last.text.push_str(line);
                    }
                } else if !code.trim().is_empty() {
                    commands.push(Example {
                        line: i + 1,
                        text: line.to_string(),
                    });
                }
                continued = code.trim_end().ends_with('\\');
            }
            (None, false) => {}
        }
    }
    out
}

/// `line` without a trailing `# comment` (a `#` starting a word, outside quotes).
fn strip_comment(line: &str) -> &str {
    let mut quote = None;
    let mut previous = ' ';
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '#') if previous.is_whitespace() => return &line[..i],
            _ => {}
        }
        previous = c;
    }
    line
}

/// Whether a command runs `evtac` (first, or after a pipe).
fn runs_evtac(text: &str) -> bool {
    let code = strip_comment(text.lines().next().unwrap_or_default()).trim();
    code.starts_with("evtac ") || code.contains("| evtac ")
}

/// The command as run: `--scale small|paper` at the tiny scale.
fn as_run(text: &str) -> String {
    text.replace("--scale small", "--scale tiny")
        .replace("--scale paper", "--scale tiny")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// A simulated session (two motions of Experiment 1, tiny scale) in `dir`.
fn session(dir: &Path, seed: u64) {
    crate::common::simulate_session_tiny("exp1", seed, dir, Some(2));
}

/// The README's setup: the recordings its examples name.
fn readme_setup(dir: &Path) -> Option<()> {
    let aedat = real_fixture("dvxplorer_320x240_imu.aedat4")?;
    for name in ["recording.aedat4", "in.aedat4", "session.aedat4"] {
        std::fs::copy(&aedat, dir.join(name)).ok()?;
    }
    std::fs::copy(
        real_fixture("prophesee_gen3_640x480.evt2.raw")?,
        dir.join("recording.raw"),
    )
    .ok()?;
    run_python(crate::legacy_formats::PY_WRITE, &[s(dir)])?;
    std::fs::rename(dir.join("a2.aedat"), dir.join("neurotac_davis240.aedat")).ok()?;
    run_python(
        crate::data_loss::PY_STEREO,
        &[s(dir), "DVXplorer_DXA00092", "DVXplorer_DXA00093"],
    )?;
    for (k, seed) in [(0, 11), (1, 12)] {
        let sim = dir.join(format!("sim-s{k}"));
        session(&sim, seed);
        std::fs::copy(sim.join("session.aedat4"), dir.join(format!("s{k}.aedat4"))).ok()?;
        std::fs::copy(sim.join("robot_log.csv"), dir.join(format!("s{k}.csv"))).ok()?;
    }
    std::fs::create_dir_all(dir.join("docs/img")).ok()
}

/// docs/real-data.md's setup: a session with its log, no-contact recording and calibration, one
/// trial in each of the lab's and other tools' formats, ROS bags, the session as a ROS bag, and
/// a folder of four trials as the lab's pickles with their log.
fn real_data_setup(dir: &Path) -> Option<()> {
    let sim = dir.join("sim-session");
    // Every motion of the tiny Experiment 1: the walkthrough ends in a reproduction, which
    // splits the trials into training, validation and test.
    crate::common::simulate_session_tiny("exp1", 21, &sim, None);
    for name in [
        "session.aedat4",
        "robot_log.csv",
        "no_contact.aedat4",
        "calibration.json",
    ] {
        std::fs::copy(sim.join(name), dir.join(name)).ok()?;
    }
    // The NeuroTac lab's pickles of one trial, as its collection script writes them.
    evtac_testkit::run_python(
        "import pickle, sys, numpy as np\n\
         for pol, n in (('on', 3), ('off', 2)):\n\
         \x20   a = np.empty((480, 640), dtype=object)\n\
         \x20   for i in range(a.size): a.flat[i] = [i % 997 + k * 0.25 for k in range(n)] if i % 13 == 0 else []\n\
         \x20   pickle.dump(a, open(sys.argv[1] + f'/trial_07_events_{pol}.pickle', 'wb'))",
        &[s(dir)],
    )?;
    // The same trial as the other tools write it: event_utils' HDF5, DSEC's, dv-processing's
    // NPY, an NPZ of one array per field, and a CSV without a header line.
    evtac_testkit::run_python(
        "import sys, os, numpy as np, h5py\n\
         d = sys.argv[1]; rng = np.random.default_rng(7); n = 5000\n\
         t = np.sort(rng.integers(1_700_000_000_000_000, 1_700_000_002_000_000, n))\n\
         x, y, p = rng.integers(0, 640, n), rng.integers(0, 480, n), rng.integers(0, 2, n)\n\
         with h5py.File(d + '/trial_07.h5', 'w') as f:\n\
         \x20   f['events/xs'] = x.astype('i2'); f['events/ys'] = y.astype('i2')\n\
         \x20   f['events/ts'] = t / 1e6; f['events/ps'] = p.astype(bool)\n\
         \x20   f.attrs['sensor_resolution'] = (480, 640); f.attrs['num_events'] = n\n\
         with h5py.File(d + '/dsec_events.h5', 'w') as f:\n\
         \x20   f['events/x'] = x.astype('u2'); f['events/y'] = y.astype('u2')\n\
         \x20   f['events/t'] = (t - t[0]).astype('u4'); f['events/p'] = p.astype('u1')\n\
         \x20   f['t_offset'] = np.int64(t[0])\n\
         a = np.zeros(n, dtype=[('timestamp', '<i8'), ('x', '<i2'), ('y', '<i2'), ('polarity', 'i1')])\n\
         a['timestamp'], a['x'], a['y'], a['polarity'] = t, x, y, p\n\
         np.save(d + '/events.npy', a)\n\
         np.savez(d + '/trial.npz', t=t, x=x, y=y, p=p)\n\
         np.savetxt(d + '/events.csv', np.stack([t, x, y, p], 1), fmt='%d', delimiter=',')",
        &[s(dir)],
    )?;
    // ROS bags, written by the `rosbags` package as the bag readers' tests write them.
    let bags = Path::new(env!("CARGO_MANIFEST_DIR")).join("../events/tests/formats/ros_bags.py");
    let script = std::fs::read_to_string(bags).ok()?;
    evtac_testkit::run_python(&script, &[s(dir)])?;
    // The session as the rpg_dvs_ros driver would have recorded it: "From ROS" imports it.
    let to_bag = include_str!("aedat_to_bag.py");
    let (session, bag) = (dir.join("session.aedat4"), dir.join("session.bag"));
    evtac_testkit::run_python(to_bag, &[s(&session), s(&bag)])?;
    // Four trials as the lab's collection script saves them, with their log, in `lab/`:
    // "From the NeuroTac lab's collection scripts" imports them.
    let trials = dir.join("sim-trials");
    crate::common::simulate_tiny("exp1", 22, &trials, 4);
    let to_lab = include_str!("aedat_to_neurotac.py");
    evtac_testkit::run_python(to_lab, &[s(&trials), s(&dir.join("lab"))])?;
    Some(())
}

/// docs/online.md's setup: a static and a combined model (the frames example), a trial, and
/// its events as CSV.
fn online_setup(dir: &Path) -> Option<()> {
    let data = dir.join("sim");
    crate::common::simulate_tiny("exp1", 31, &data, 4);
    for repr in ["static", "combined"] {
        run_ok(&[
            "train",
            s(&data),
            "--repr",
            repr,
            "--epochs",
            "2",
            "--out",
            s(&dir.join("runs").join(repr)),
        ]);
    }
    let trial = dir.join("trial.aedat4");
    std::fs::copy(data.join("t0000.aedat4"), &trial).ok()?;
    run_ok(&["convert", s(&trial), s(&dir.join("events.csv"))]);
    Some(())
}

fn no_setup(_: &Path) -> Option<()> {
    Some(())
}

/// Before a command containing the first text, runs the second (what the prose says the
/// reader has made by then).
const BEFORE: &[(&str, &str)] = &[(
    "--samples times.txt",
    r#"t0=$(evtac info data/exp1/t0000.aedat4 --json | sed -n 's/.*"first_t_us": \([0-9]*\).*/\1/p' | head -1)
for i in $(seq 1 20); do echo $((t0 + i * 50000)); done > times.txt"#,
)];

type Setup = fn(&Path) -> Option<()>;

/// The documents and their setups.
const DOCS: &[(&str, Setup)] = &[
    ("README.md", readme_setup),
    // The full command tour moved out of the README; it uses the README's files.
    ("docs/guide.md", readme_setup),
    ("docs/real-data.md", real_data_setup),
    ("docs/online.md", online_setup),
    ("docs/cluster.md", no_setup),
    ("docs/simulator.md", no_setup),
];

/// Runs `text` with bash in `dir`, the tested `evtac` first on the PATH.
fn run_bash(dir: &Path, text: &str) -> std::process::Output {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_evtac"));
    let path = format!(
        "{}:{}",
        bin.parent().expect("the binary's folder").display(),
        std::env::var("PATH").unwrap_or_default()
    );
    Command::new("bash")
        .args(["-c", &format!("set -eo pipefail\n{text}")])
        .current_dir(dir)
        .env("PATH", path)
        .output()
        .expect("bash runs")
}

/// Copies the files and folders under `from` into `to` (which exists).
fn copy_tree(from: &Path, to: &Path) {
    for entry in std::fs::read_dir(from).expect("the set-up folder") {
        let entry = entry.expect("an entry");
        let target = to.join(entry.file_name());
        if entry.file_type().expect("a type").is_dir() {
            std::fs::create_dir(&target).expect("a folder");
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).expect("a copy");
        }
    }
}

fn say(text: &str) {
    // Past libtest's capture: what was skipped or changed shows in a plain run.
    let _ = std::io::Write::write_all(&mut std::io::stderr(), text.as_bytes());
}

#[test]
fn every_documented_evtac_command_runs_as_written() {
    let root = workspace_root();
    let mut failures = Vec::new();
    let mut ran = 0;
    let mut every_doc_documented = 0;
    for (doc, setup) in DOCS {
        let markdown = std::fs::read_to_string(root.join(doc)).expect("the document");
        // The document's files, made once and copied into each block's folder.
        let mut prepared: Option<tempfile::TempDir> = None;
        for block in blocks(&markdown) {
            let commands: Vec<&Example> = block.iter().filter(|c| runs_evtac(&c.text)).collect();
            if commands.is_empty() {
                continue;
            }
            every_doc_documented += 1;
            if prepared.is_none() {
                let template = tempfile::tempdir().expect("tmp");
                if setup(template.path()).is_none() {
                    return; // a fixture or Python is missing outside CI: said by the testkit
                }
                prepared = Some(template);
            }
            let dir = tempfile::tempdir().expect("tmp");
            copy_tree(prepared.as_ref().expect("set up").path(), dir.path());
            for c in commands {
                let at = format!("{doc}:{}", c.line);
                if let Some((_, why)) = SKIP.iter().find(|(text, _)| c.text.contains(text)) {
                    say(&format!("skipped: {at}: needs {why}\n"));
                    continue;
                }
                if let Some(tool) = missing_tool(&c.text) {
                    say(&format!("skipped: {at}: needs {tool}, not on the PATH\n"));
                    continue;
                }
                let command = as_run(&c.text);
                if command != c.text {
                    say(&format!("{at}: run at --scale tiny\n"));
                }
                for (when, prepare) in BEFORE {
                    if c.text.contains(when) {
                        let out = run_bash(dir.path(), prepare);
                        assert!(out.status.success(), "{at}: preparing: {out:?}");
                    }
                }
                let out = run_bash(dir.path(), &command);
                ran += 1;
                if !out.status.success() {
                    let err = String::from_utf8_lossy(&out.stderr);
                    let tail: Vec<&str> = err.lines().rev().take(6).collect();
                    let tail: Vec<&str> = tail.into_iter().rev().collect();
                    failures.push(format!("{at}: {}\n  {}", c.text, tail.join("\n  ")));
                }
            }
        }
    }
    assert!(
        every_doc_documented >= DOCS.len(),
        "every document has examples"
    );
    assert!(ran > 30, "only {ran} commands ran");
    assert!(
        failures.is_empty(),
        "{} of {ran} documented commands failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn blocks_split_commands_at_their_ends_and_keep_continuations() {
    let md = "text\n```sh\nevtac a \\\n  --b  # c\n# only a comment\nevtac d \"#x\"   # e\n```\n```python\nevtac no\n```\n";
    let b = blocks(md);
    assert_eq!(b.len(), 1);
    let texts: Vec<&str> = b[0].iter().map(|c| c.text.as_str()).collect();
    assert_eq!(texts, ["evtac a \\\n  --b  # c", "evtac d \"#x\"   # e"]);
    assert_eq!(b[0][1].line, 6);
    assert_eq!(strip_comment("evtac d \"#x\"   # e"), "evtac d \"#x\"   ");
    assert!(runs_evtac("cat e.csv | evtac online"));
    assert!(!runs_evtac(
        "sbatch --array=0-$(( $(evtac jobs count x) - 1 )) a.sbatch"
    ));
}
