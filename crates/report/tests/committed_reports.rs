//! The committed reports (`docs/report-example`, `docs/report-paper`) are what this code makes
//! of their committed `results.json`: a change to the report's wording or tables shows up here
//! until the reports are re-rendered, so the docs never describe a run in words the code no
//! longer writes. `EVTAC_BLESS=1` re-renders them (the Markdown only: the numbers come from the
//! committed runs, the figures from the runs' own binaries).

use evtac_experiments::results::Results;
use std::path::Path;

fn check(dir: &str) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs")
        .join(dir);
    let text = std::fs::read_to_string(dir.join("results.json")).unwrap();
    let results: Results = serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.join("results.json").display()));
    let present: Vec<&str> = evtac_report::FIGURES
        .iter()
        .map(|(file, _)| *file)
        .filter(|file| dir.join("figures").join(file).is_file())
        .collect();
    let made = evtac_report::markdown(&results, &present);
    let path = dir.join("report.md");
    if std::env::var_os("EVTAC_BLESS").is_some() {
        std::fs::write(&path, &made).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap();
    if committed != made {
        let first = committed
            .lines()
            .zip(made.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(committed.lines().count().min(made.lines().count()));
        panic!(
            "{} is not what the code makes of its results.json (first difference at line {}:\n  \
             committed: {:?}\n  made:      {:?}); re-render with EVTAC_BLESS=1 cargo test -p \
             evtac-report --test committed_reports",
            path.display(),
            first + 1,
            committed.lines().nth(first),
            made.lines().nth(first)
        );
    }
}

#[test]
fn the_example_report_is_what_the_code_makes_of_its_results() {
    check("report-example");
}

#[test]
fn the_paper_scale_report_is_what_the_code_makes_of_its_results() {
    check("report-paper");
}
