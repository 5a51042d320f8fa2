//! Tests of `evtac reproduce`: the whole protocol at the tiny scale, the report with every
//! figure, resuming, and the exported job list.

use crate::common::{run_err, run_ok};
use evtac_experiments::choices;
use evtac_experiments::job::{Job, TrainJob};
use evtac_experiments::plan::Plan;
use evtac_report::{CHOICES_TITLE, FIGURES};
use evtac_repr::ReprKind;
use evtac_sim::{Scale, SimParams};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// One tiny reproduction shared by the tests of `train`, `evaluate`, `tune` and `reproduce`
/// (simulated once per test binary, and the only end-to-end reproduction of every protocol in
/// the test suite; `import.rs` reproduces an imported Experiment 1 session):
/// its output folder. It runs twice: the second run resumes the finished one, and must find
/// every job done and give the same Experiment 1 results.
pub fn tiny_run() -> &'static Path {
    static RUN: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, out) = RUN.get_or_init(|| {
        let dir = tempfile::tempdir().expect("temp dir");
        let out = dir.path().join("out");
        let args = tiny_args(&out);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let log = String::from_utf8_lossy(&run_ok(&args).stderr).into_owned();
        // Not a terminal: plain lines say each stage's start, end and the overall ETA.
        for line in [
            "estimated run time ",
            "experiment 1 training: 10 to do (overall eta ",
            "experiment 1 training: done in ",
            "latency: done in ",
        ] {
            assert!(log.contains(line), "no `{line}` in the log:\n{log}");
        }
        let exp1 = |out: &Path| results(out)["exp1"].clone();
        let noise = |out: &Path| results(out)["noise"].clone();
        let other = |out: &Path| results(out)["dataset_seeds"].clone();
        let (first, first_noise, first_other) = (exp1(&out), noise(&out), other(&out));
        let resumed = String::from_utf8_lossy(&run_ok(&args).stderr).into_owned();
        // Its stages say what an earlier run had finished (features and training alike).
        for line in [
            "experiment 1 training: done in ",
            " (10 of 10 found done by an earlier run)",
        ] {
            assert!(
                resumed.contains(line),
                "no `{line}` in the resumed log:\n{resumed}"
            );
        }
        assert_eq!(exp1(&out), first, "a resumed run changed Experiment 1");
        assert_eq!(
            noise(&out),
            first_noise,
            "a resumed run changed the noise study"
        );
        assert_eq!(
            other(&out),
            first_other,
            "a resumed run changed the other datasets' results"
        );
        (dir, out)
    });
    out
}

/// The arguments of the tiny reproduction (scale tiny, seed 1) into `out`, with the
/// capture-filter ablation (`small`'s default, none at `tiny`) so that every test of a tiny
/// run goes through it too.
pub fn tiny_args(out: &Path) -> Vec<String> {
    let out = out.to_str().expect("utf-8 path");
    [
        "reproduce",
        "--scale",
        "tiny",
        "--seed",
        "1",
        "--out",
        out,
        "--capture-filter",
        "background-activity=10ms",
    ]
    .map(String::from)
    .to_vec()
}

/// A decoded 8-bit RGB figure.
struct Rgb(Vec<u8>);

impl Rgb {
    fn decode(bytes: &[u8]) -> Rgb {
        let mut reader = png::Decoder::new(bytes).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(
            (info.color_type, info.bit_depth),
            (png::ColorType::Rgb, png::BitDepth::Eight)
        );
        buf.truncate(info.buffer_size());
        Rgb(buf)
    }

    fn pixels(&self) -> impl Iterator<Item = [u8; 3]> + '_ {
        self.0.chunks_exact(3).map(|p| [p[0], p[1], p[2]])
    }

    /// The share of pixels for which `f` holds.
    fn share(&self, f: impl Fn([u8; 3]) -> bool) -> f64 {
        self.pixels().filter(|&p| f(p)).count() as f64 / (self.0.len() / 3).max(1) as f64
    }

    fn distinct(&self) -> usize {
        self.pixels()
            .collect::<std::collections::HashSet<_>>()
            .len()
    }
}

/// `results.json` of a finished run.
fn results(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap()
}

#[test]
fn tiny_reproduction_writes_the_report_with_every_figure() {
    let out = tiny_run();
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for row in [
        "| Static |",
        "| Dynamic |",
        "| Combined |",
        "| Stacked |",
        "| Late |",
    ] {
        assert!(report.contains(row), "no `{row}` row in:\n{report}");
    }
    // The learned fusions: beside the paper's three, and the section's verdicts, computed.
    assert!(report.contains("| Late | ") && report.contains("not in the paper"));
    assert!(report.contains("## Beyond OR: learned fusion"), "{report}");
    for line in [
        "- Experiment 1: Stacked (",
        "- Experiment 1: Late (",
        "against the best single representation, ",
        "- Experiment 2, ",
        "**In short:** at scale `tiny`, ",
    ] {
        assert!(report.contains(line), "no `{line}` in:\n{report}");
    }
    assert!(
        report.contains("0.160 ± 0.004"),
        "the paper's numbers are quoted"
    );
    // Every figure drawn, named in the report, and not blank; nothing else in figures/.
    assert!(
        FIGURES.len() >= 8,
        "the report has {} figures",
        FIGURES.len()
    );
    for (fig, _) in FIGURES {
        let bytes = std::fs::read(out.join("figures").join(fig)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG"), "{fig} is not a PNG");
        assert!(bytes.len() > 5_000, "{fig} is nearly empty");
        let image = Rgb::decode(&bytes);
        assert!(
            image.share(|p| p != [255, 255, 255]) > 0.02,
            "{fig} is blank"
        );
        assert!(
            image.distinct() >= 16,
            "{fig} has {} colors",
            image.distinct()
        );
        assert!(
            report.contains(&format!("(figures/{fig})")),
            "{fig} not referenced"
        );
    }
    for entry in std::fs::read_dir(out.join("figures")).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            report.contains(&format!("(figures/{name})")),
            "figures/{name} is not named in report.md"
        );
    }
    // Fig. 2: the window's events in colour (ON red or OFF blue), and frames with set pixels.
    let repr = Rgb::decode(&std::fs::read(out.join("figures/representations.png")).unwrap());
    assert!(
        repr.share(|p| p == [255, 60, 60] || p == [70, 140, 255]) > 0.001,
        "representations.png shows no events"
    );
    assert!(repr.share(|p| p == [255, 255, 255]) > 0.001);
    // The simulated sensor: a camera image has many grey levels, not two.
    let sensor = Rgb::decode(&std::fs::read(out.join("figures/sensor.png")).unwrap());
    let greys = sensor.pixels().filter(|p| p[0] == p[1] && p[1] == p[2]);
    let levels: std::collections::HashSet<u8> = greys.map(|p| p[0]).collect();
    assert!(
        levels.len() > 64,
        "sensor.png has {} grey levels",
        levels.len()
    );
    assert!(report.contains("Simulated: the simulator's camera brightness"));
    // Every value the paper leaves open, as this run used it: simulated with the defaults.
    assert!(report.contains(&format!("## {CHOICES_TITLE}")));
    let sim = SimParams::default();
    let expected = choices::of_run(&Plan::for_scale(Scale::Tiny), 1, Some(&sim), Some(&sim));
    for c in &expected {
        let row = format!("| {} | {} | {} | {} |", c.what, c.value, c.why, c.change);
        assert!(report.contains(&row), "no choice row `{row}` in:\n{report}");
    }
    let results = results(out);
    assert_eq!(
        results["choices"].as_array().map(Vec::len),
        Some(expected.len())
    );
    let reprs = evtac_repr::ReprKind::BINARY.len();
    assert_eq!(results["exp1"].as_array().map(Vec::len), Some(reprs));
    // Experiment 1 at every noise level of the plan, for every representation; x1 is
    // Experiment 1 itself, and no noise means no background events.
    let levels = Plan::for_scale(Scale::Tiny).noise_levels;
    let noise = results["noise"].as_array().unwrap();
    assert_eq!(noise.len(), reprs * levels.len());
    for p in noise {
        let level = p["level"].as_f64().unwrap();
        assert!(levels.contains(&level), "{p}");
        let rate = p["no_contact_events_per_s"].as_f64().unwrap();
        assert_eq!(
            rate == 0.0,
            level == 0.0,
            "background rate {rate} at x{level}"
        );
        if level == 1.0 {
            let e1 = results["exp1"].as_array().unwrap();
            let same = e1.iter().find(|e| e["name"] == p["name"]).unwrap();
            assert_eq!(same["test"], p["test"], "x1 is not Experiment 1");
        }
        assert!(p["test"]["overall"]["mean"].as_f64().unwrap() > 0.0);
    }
    for level in levels {
        assert!(
            report.contains(&format!("| x{level} | ")),
            "no x{level} row"
        );
    }
    assert!(report.contains("Dynamic minus static test MAE: "));
    // Experiment 1 on the plan's two simulated datasets: the first is Experiment 1 itself, the
    // second another simulation (its own folder and models) with other results.
    let points = results["dataset_seeds"].as_array().unwrap();
    assert_eq!(points.len(), reprs * Plan::for_scale(Scale::Tiny).datasets);
    let e1 = results["exp1"].as_array().unwrap();
    for p in points {
        let same = e1.iter().find(|e| e["name"] == p["name"]).unwrap();
        let first = p["dataset_seed"] == results["run"]["seed"];
        assert_eq!(same["runs"] == p["runs"], first, "{p}");
    }
    let seed = results["run"]["seed"].as_u64().unwrap();
    let other = format!("datasets/seed{}", seed + 1);
    assert!(out.join(&other).join("simulator.json").is_file());
    assert!(out.join("models").join(&other).join("exp1").is_dir());
    assert!(
        report.contains("## Experiment 1 on other simulated datasets")
            && report.contains("| SD across datasets |")
            && report.contains("pairs differ beyond both spreads"),
        "{report}"
    );
    // The label-noise ablation: the paper's three, trained on noisy labels, beside Experiment 1
    // on the clean ones, its models apart from Experiment 1's.
    let ablation = &results["label_noise"];
    assert_eq!(ablation["sd_deg"].as_f64(), Some(0.04));
    let e1 = results["exp1"].as_array().unwrap();
    for (noisy, clean) in ablation["noisy"]
        .as_array()
        .unwrap()
        .iter()
        .zip(ablation["clean"].as_array().unwrap())
    {
        assert_eq!(noisy["name"], clean["name"]);
        assert_eq!(
            noisy["config"], clean["config"],
            "the ablation keeps the tuned settings"
        );
        assert!(e1.contains(clean), "{clean} is not Experiment 1's");
        assert_ne!(noisy["runs"], clean["runs"], "noisy labels changed nothing");
    }
    assert_eq!(ablation["noisy"].as_array().map(Vec::len), Some(3));
    let noisy_model = out.join("models/label-noise/sd0.04/exp1/static/seed1/config.json");
    assert!(noisy_model.is_file(), "{}", noisy_model.display());
    assert!(report.contains("## Label-noise ablation"), "{report}");
    // The capture-filter ablation: the paper's three on filtered events, paired with Experiment
    // 1's, their models recording the filter and their features cached apart.
    let ablation = &results["capture_filter"];
    assert_eq!(ablation["spec"], "background-activity=10ms");
    for (filtered, plain) in ablation["filtered"]
        .as_array()
        .unwrap()
        .iter()
        .zip(ablation["unfiltered"].as_array().unwrap())
    {
        assert_eq!(filtered["name"], plain["name"]);
        assert_eq!(filtered["config"], plain["config"]);
        assert_eq!(filtered["seeds"], plain["seeds"]);
        assert!(e1.contains(plain), "{plain} is not Experiment 1's");
        assert_ne!(
            filtered["runs"], plain["runs"],
            "the filter changed nothing"
        );
    }
    assert_eq!(ablation["filtered"].as_array().map(Vec::len), Some(3));
    let model = out.join("models/capture-filter/exp1/static/seed1/config.json");
    let config: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(
        config["representation"]["filters"],
        serde_json::json!(["background-activity=10ms"])
    );
    assert!(
        report.contains("## Capture-filter ablation")
            && report.contains("through `background-activity=10ms` on the full sensor"),
        "{report}"
    );
    let settings = 3; // continuous-only, pause-motion, pause-motion-stop
    assert_eq!(
        results["exp2"].as_array().map(Vec::len),
        Some(settings * reprs)
    );
    let speeds = results["exp3_speed"].as_array().unwrap();
    assert!(
        speeds.iter().any(|p| p["seen"] == false),
        "Experiment 3 has no unseen speed"
    );
    assert!(!results["exp3_depth"].as_array().unwrap().is_empty());
    let intervals = Plan::for_scale(Scale::Tiny).latency_intervals_ms.len();
    assert_eq!(
        results["latency"].as_array().map(Vec::len),
        Some(reprs * intervals)
    );
    let mae = results["exp1"][0]["test"]["overall"]["mean"]
        .as_f64()
        .unwrap();
    assert!(mae.is_finite() && mae > 0.0);
}

#[test]
fn finished_run_exports_no_jobs_and_a_fresh_one_exports_the_tuning_grid() {
    let out = tiny_run();
    let data = out.join("data");
    let dir = tempfile::tempdir().unwrap();
    let list = dir.path().join("jobs.txt");
    let args = |o: &Path| {
        vec![
            "reproduce".to_string(),
            "--scale".into(),
            "tiny".into(),
            "--seed".into(),
            "1".into(),
            "--data".into(),
            data.display().to_string(),
            "--out".into(),
            o.display().to_string(),
            "--export-jobs".into(),
            list.display().to_string(),
        ]
    };
    let a = args(out);
    run_ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(std::fs::read_to_string(&list).unwrap(), "");
    let fresh = dir.path().join("fresh");
    let a = args(&fresh);
    run_ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let jobs = evtac_experiments::job::read(&list).unwrap();
    // The tiny cross: 6 static settings (the paper grid's 3 and the extended grid's 3 longer
    // decays at the cross's threshold) and 3 dynamic ones.
    assert_eq!(jobs.len(), 9, "{jobs:?}");
    let train: Vec<&TrainJob> = jobs
        .iter()
        .filter_map(|j| match j {
            Job::Train(t) => Some(t),
            _ => None,
        })
        .collect();
    assert_eq!(train.len(), 9);
    let kinds = |k: ReprKind| train.iter().filter(|t| t.spec.repr.kind() == k).count();
    assert_eq!((kinds(ReprKind::Static), kinds(ReprKind::Dynamic)), (6, 3));
    // Run one as a Slurm task would: it trains what a local run trains (the same bytes as the
    // tiny run's model of that setting), and it is no longer listed.
    let list_s = list.display().to_string();
    run_ok(&["jobs", "run", &list_s, "--index", "0"]);
    let trained = std::fs::read(train[0].out.join("model.safetensors")).unwrap();
    let local = out.join(train[0].out.strip_prefix(&fresh).unwrap());
    assert_eq!(
        trained,
        std::fs::read(local.join("model.safetensors")).unwrap()
    );
    let a = args(&fresh);
    run_ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(evtac_experiments::job::read(&list).unwrap().len(), 8);
}

#[test]
fn datasets_without_calibration_or_no_contact_are_refused_unless_opted_out() {
    let report = std::fs::read_to_string(tiny_run().join("report.md")).unwrap();
    assert!(
        report.contains("Calibration: calibration.json. No-contact mask: no_contact.aedat4."),
        "the report does not state its inputs"
    );
    // A dataset of only a manifest: opening it is refused before any recording is read.
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    let exp1 = data.join("exp1");
    std::fs::create_dir_all(&exp1).unwrap();
    std::fs::copy(
        tiny_run().join("data").join("exp1").join("trials.csv"),
        exp1.join("trials.csv"),
    )
    .unwrap();
    let (data_s, exp1_s) = (data.to_str().unwrap(), exp1.to_str().unwrap());
    let out_s = dir.path().join("out").display().to_string();
    let list = dir.path().join("jobs.txt");
    let list_s = list.to_str().unwrap();
    let reproduce = |extra: &[&str]| {
        let mut a = vec!["reproduce", "--scale", "tiny", "--data", data_s, "--out"];
        a.extend([out_s.as_str(), "--export-jobs", list_s]);
        a.extend(extra);
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let run = |extra: &[&str], ok: bool| {
        let a = reproduce(extra);
        let args: Vec<&str> = a.iter().map(String::as_str).collect();
        if ok {
            run_ok(&args);
            String::new()
        } else {
            run_err(&args)
        }
    };
    let err = run(&[], false);
    assert!(
        err.contains("calibration.json is missing") && err.contains("--identity-calibration"),
        "{err}"
    );
    let err = run(&["--identity-calibration"], false);
    assert!(
        err.contains("no_contact.aedat4 is missing") && err.contains("--no-mask"),
        "{err}"
    );
    run(&["--identity-calibration", "--no-mask"], true);
    let jobs = evtac_experiments::job::read(&list).unwrap();
    assert!(!jobs.is_empty());
    let opted_out = evtac_import::inputs::Inputs::from_flags(true, true);
    assert!(
        jobs.iter()
            .all(|j| matches!(j, Job::Train(t) if t.inputs == opted_out)),
        "exported jobs must open the dataset as the reproduction does:\n{jobs:?}"
    );
    let model = dir.path().join("m").display().to_string();
    for cmd in [
        vec!["train", exp1_s, "--repr", "static", "--out", &model],
        vec!["tune", exp1_s, "--repr", "static", "--scale", "tiny"],
    ] {
        let err = run_err(&cmd);
        assert!(
            err.contains("calibration.json is missing"),
            "{cmd:?}: {err}"
        );
    }
}

#[test]
fn no_fusions_trains_the_papers_three_representations_only() {
    // The tiny run's tuning is done: exporting the jobs that can run now lists Experiments 1
    // and 2's, for every representation the plan compares.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("models")).unwrap();
    let copied = std::process::Command::new("cp")
        .arg("-r")
        .arg(tiny_run().join("models").join("tuning"))
        .arg(out.join("models"))
        .status()
        .unwrap();
    assert!(copied.success());
    let data = tiny_run().join("data").display().to_string();
    let out_s = out.display().to_string();
    let export = |extra: &[&str]| {
        let list = dir.path().join("jobs.txt");
        let list_s = list.display().to_string();
        let mut args = vec![
            "reproduce",
            "--scale",
            "tiny",
            "--seed",
            "1",
            "--data",
            &data,
        ];
        args.extend(["--out", &out_s, "--export-jobs", &list_s]);
        args.extend(extra);
        run_ok(&args);
        let jobs = evtac_experiments::job::read(&list).unwrap();
        let count = |kind: ReprKind| {
            jobs.iter()
                .filter(|j| matches!(j, Job::Train(t) if t.spec.repr.kind() == kind))
                .count()
        };
        ReprKind::BINARY.map(count)
    };
    let all = export(&[]);
    let paper = export(&["--no-fusions"]);
    assert!(
        all.iter().all(|&n| n > 0),
        "jobs per representation: {all:?}"
    );
    assert_eq!(paper[..3], all[..3], "the paper's three keep their jobs");
    assert_eq!(paper[3..], [0, 0], "no fusion is trained: {paper:?}");
    // The paper's plan as a shell gives it: `--noise-levels ''` is no levels, not an error.
    assert_eq!(export(&["--no-fusions", "--noise-levels", ""]), paper);
    let bad = crate::common::evtac()
        .args(["reproduce", "--scale", "tiny", "--out", &out_s])
        .args(["--noise-levels", "0,x3"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && stderr.contains("\"x3\" is not a factor"),
        "{stderr}"
    );
    let none = crate::common::evtac()
        .args(["reproduce", "--scale", "tiny", "--out", &out_s])
        .args(["--datasets", "0"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&none.stderr);
    assert!(
        !none.status.success() && stderr.contains("--datasets"),
        "{stderr}"
    );
}

#[test]
fn a_resumed_reproductions_report_tables_every_invocations_stages() {
    // `tiny_run` ran twice: the second invocation resumed the first.
    let out = tiny_run();
    let run = &results(out)["run"];
    let history = run["stage_history"]
        .as_array()
        .expect("stage_history")
        .clone();
    let stages_of = |invocation: u64| -> Vec<String> {
        history
            .iter()
            .filter(|r| r["invocation"] == invocation)
            .map(|r| r["stage"].as_str().expect("stage").to_string())
            .collect()
    };
    let (first, second) = (stages_of(1), stages_of(2));
    assert_eq!(
        first.first().map(String::as_str),
        Some("simulation"),
        "{first:?}"
    );
    for stage in ["tuning (static)", "experiment 1", "latency", "report"] {
        assert!(
            first.iter().any(|s| s == stage),
            "no `{stage}` in {first:?}"
        );
    }
    // The second wrote results.json during its report stage: its stages up to the latency.
    for stage in ["simulation", "experiment 1", "latency"] {
        assert!(
            second.iter().any(|s| s == stage),
            "no `{stage}` in {second:?}"
        );
    }
    let csv = std::fs::read_to_string(out.join("stage-times.csv")).unwrap();
    assert!(csv.starts_with("invocation,stage,seconds\n"));
    assert_eq!(
        csv.lines().rfind(|l| l.starts_with("2,")),
        csv.lines().last(),
        "the second invocation's report row ends the log"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("produced by 2 invocations") && report.contains("| 1 | simulation |"),
        "the report does not table both invocations"
    );
    let total: f64 = history.iter().map(|r| r["seconds"].as_f64().unwrap()).sum();
    assert!(
        report.contains(&format!("| | total | {total:.1} |")),
        "the report's total is not the invocations' sum ({total:.1})"
    );
}

#[test]
fn two_repeats_measure_the_split_that_keeps_them_together() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out_s = out.display().to_string();
    // Two passes, and of the studies the repeats-together split alone.
    let two_passes = [
        "reproduce",
        "--scale",
        "tiny",
        "--out",
        &out_s,
        "--repeats",
        "2",
        "--datasets",
        "1",
        "--no-fusions",
        "--noise-levels",
        "",
        "--label-noise-deg",
        "0",
    ];
    run_ok(&two_passes);
    let r = results(&out);
    // Two passes over tiny's 16 conditions, each with its own seating.
    let trials = |name: &str| {
        r["run"]["datasets"]
            .as_array()
            .unwrap()
            .iter()
            .find(|d| d[0] == name)
            .and_then(|d| d[1].as_u64())
    };
    assert_eq!(trials("exp1"), Some(32));
    assert_eq!(trials("exp2"), Some(32));
    let sim: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("data/exp1/simulator.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(sim["repeats"], 2);
    let split = &r["repeat_split"];
    assert_eq!(split["repeats"], 2);
    let together = split["together"].as_array().unwrap();
    assert_eq!(together.len(), 3);
    for (t, p) in together
        .iter()
        .zip(split["paper_split"].as_array().unwrap())
    {
        assert_eq!(t["name"], p["name"]);
        assert_eq!(t["config"], p["config"], "the same settings on both splits");
        assert_ne!(t["runs"], p["runs"], "another split, other test trials");
    }
    assert!(
        out.join("models/repeats-together/exp1/static").is_dir(),
        "the grouped split's models have their own folder"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## Repeats across the split"), "{report}");
    assert!(!report.contains("## Experiment 1 on other simulated datasets"));
    // The one-pass scale measures nothing of the kind.
    assert!(results(tiny_run())["repeat_split"].is_null());
    let bad = crate::common::evtac()
        .args([
            "reproduce",
            "--scale",
            "tiny",
            "--out",
            &out_s,
            "--repeats",
            "0",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && stderr.contains("not a number of passes"),
        "{stderr}"
    );
    // Given datasets are already simulated: their passes cannot be changed.
    let data = out.join("data").display().to_string();
    let given = crate::common::evtac()
        .args(["reproduce", "--scale", "tiny", "--out", &out_s])
        .args(["--data", &data, "--repeats", "3"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&given.stderr);
    assert!(
        !given.status.success() && stderr.contains("--repeats sets how the datasets are simulated"),
        "{stderr}"
    ); // The paper's own plan leaves the study out: the same run again (every job done) without it.
    run_ok(&[&two_passes[..], &["--no-repeat-split"]].concat());
    assert!(results(&out)["repeat_split"].is_null());
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(!report.contains("## Repeats across the split"), "{report}");
}
