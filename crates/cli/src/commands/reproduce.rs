//! `evtac reproduce`: the paper end to end. Simulates the datasets when none are given (every
//! protocol), then labels, splits, tuning, Experiments 1-3, the latency study and the report
//! (`OUT/report.md`, `OUT/results.json`, `OUT/figures/`). Interrupted runs resume from finished
//! jobs; `--export-jobs` writes the ready training jobs as `evtac train` lines instead, and
//! `--executor slurm` submits every stage to a Slurm cluster (`evtac_experiments::slurm`).

use crate::progress::Bars;
use anyhow::Context;
use evtac_experiments::job::{self, ReproduceJob};
use evtac_experiments::pipeline::{self, Datasets};
use evtac_experiments::plan::{Grid, Plan};
use evtac_experiments::progress::Progress;
use evtac_experiments::stage::{CostModel, Stage, TrialCounts};
use evtac_experiments::stage_log::StageLog;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

/// Arguments of `evtac reproduce`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Run time: a few minutes at --scale tiny, under 20 minutes on 2 cores at small. \
    With --executor slurm, each stage's jobs are one Slurm job array."
)]
pub struct Args {
    #[command(flatten)]
    pub scale_seed: crate::scale_seed::ScaleSeed,
    /// Folder with the datasets `exp1/` (required), `exp2/`, `exp3-speed/`, `exp3-depth/`
    /// (simulated into `OUT/data` when not given).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Opting out of the `--data` datasets' calibration or mask (simulated datasets have both).
    #[command(flatten)]
    pub inputs: crate::inputs::InputArgs,
    /// Output folder: models, report, figures.
    #[arg(long)]
    pub out: PathBuf,
    /// Background-noise factors to repeat Experiment 1 at (leak, shot and hot-pixel noise of
    /// the simulator scaled together; 1 is Experiment 1 itself), comma-separated; empty to skip.
    /// Default: the plan's (0,1,3 at every scale). Needs simulated Experiment 1 data.
    #[arg(long, value_delimiter = ',', num_args = 0.., value_parser = noise_level)]
    pub noise_levels: Option<Vec<NoiseLevel>>,
    /// Leave out evtac's learned fusions (stacked, late): train and report the paper's three
    /// representations only. With `--noise-levels` given empty, `--label-noise-deg 0`,
    /// `--no-repeat-split` and `--grid paper`, this is the paper's own plan (195 training runs at
    /// `--scale paper` and the recheck of the best settings, instead of 435).
    #[arg(long)]
    pub no_fusions: bool,
    /// Standard deviation (degrees) of the noise the label-noise ablation adds to Experiment
    /// 1's training labels (the paper's three representations trained again on them); 0 skips
    /// the ablation. Default: the plan's, 0.04 (the spread of the paper's label check).
    #[arg(long, value_name = "SD")]
    pub label_noise_deg: Option<f64>,
    /// Simulated datasets to run Experiment 1 on, its own included: each other one is simulated
    /// with the same parameters and the next seed, and trained with the settings tuned on the
    /// first, so the report can set the spread across datasets beside the training seeds'.
    /// 1 runs Experiment 1's dataset alone (the paper's plan). Default: the plan's (5 at
    /// `small`, 2 at `tiny`, 3 at `paper`). Needs simulated Experiment 1 data.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub datasets: Option<u64>,
    /// Passes over the conditions of the simulated Experiments 1 and 2, each with the sensor
    /// seated again, instead of the scale's (2 at `paper`, 1 at `small` and `tiny`). With 2 or
    /// more, the report measures what repeats on both sides of the split are worth: Experiment
    /// 1 trained again with each condition's repeats kept on one side.
    #[arg(long, value_name = "N", value_parser = parse_repeats)]
    pub repeats: Option<usize>,
    /// Leave out Experiment 1 trained again with each condition's repeats kept on one side of
    /// the split (30 training runs at `--scale paper`, which has two repeats; nothing at one
    /// repeat, where the study does not run).
    #[arg(long)]
    pub no_repeat_split: bool,
    /// The tuning grids: `extended` (the default) adds static decays of 3, 5 and 10 s to the
    /// paper's grid, whose static optimum sat on its largest decay; `paper` keeps the grids
    /// that bracket the paper's stated values (the paper's own plan).
    #[arg(long, value_name = "GRID", value_parser = clap::value_parser!(Grid))]
    pub grid: Option<Grid>,
    /// Leave out training the 3 best settings of each tuning again with 5 seeds each (24 runs
    /// of the tuning's epochs at every scale; the report then judges the choice against the
    /// seeds' spread Experiment 1 measured instead).
    #[arg(long)]
    pub no_recheck: bool,
    /// Worker threads.
    #[command(flatten)]
    pub workers: crate::workers::Workers,
    /// Write the training jobs that are ready (not finished) to the jobs file FILE, one job per
    /// line, and stop. Run them (`evtac jobs run FILE --index K`, e.g. as a Slurm array), then
    /// run `evtac reproduce` again with the same arguments: it resumes from the finished jobs.
    #[arg(long)]
    pub export_jobs: Option<PathBuf>,
    #[command(flatten)]
    pub executor: crate::cluster::ExecutorArgs,
}

/// One value of `--noise-levels`: a factor, or none (`--noise-levels ''`, how a shell gives
/// the flag an empty value, means no levels as `--noise-levels` alone does).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseLevel(pub Option<f64>);

fn noise_level(s: &str) -> Result<NoiseLevel, String> {
    let s = s.trim();
    if s.is_empty() {
        return Ok(NoiseLevel(None));
    }
    s.parse::<f64>()
        .map(|v| NoiseLevel(Some(v)))
        .map_err(|e| format!("{s:?} is not a factor: {e}"))
}

/// `--repeats` (here and in `evtac simulate`): a count of at least 1.
pub(crate) fn parse_repeats(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("{s:?} is not a number of passes (1 or more)")),
    }
}

impl Args {
    /// The noise levels asked for (empty values dropped), or `None` for the plan's.
    pub fn noise_levels(&self) -> Option<Vec<f64>> {
        self.noise_levels
            .as_ref()
            .map(|levels| levels.iter().filter_map(|l| l.0).collect())
    }

    /// The arguments that run `job` on this machine with one worker thread (the last task of a
    /// Slurm reproduction, whose task has one CPU).
    pub fn for_job(job: &ReproduceJob) -> Args {
        Args {
            scale_seed: crate::scale_seed::ScaleSeed {
                scale: job.scale,
                seed: job.seed,
            },
            data: job.data.clone(),
            inputs: crate::inputs::InputArgs::of(job.inputs),
            out: job.out.clone(),
            label_noise_deg: job.label_noise_deg,
            datasets: job.datasets.map(|n| n as u64),
            repeats: job.repeats,
            no_repeat_split: !job.repeat_split,
            grid: job.grid,
            no_recheck: !job.recheck,
            noise_levels: job
                .noise_levels
                .as_ref()
                .map(|levels| levels.iter().map(|&l| NoiseLevel(Some(l))).collect()),
            no_fusions: !job.fusions,
            workers: crate::workers::Workers { jobs: Some(1) },
            export_jobs: None,
            executor: crate::cluster::ExecutorArgs::local(),
        }
    }
}

/// The stage bars plus an overall bar over the estimated cost of every stage: its ETA is the
/// estimate of the time left for the whole run. When stderr is not a terminal (a run under
/// `nohup` writing to a log), the bars are hidden and [`Overall`] writes plain lines instead: each
/// stage's start and end with its time, and every [`LOG_EVERY`] a line with the stage's count and
/// the overall ETA, so a log of a long run says where it is.
struct Overall<'a> {
    bars: &'a Bars,
    overall: indicatif::ProgressBar,
    costs: CostModel,
    /// Milliseconds of estimated cost per unit of the current stage.
    per_unit: Mutex<f64>,
    /// Milliseconds of estimated cost found done by an earlier run: on the bar, but left out of
    /// the pace the plain-line ETA learns.
    skipped_ms: std::sync::atomic::AtomicU64,
    /// The plain-line log, when stderr is not a terminal.
    log: Option<Mutex<PlainLog>>,
}

/// How often a plain-line log reports progress within a stage.
const LOG_EVERY: std::time::Duration = std::time::Duration::from_secs(60);

/// What the plain-line log knows of the current stage.
struct PlainLog {
    started: Instant,
    stage: Option<(String, Instant, u64)>,
    done: u64,
    /// Units of the current stage an earlier run had finished.
    skipped: u64,
    last_line: Instant,
}

impl PlainLog {
    /// Ends the current stage's line, if any.
    fn end_stage(&mut self) {
        if let Some((name, since, total)) = self.stage.take() {
            let resumed = match self.skipped {
                0 => String::new(),
                n => format!(" ({n} of {total} found done by an earlier run)"),
            };
            eprintln!(
                "[{}] {name}: done in {:.1} s{resumed}",
                clock(self.started.elapsed()),
                since.elapsed().as_secs_f64()
            );
        }
    }
}

/// Seconds left of a run that has done `done` of `total` units of cost in `elapsed_s` seconds,
/// `skipped` of them found done by an earlier run (in no time: a resumed run that learned its
/// pace from them would promise to finish in minutes). `None` before any work was timed.
fn seconds_left(elapsed_s: f64, done: u64, skipped: u64, total: u64) -> Option<f64> {
    let worked = done.saturating_sub(skipped);
    (worked > 0).then(|| elapsed_s * total.saturating_sub(done) as f64 / worked as f64)
}

/// `h:mm:ss` of a duration.
fn clock(d: std::time::Duration) -> String {
    let s = d.as_secs();
    format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}

impl<'a> Overall<'a> {
    fn new(bars: &'a Bars, costs: CostModel) -> Self {
        let total_ms = (costs.total_seconds() * 1000.0).round() as u64;
        let overall = bars.add(crate::progress::bar(total_ms.max(1), "overall"));
        overall.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:>12} [{elapsed_precise}] {wide_bar} {percent:>3}% (eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        let log = (!std::io::stderr().is_terminal()).then(|| {
            eprintln!(
                "estimated run time {} (cost model of a 2-core reference machine); progress every {} s below",
                clock(std::time::Duration::from_secs_f64(costs.total_seconds())),
                LOG_EVERY.as_secs()
            );
            Mutex::new(PlainLog {
                started: Instant::now(),
                stage: None,
                done: 0,
                skipped: 0,
                last_line: Instant::now(),
            })
        });
        Self {
            bars,
            overall,
            costs,
            per_unit: Mutex::new(0.0),
            skipped_ms: std::sync::atomic::AtomicU64::new(0),
            log,
        }
    }

    /// The overall ETA from the cost done so far and the time it took.
    fn eta(&self, elapsed: std::time::Duration) -> String {
        let (done, total) = (self.overall.position(), self.overall.length().unwrap_or(1));
        let skipped = self.skipped_ms.load(std::sync::atomic::Ordering::Relaxed);
        match seconds_left(elapsed.as_secs_f64(), done, skipped, total) {
            Some(left) => clock(std::time::Duration::from_secs_f64(left)),
            None => "unknown".into(),
        }
    }

    fn finish(&self) {
        self.overall.finish_and_clear();
        self.bars.finish();
        if let Some(log) = &self.log
            && let Ok(mut log) = log.lock()
        {
            log.end_stage();
        }
    }
}

impl Progress for Overall<'_> {
    fn stage(&self, stage: Stage, total: u64) {
        self.bars.stage(stage, total);
        if let Ok(mut per_unit) = self.per_unit.lock() {
            let cost = self.costs.seconds(stage, total) * 1000.0;
            *per_unit = if total > 0 { cost / total as f64 } else { 0.0 };
        }
        if let Some(log) = &self.log
            && let Ok(mut log) = log.lock()
        {
            log.end_stage();
            let elapsed = log.started.elapsed();
            eprintln!(
                "[{}] {stage}: {total} to do (overall eta {})",
                clock(elapsed),
                self.eta(elapsed)
            );
            log.stage = Some((stage.to_string(), Instant::now(), total));
            log.done = 0;
            log.skipped = 0;
            log.last_line = Instant::now();
        }
    }
    fn advance(&self, n: u64) {
        self.bars.advance(n);
        if let Ok(per_unit) = self.per_unit.lock() {
            self.overall.inc((*per_unit * n as f64).round() as u64);
        }
        if let Some(log) = &self.log
            && let Ok(mut log) = log.lock()
        {
            log.done += n;
            if log.last_line.elapsed() >= LOG_EVERY
                && let Some((name, _, total)) = &log.stage
            {
                let elapsed = log.started.elapsed();
                eprintln!(
                    "[{}] {name}: {}/{total} (overall eta {})",
                    clock(elapsed),
                    log.done,
                    self.eta(elapsed)
                );
                log.last_line = Instant::now();
            }
        }
    }
    fn skipped(&self, n: u64) {
        if let Ok(per_unit) = self.per_unit.lock() {
            let cost = (*per_unit * n as f64).round() as u64;
            self.skipped_ms
                .fetch_add(cost, std::sync::atomic::Ordering::Relaxed);
        }
        if let Some(log) = &self.log
            && let Ok(mut log) = log.lock()
        {
            log.skipped += n;
        }
        self.advance(n);
    }
    fn message(&self, text: &str) {
        self.bars.message(text);
    }
}

/// Runs `evtac reproduce` on Slurm: submits, follows, and returns when the report is written.
fn run_on_slurm(args: &Args, plan: &Plan) -> anyhow::Result<()> {
    let started = Instant::now();
    let absolute = |p: &PathBuf| std::path::absolute(p).with_context(|| p.display().to_string());
    let run = ReproduceJob {
        scale: args.scale_seed.scale,
        seed: args.scale_seed.seed,
        out: absolute(&args.out)?,
        data: args.data.as_ref().map(absolute).transpose()?,
        inputs: args.inputs.inputs(),
        noise_levels: args.noise_levels(),
        fusions: !args.no_fusions,
        label_noise_deg: args.label_noise_deg,
        datasets: args.datasets.map(|n| n as usize),
        repeats: args.repeats,
        repeat_split: !args.no_repeat_split,
        grid: args.grid,
        recheck: !args.no_recheck,
    };
    let (slurm, task) = (args.executor.slurm(), crate::cluster::task()?);
    let bars = Bars::default();
    slurm.reproduce(&run, plan, &task, &bars)?;
    bars.finish();
    println!("{}", run.out.join("report.md").display());
    eprintln!(
        "reproduced at scale {} on Slurm in {:.1} s (task logs in {})",
        args.scale_seed.scale,
        started.elapsed().as_secs_f64(),
        run.out.join("slurm").display()
    );
    Ok(())
}

/// Runs `evtac reproduce`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let started = Instant::now();
    let mut plan = Plan::for_scale(args.scale_seed.scale);
    if let Some(levels) = &args.noise_levels() {
        if let Some(bad) = levels.iter().find(|l| !(l.is_finite() && **l >= 0.0)) {
            anyhow::bail!("--noise-levels: {bad} is not a factor (finite and at least 0)");
        }
        plan.noise_levels = levels.clone();
    }
    plan.fusions = !args.no_fusions;
    plan.repeat_split = !args.no_repeat_split;
    if let Some(grid) = args.grid {
        plan = plan.with_grid(grid);
    }
    if args.no_recheck {
        (plan.recheck_top, plan.recheck_seeds) = (0, 0);
    }
    if let Some(sd) = args.label_noise_deg {
        anyhow::ensure!(
            sd.is_finite() && sd >= 0.0,
            "--label-noise-deg {sd}: give a standard deviation in degrees, 0 (no ablation) or more"
        );
        plan.label_noise_deg = (sd > 0.0).then_some(sd);
    }
    if let Some(n) = args.datasets {
        plan.datasets = n as usize;
    }
    anyhow::ensure!(
        args.repeats.is_none() || args.data.is_none(),
        "--repeats sets how the datasets are simulated; the --data datasets are already made \
         (simulate them with `evtac simulate --repeats N`)"
    );
    if args.executor.on_slurm()? {
        anyhow::ensure!(
            args.export_jobs.is_none(),
            "--export-jobs lists the jobs for a scheduler of your own; --executor slurm submits them itself: use one or the other"
        );
        return run_on_slurm(&args, &plan);
    }
    let pool = args.workers.pool()?;
    let bars = Bars::default();
    let sim_dir = args.out.join("data");
    let counts = match &args.data {
        Some(data) => TrialCounts::of_datasets(data),
        None => TrialCounts::of_simulation(
            &sim_dir,
            (args.scale_seed.scale, args.repeats),
            args.scale_seed.seed,
        ),
    };
    let bars = Overall::new(&bars, CostModel::new(&plan, counts));
    // Every invocation's stage times go to OUT/stage-times.csv: a resumed run's report
    // states what the whole reproduction took.
    let log = StageLog::open(&args.out)?;
    let data_dir = match &args.data {
        Some(d) => d.clone(),
        None => {
            let d = sim_dir;
            pool.install(|| {
                pipeline::simulate_all(
                    &d,
                    (args.scale_seed.scale, args.repeats),
                    args.scale_seed.seed,
                    &bars,
                )
            })?;
            let seconds = started.elapsed().as_secs_f64();
            bars.message(&format!("simulated datasets ready in {seconds:.1} s"));
            log.record("simulation", seconds)?;
            d
        }
    };
    let data = Datasets {
        inputs: args.inputs.inputs(),
        ..Datasets::in_dir(&data_dir)
    };
    anyhow::ensure!(
        data.exp1
            .join(evtac_events::layout::MANIFEST_FILE)
            .is_file(),
        "{} has no Experiment 1 dataset (exp1/trials.csv)",
        data_dir.display()
    );
    if let Some(file) = &args.export_jobs {
        let jobs = pipeline::export_jobs(&data, &plan, args.scale_seed.seed, &args.out)?;
        crate::outputs::write_text(file, &job::to_text(&jobs))?;
        bars.finish();
        let f = file.display();
        eprintln!(
            "wrote {} training jobs to {f}; run each with `evtac jobs run {f} --index K` (K from 0 \
             to `evtac jobs count {f}` - 1; `evtac jobs show {f}` lists them), then run this \
             command again without --export-jobs",
            jobs.len(),
        );
        return Ok(());
    }
    let results = pool.install(|| {
        pipeline::reproduce(&data, &plan, args.scale_seed.seed, &args.out, &log, &bars)
    })?;
    // The report is the last stage, timed like the others (its own time is in the log, not in
    // the report it writes).
    let report_started = Instant::now();
    evtac_report::write(&args.out, &results)?;
    let seconds = report_started.elapsed().as_secs_f64();
    bars.message(&format!("report: {seconds:.1} s"));
    log.record("report", seconds)?;
    bars.finish();
    println!("{}", args.out.join("report.md").display());
    for e in &results.exp1 {
        println!(
            "{:<9} test MAE {} deg (pitch {}, roll {})",
            e.name,
            e.test.overall.display(),
            e.test.pitch.display(),
            e.test.roll.display()
        );
    }
    eprintln!(
        "reproduced at scale {} in {:.1} s",
        args.scale_seed.scale,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::seconds_left;

    #[test]
    fn the_eta_learns_its_pace_from_work_done_here_only() {
        // Nothing timed yet, or only work an earlier run finished: no pace to go by.
        assert_eq!(seconds_left(5.0, 0, 0, 100), None);
        assert_eq!(seconds_left(5.0, 60, 60, 100), None);
        // 20 units in 10 s, 80 left: 40 s.
        assert_eq!(seconds_left(10.0, 20, 0, 100), Some(40.0));
        // A resumed run: 60 units were found done, 10 more took 10 s; 30 left take 30 s, not
        // the 4.3 s a pace over all 70 would promise.
        assert_eq!(seconds_left(10.0, 70, 60, 100), Some(30.0));
        assert_eq!(seconds_left(10.0, 100, 60, 100), Some(0.0));
    }
}
