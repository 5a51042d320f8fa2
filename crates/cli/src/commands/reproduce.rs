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
use evtac_experiments::stage::{CostModel, Stage, Timed, TrialCounts};
use evtac_experiments::stage_log::StageLog;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
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
    /// Also compare the representations the paper did not choose in Experiment 1: time
    /// surfaces, polarity histograms and voxel grids (tonic's), each tuned on its own grid and
    /// trained with every seed on every dataset, with their latency (the "beyond the paper"
    /// rows). Not trained in Experiment 2, at other noise or in the ablations.
    #[arg(long)]
    pub beyond: bool,
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
    /// The filter of the capture-filter ablation (Experiment 1's three paper representations
    /// again with every recording through it, paired by seed with the unfiltered runs) instead
    /// of the plan's (`background-activity=10ms`, the NeuroTac lab's capture filter, at
    /// `--scale small`; none at `tiny` and `paper`). A SPEC as `--filter` takes.
    #[arg(long, value_name = "SPEC", conflicts_with = "no_capture_filter")]
    pub capture_filter: Option<evtac_filters::FilterSpec>,
    /// Leave out the capture-filter ablation.
    #[arg(long)]
    pub no_capture_filter: bool,
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

    /// The reproduction these arguments ask for, as the job that stands for it (its paths as
    /// given).
    pub(crate) fn job(&self) -> ReproduceJob {
        ReproduceJob {
            scale: self.scale_seed.scale,
            seed: self.scale_seed.seed,
            out: self.out.clone(),
            data: self.data.clone(),
            inputs: self.inputs.inputs(),
            noise_levels: self.noise_levels(),
            fusions: !self.no_fusions,
            label_noise_deg: self.label_noise_deg,
            datasets: self.datasets.map(|n| n as usize),
            repeats: self.repeats,
            repeat_split: !self.no_repeat_split,
            grid: self.grid,
            recheck: !self.no_recheck,
            capture_filter: self.capture_filter.clone(),
            capture_ablation: !self.no_capture_filter,
            beyond: self.beyond,
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
fn run_on_slurm(args: &Args, job: &ReproduceJob, plan: &Plan) -> anyhow::Result<()> {
    let started = Instant::now();
    let absolute = |p: &PathBuf| std::path::absolute(p).with_context(|| p.display().to_string());
    let run = ReproduceJob {
        out: absolute(&job.out)?,
        data: job.data.as_ref().map(absolute).transpose()?,
        ..job.clone()
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
    let job = args.job();
    let plan = job.plan()?;
    if args.executor.on_slurm()? {
        anyhow::ensure!(
            args.export_jobs.is_none(),
            "--export-jobs lists the jobs for a scheduler of your own; --executor slurm submits them itself: use one or the other"
        );
        return run_on_slurm(&args, &job, &plan);
    }
    let pool = args.workers.pool()?;
    run_here(&job, &plan, args.export_jobs.as_deref(), &pool, started)
}

/// Runs the reproduction `job` on this machine with one worker thread: the last task of a Slurm
/// reproduction (`evtac jobs run`), whose task has one CPU.
pub fn run_job(job: &ReproduceJob) -> anyhow::Result<()> {
    let started = Instant::now();
    let plan = job.plan()?;
    let pool = crate::workers::Workers { jobs: Some(1) }.pool()?;
    run_here(job, &plan, None, &pool, started)
}

/// Runs `job` with `plan` on `pool`'s threads (or, with `export_jobs`, writes its ready training
/// jobs to that file and stops): simulation when no datasets are given, the experiments, the
/// report. `started` is when the command started, for the times it reports.
fn run_here(
    job: &ReproduceJob,
    plan: &Plan,
    export_jobs: Option<&Path>,
    pool: &rayon::ThreadPool,
    started: Instant,
) -> anyhow::Result<()> {
    let bars = Bars::default();
    let sim_dir = job.out.join("data");
    let counts = match &job.data {
        Some(data) => TrialCounts::of_datasets(data),
        None => TrialCounts::of_simulation(&sim_dir, &job.simulation()),
    };
    let bars = Overall::new(&bars, CostModel::new(plan, counts));
    // Every invocation's stage times go to OUT/stage-times.csv: a resumed run's report
    // states what the whole reproduction took.
    let log = StageLog::open(&job.out)?;
    let data_dir = match &job.data {
        Some(d) => d.clone(),
        None => {
            let d = sim_dir;
            pool.install(|| pipeline::simulate_all(&d, &job.simulation(), &bars))?;
            let seconds = started.elapsed().as_secs_f64();
            bars.message(&format!("simulated datasets ready in {seconds:.1} s"));
            log.record(Timed::Simulation, seconds)?;
            d
        }
    };
    let data = Datasets {
        inputs: job.inputs.clone(),
        ..Datasets::in_dir(&data_dir)
    };
    anyhow::ensure!(
        data.exp1
            .join(evtac_events::layout::MANIFEST_FILE)
            .is_file(),
        "{} has no Experiment 1 dataset (exp1/trials.csv)",
        data_dir.display()
    );
    if let Some(file) = export_jobs {
        let jobs = pipeline::export_jobs(&data, plan, job.seed, &job.out)?;
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
    let results =
        pool.install(|| pipeline::reproduce(&data, plan, job.seed, &job.out, &log, &bars))?;
    // The report is the last stage, timed like the others (its own time is in the log, not in
    // the report it writes).
    let report_started = Instant::now();
    evtac_report::write(&job.out, &results)?;
    let seconds = report_started.elapsed().as_secs_f64();
    bars.message(&format!("report: {seconds:.1} s"));
    log.record(Timed::Report, seconds)?;
    bars.finish();
    println!("{}", job.out.join("report.md").display());
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
        job.scale,
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
