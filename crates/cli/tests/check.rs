//! Tests of `evtac check`: exit status 0 and a summary for a simulated dataset, 1 and a table
//! of problems for a damaged one.

use crate::common::{evtac, run_ok, simulate_tiny};

#[test]
fn passes_a_simulated_dataset_and_tables_the_problems_of_a_damaged_one() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("ds");
    let ds_s = ds.to_str().unwrap();
    simulate_tiny("exp1", 5, &ds, 2);
    let out = run_ok(&["check", ds_s]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        text,
        format!("{ds_s}: no problems in 1 dataset (2 trials, 3 recordings checked)\n")
    );

    std::fs::remove_file(ds.join("calibration.json")).unwrap();
    std::fs::remove_file(ds.join("t0001.aedat4")).unwrap();
    let out = evtac().args(["check", ds_s]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "{text}");
    let cells = |l: &str| l.split_whitespace().take(3).collect::<Vec<_>>().join(" ");
    assert_eq!(cells(lines[0]), "file line field");
    assert!(
        lines[0].contains(" problem ") && lines[0].ends_with(" fix"),
        "{text}"
    );
    assert_eq!(cells(lines[1]), "calibration.json - -");
    assert!(lines[1].contains("--identity-calibration"), "{text}");
    assert_eq!(cells(lines[2]), "t0001.aedat4 3 file");
    assert_eq!(
        lines[3],
        "2 problems in 1 dataset (2 trials, 3 recordings checked)"
    );

    let out = evtac()
        .args(["check", ds_s, "--identity-calibration", "--json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let problems = json["problems"].as_array().unwrap();
    assert_eq!(problems.len(), 1, "{json}");
    assert_eq!(problems[0]["line"], 3);
    assert_eq!(problems[0]["field"], "file");
    assert_eq!(problems[0]["problem"], "missing");
}

#[test]
fn a_missing_or_empty_folder_is_said_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nothing-here");
    let o = evtac().arg("check").arg(&missing).output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(!o.status.success());
    assert!(out.contains("the folder does not exist"), "{out}");
    assert!(!out.contains("trials.csv"), "{out}");
    let o = evtac().arg("check").arg(dir.path()).output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(!o.status.success());
    assert!(out.contains("the folder is empty"), "{out}");
}

#[test]
fn an_error_says_its_cause_once() {
    let dir = tempfile::tempdir().unwrap();
    let o = evtac()
        .args(["evaluate", "--model"])
        .arg(dir.path().join("no-model"))
        .arg(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
}

#[test]
fn a_missing_folder_is_named_in_its_row() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no-such-folder");
    let o = evtac().arg("check").arg(&missing).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let out = String::from_utf8_lossy(&o.stdout);
    let row = out.lines().nth(1).unwrap_or_default();
    // The file column holds the folder as given (not the empty path relative to itself).
    assert!(
        row.starts_with(&format!("{}  ", missing.display())),
        "{out}"
    );
    assert!(row.contains("the folder does not exist"), "{out}");
}

#[test]
fn filters_are_refused_rather_than_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let o = evtac()
        .arg("check")
        .arg(dir.path())
        .args(["--filter", "polarity=on"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("check reads the dataset's files as they are"),
        "{err}"
    );
}
