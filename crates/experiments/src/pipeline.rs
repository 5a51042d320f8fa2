//! The whole protocol on existing datasets: labels, splits, tuning, Experiments 1-3, latency and
//! the report. Every stage resumes from finished jobs; [`export_jobs`] lists the training jobs
//! that are ready to run as `evtac train` command lines for an external scheduler.

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::exp3::Axis;
use crate::job::{Job, Simulation};
use crate::jobs;
use crate::plan::Plan;
use crate::progress::Progress;
use crate::results::{
    CaptureFilter, DatasetSeedPoint, ExampleTrial, Exp1Repr, Exp2Cell, Exp2Setting, Exp3Point,
    LabelCheck, LabelNoise, LatencyCell, NoisePoint, PacedLatencyCell, RepeatSplit, ReprExample,
    Results, RunInfo, SensorView, Tuning,
};
use crate::splits::{Split, Splits};
use crate::stage::{Stage, Timed};
use crate::stage_log::StageLog;
use crate::training;
use crate::tuning::{self, Kind};
use crate::{
    capture_filter, choices, dataset_seeds, examples, exp1, exp2, exp3, label_check, label_noise,
    latency, noise, repeat_split, repr_example, sensor_view,
};
use evtac_events::manifest::TrialMeta;
use evtac_import::inputs::Inputs;
use evtac_learn::Model;
use evtac_repr::{ReprConfig, ReprKind};
use evtac_sim::{Protocol, SimParams};
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use crate::error::Error;

/// The datasets of a reproduction (Experiment 1 is required).
#[derive(Debug, Clone, PartialEq)]
pub struct Datasets {
    /// Continuous motion (Experiment 1).
    pub exp1: PathBuf,
    /// Motion with a stop (Experiment 2).
    pub exp2: Option<PathBuf>,
    /// Speed-wise (Experiment 3).
    pub exp3_speed: Option<PathBuf>,
    /// Depth-wise (Experiment 3).
    pub exp3_depth: Option<PathBuf>,
    /// The calibration and mask every dataset is opened with.
    pub inputs: Inputs,
}

impl Datasets {
    /// The datasets under `dir` as `evtac simulate` lays them out (`exp1/`, `exp2/`,
    /// `exp3-speed/`, `exp3-depth/`); absent optional ones are `None`. Each dataset's
    /// calibration and mask come from its files ([`Inputs::FROM_FILES`]).
    pub fn in_dir(dir: &Path) -> Datasets {
        let opt = |name: &str| {
            let p = dir.join(name);
            p.join(evtac_events::layout::MANIFEST_FILE)
                .is_file()
                .then_some(p)
        };
        Datasets {
            exp1: dir.join(evtac_sim::Protocol::Exp1.name()),
            exp2: opt(evtac_sim::Protocol::Exp2.name()),
            exp3_speed: opt(evtac_sim::Protocol::Exp3Speed.name()),
            exp3_depth: opt(evtac_sim::Protocol::Exp3Depth.name()),
            inputs: Inputs::FROM_FILES,
        }
    }
}

/// Simulates the dataset of every protocol ([`crate::stage::PROTOCOLS`]) as `simulation` says
/// into `dir`, laid out as [`Datasets::in_dir`] reads them. A dataset whose folder is marked
/// done is kept, so an interrupted simulation resumes.
pub fn simulate_all(
    dir: &Path,
    simulation: &Simulation,
    progress: &dyn Progress,
) -> Result<(), Error> {
    for protocol in crate::stage::PROTOCOLS {
        let job = simulation.job(protocol, dir);
        if jobs::is_done(&job.out) {
            continue;
        }
        progress.stage(Stage::Simulating(protocol), job.trials() as u64);
        crate::simulation::run(&job, || progress.advance(1))?;
    }
    Ok(())
}

/// This invocation's stages as they finish: kept for the results, shown, and appended to the
/// output folder's [`StageLog`].
struct Stages<'a> {
    list: Vec<(String, f64)>,
    started: Instant,
    progress: &'a dyn Progress,
    log: &'a StageLog,
}

impl Stages<'_> {
    fn done(&mut self, stage: Timed) -> Result<(), Error> {
        let s = self.started.elapsed().as_secs_f64();
        self.list.push((stage.name().to_string(), s));
        self.progress.message(&format!("{stage}: {s:.1} s"));
        self.log.record(stage, s)?;
        self.started = Instant::now();
        Ok(())
    }
}

/// Runs the whole protocol on `data`, with its models and datasets in `out`, and returns what
/// it measured (`evtac_report::write` turns that into the report). Each stage's time is
/// appended to `log` (the output folder's, opened by this invocation) as it finishes, and is in
/// the results (this invocation's stages, and every invocation's from the log).
pub fn reproduce(
    data: &Datasets,
    plan: &Plan,
    seed: u64,
    out: &Path,
    log: &StageLog,
    progress: &dyn Progress,
) -> Result<Results, Error> {
    evtac_learn::flush_denormals();
    let mut stages = Stages {
        list: Vec::new(),
        started: Instant::now(),
        progress,
        log,
    };
    let models = out.join("models");
    let ds1 = Dataset::open(&data.exp1, data.inputs.clone())?;
    let splits1 = ds1.splits(seed)?;
    let cache1 = FeatureCache::new(&ds1)?;
    let mut datasets = vec![(Protocol::Exp1, ds1.manifest.trials.len())];

    let run = RunContext {
        plan,
        seed,
        models: &models,
        progress,
    };
    let on1 = on_exp1(&cache1, &splits1, &run, out, &mut stages)?;
    let exp1_sim = ds1.simulator()?;
    let on2 = match &data.exp2 {
        Some(dir) => {
            // Experiment 2 compares the binary kinds (the paper's and the fusions).
            let binary: Vec<ReprConfig> = on1
                .reprs
                .iter()
                .filter(|c| c.dense_part().is_none())
                .copied()
                .collect();
            let on2 = on_exp2(dir, data.inputs.clone(), &binary, &run)?;
            datasets.push((Protocol::Exp2, on2.trials));
            stages.done(Timed::Exp2)?;
            Some(on2)
        }
        None => None,
    };
    let exp1_models = exp1_models(&on1.reprs, &run)?;
    let (e3s, e3d) = on_exp3(data, &ds1, &exp1_models, progress, &mut datasets)?;
    if data.exp3_speed.is_some() || data.exp3_depth.is_some() {
        stages.done(Timed::Exp3)?;
    }
    let overlays = examples::overlays(&cache1, on1.reprs[0], on1.reprs[1])?;
    // The paper's Fig. 2, the sensor's camera view and the latency study, on the test trials.
    let test = ds1.trials(splits1.get(Split::Test))?;
    let (repr_example, sensor) = fig2_and_sensor(&cache1, &test, &on1.reprs)?;
    let (lat, paced) = latencies(&ds1, &test, &exp1_models, plan, progress)?;
    stages.done(Timed::Latency)?;

    let (e2, example, exp2_sim, labels) = match on2 {
        Some(on2) => (on2.cells, on2.example, on2.sim, on2.labels),
        None => (Vec::new(), None, None, None),
    };
    let mut results = Results {
        run: RunInfo {
            scale: plan.scale,
            seed,
            plan: plan.clone(),
            stage_seconds: Vec::new(),
            stage_history: Vec::new(),
            datasets,
            inputs: Some(data.inputs.clone()),
        },
        tuning: [vec![on1.st, on1.dt], on1.beyond].concat(),
        exp1: on1.e1,
        exp2: e2,
        exp3_speed: e3s,
        exp3_depth: e3d,
        latency: lat,
        noise: on1.noise,
        label_noise: on1.label_noise,
        capture_filter: on1.capture_filter,
        example,
        choices: choices::of_run(
            plan,
            seed,
            exp1_sim.as_ref().map(|s| &s.params),
            exp2_sim.as_ref(),
        ),
        labels,
        overlays,
        repr_example,
        sensor_kind: sensor.as_ref().map(|v| v.kind),
        sensor,
        dataset_seeds: on1.dataset_seeds,
        repeat_split: on1.repeat_split,
        paced_latency: paced,
    };
    results.run.stage_seconds = stages.list;
    results.run.stage_history = log.records();
    Ok(results)
}

/// What the stages on Experiment 1's dataset measured: the tunings, the representations they
/// chose, Experiment 1 and the studies that train it again (other noise, other datasets,
/// repeats kept together, noisy labels).
struct OnExp1 {
    st: Tuning,
    dt: Tuning,
    /// The tunings of the kinds the paper did not choose ([`Plan::beyond`]).
    beyond: Vec<Tuning>,
    reprs: Vec<ReprConfig>,
    e1: Vec<Exp1Repr>,
    noise: Vec<NoisePoint>,
    dataset_seeds: Vec<DatasetSeedPoint>,
    repeat_split: Option<RepeatSplit>,
    label_noise: Option<LabelNoise>,
    capture_filter: Option<CaptureFilter>,
}

/// Tuning, Experiment 1 and the studies built on it, each stage timed in `stages` as it
/// finishes (a study the plan leaves out is no stage).
fn on_exp1(
    cache1: &FeatureCache<'_>,
    splits1: &Splits,
    run: &RunContext<'_>,
    out: &Path,
    stages: &mut Stages<'_>,
) -> Result<OnExp1, Error> {
    let ds1 = cache1.dataset();
    let st = tuning::tune(cache1, splits1, Kind::Static, run)?;
    stages.done(Timed::TuningStatic)?;
    let dt = tuning::tune(cache1, splits1, Kind::Dynamic, run)?;
    stages.done(Timed::TuningDynamic)?;
    let beyond = tuning::tune_beyond(cache1, splits1, run)?;
    if !beyond.is_empty() {
        stages.done(Timed::TuningBeyond)?;
    }
    let binary = exp1::of_plan(run.plan, st.chosen_config, dt.chosen_config);
    // Experiment 1 compares the kinds beyond the paper too; the studies that train it again
    // at other noise or in the ablations keep to the binary ones.
    let mut reprs = binary.clone();
    reprs.extend(beyond.iter().map(|t| t.chosen_config));

    let e1 = exp1::run(cache1, splits1, &reprs, run)?;
    stages.done(Timed::Exp1)?;
    let noise = noise::run(ds1, &e1, &binary, run, out)?;
    if !noise.is_empty() {
        stages.done(Timed::Exp1OtherNoise)?;
    }
    let dataset_seeds = dataset_seeds::run(ds1, &e1, &reprs, run, out)?;
    if !dataset_seeds.is_empty() {
        stages.done(Timed::Exp1OtherDatasets)?;
    }
    let repeat_split = repeat_split::run(cache1, &reprs, &e1, run)?;
    if repeat_split.is_some() {
        stages.done(Timed::RepeatsTogether)?;
    }
    let label_noise = label_noise::run(cache1, splits1, &reprs, &e1, run)?;
    if label_noise.is_some() {
        stages.done(Timed::LabelNoise)?;
    }
    let capture_filter = capture_filter::run(ds1, splits1, &reprs, &e1, run)?;
    if capture_filter.is_some() {
        stages.done(Timed::CaptureFilter)?;
    }
    Ok(OnExp1 {
        st,
        dt,
        beyond,
        reprs,
        e1,
        noise,
        dataset_seeds,
        repeat_split,
        label_noise,
        capture_filter,
    })
}

/// What the stage on Experiment 2's dataset measured, and what the report says of that dataset.
struct OnExp2 {
    /// Experiment 2.
    cells: Vec<Exp2Cell>,
    /// The example trial of the report's figure.
    example: Option<ExampleTrial>,
    /// The dataset's simulator parameters (`None` for recordings).
    sim: Option<SimParams>,
    /// Its labels against the commanded stop angles.
    labels: Option<LabelCheck>,
    /// Its trials.
    trials: usize,
}

/// Experiment 2 on the dataset in `dir`, its label check, and the example trial: the first test
/// trial with a stop, with the motion + stop models.
fn on_exp2(
    dir: &Path,
    inputs: Inputs,
    reprs: &[ReprConfig],
    run: &RunContext<'_>,
) -> Result<OnExp2, Error> {
    let ds2 = Dataset::open(dir, inputs)?;
    let labels = Some(label_check::of_dataset(&ds2)?);
    let sim = ds2.simulator()?.map(|s| s.params);
    let trials = ds2.manifest.trials.len();
    let splits2 = ds2.splits(run.seed)?;
    let cache2 = FeatureCache::new(&ds2)?;
    let cells = exp2::run(&cache2, &splits2, reprs, run)?;
    let test = ds2.trials(splits2.get(Split::Test))?;
    let mut example = None;
    if let Some(meta) = test.iter().find(|t| t.stop_start_us.is_some()) {
        let loaded: Vec<(ReprKind, Model)> = reprs
            .iter()
            .map(|config| {
                let kind = config.kind();
                let setting = Exp2Setting::PauseMotionStop;
                training::load_model(&exp2::model_dir(run.models, setting, kind, run.seed))
                    .map(|m| (kind, m))
            })
            .collect::<Result<_, _>>()?;
        let refs: Vec<(ReprKind, &Model)> = loaded.iter().map(|(n, m)| (*n, m)).collect();
        example = Some(examples::example_trial(&cache2, meta, &refs)?);
    }
    Ok(OnExp2 {
        cells,
        example,
        sim,
        labels,
        trials,
    })
}

/// Experiment 1's models of every representation in `reprs`, every seed of the plan.
fn exp1_models(
    reprs: &[ReprConfig],
    run: &RunContext<'_>,
) -> Result<Vec<(ReprKind, Vec<Model>)>, Error> {
    Ok(reprs
        .iter()
        .map(|config| {
            let kind = config.kind();
            exp1::models(run.models, kind, run.seed, run.plan.seeds).map(|m| (kind, m))
        })
        .collect::<Result<_, _>>()?)
}

/// Experiment 3 by speed and by depth, on those of its datasets `data` has (each one's trials
/// added to `datasets`), with Experiment 1's models: `ds1`'s levels are the ones seen in training.
fn on_exp3(
    data: &Datasets,
    ds1: &Dataset,
    exp1_models: &[(ReprKind, Vec<Model>)],
    progress: &dyn Progress,
    datasets: &mut Vec<(Protocol, usize)>,
) -> Result<(Vec<Exp3Point>, Vec<Exp3Point>), Error> {
    let speeds: Vec<f64> = ds1.manifest.trials.iter().map(|t| t.speed_deg_s).collect();
    let depths: Vec<f64> = ds1.manifest.trials.iter().map(|t| t.depth_mm).collect();
    let mut e3s = Vec::new();
    let mut e3d = Vec::new();
    for (dir, axis, values) in [
        (&data.exp3_speed, Axis::Speed, &speeds),
        (&data.exp3_depth, Axis::Depth, &depths),
    ] {
        let Some(dir) = dir else { continue };
        let ds = Dataset::open(dir, data.inputs.clone())?;
        datasets.push((
            match axis {
                Axis::Speed => Protocol::Exp3Speed,
                Axis::Depth => Protocol::Exp3Depth,
            },
            ds.manifest.trials.len(),
        ));
        let cache = FeatureCache::new(&ds)?;
        let points = exp3::run(&cache, axis, exp1_models, values, progress)?;
        match axis {
            Axis::Speed => e3s = points,
            Axis::Depth => e3d = points,
        }
    }
    Ok((e3s, e3d))
}

/// The paper's Fig. 2 and the sensor's camera view, both on the first of Experiment 1's `test`
/// trials (none without one).
fn fig2_and_sensor(
    cache1: &FeatureCache<'_>,
    test: &[&TrialMeta],
    reprs: &[ReprConfig],
) -> Result<(Option<ReprExample>, Option<SensorView>), Error> {
    let Some(meta) = test.first() else {
        return Ok((None, None));
    };
    // The paper's three frames (the fusions' are the static and dynamic ones).
    let paper_reprs: Vec<_> = reprs
        .iter()
        .filter(|c| c.frames() == 1 && c.dense_part().is_none())
        .copied()
        .collect();
    let example = repr_example::example(cache1, meta, &paper_reprs)?;
    // The tilt at the example's sample (commanded: constant speed from onset).
    let theta = example.as_ref().map_or(meta.total_deg / 2.0, |e| {
        (meta.speed_deg_s * e.t_ms / 1000.0).min(meta.total_deg)
    });
    let sensor = sensor_view::view(cache1.dataset(), meta, theta)?;
    Ok((example, Some(sensor)))
}

/// The latency study: the first model of each representation on the first of Experiment 1's
/// `test` trials, alone, then end to end at recorded pace.
fn latencies(
    ds1: &Dataset,
    test: &[&TrialMeta],
    exp1_models: &[(ReprKind, Vec<Model>)],
    plan: &Plan,
    progress: &dyn Progress,
) -> Result<(Vec<LatencyCell>, Vec<PacedLatencyCell>), Error> {
    let test = &test[..test.len().min(plan.latency_trials)];
    progress.stage(
        Stage::Latency,
        (exp1_models.len() * plan.latency_intervals_ms.len()) as u64,
    );
    let mut lat = Vec::new();
    for (name, ms) in exp1_models {
        let Some(model) = ms.first() else { continue };
        for &iv in &plan.latency_intervals_ms {
            lat.push(latency::measure(ds1, test, *name, model, iv)?);
            progress.advance(1);
        }
    }
    // Then end to end, queueing included: a few of these trials replayed at recorded pace,
    // idle and under load (on the wall clock: its progress is messages, not units).
    let firsts: Vec<(ReprKind, &Model)> = exp1_models
        .iter()
        .filter_map(|(name, ms)| ms.first().map(|m| (*name, m)))
        .collect();
    let paced = crate::paced_latency::measure(ds1, test, &firsts, plan.scale, progress)?;
    Ok((lat, paced))
}

/// The kinds `plan` tunes: static and dynamic, then those beyond the paper it compares.
fn tuned_kinds(plan: &Plan) -> Vec<Kind> {
    let beyond = plan.beyond_kinds().iter().filter_map(|&r| Kind::of_repr(r));
    [Kind::Static, Kind::Dynamic]
        .into_iter()
        .chain(beyond)
        .collect()
}

/// Whether every tuning run of every tuned representation is finished in `out`.
pub fn tunings_finished(plan: &Plan, out: &Path) -> bool {
    let models = out.join("models");
    tuned_kinds(plan).into_iter().all(|kind| {
        tuning::grid(plan, kind)
            .iter()
            .all(|p| exp1::finished(&tuning::run_dir(&models, kind, &p.config)))
    })
}

/// The training jobs that can run now and are not finished: the tuning runs, and once both
/// tunings are finished, the recheck of their best settings, Experiments 1 and 2 and the
/// label-noise ablation. Run them (in any order, in parallel, e.g. with
/// `evtac jobs run`), then run the reproduction again: it resumes from the finished jobs.
/// Makes the splits (and needs the Experiment 1 dataset).
pub fn export_jobs(data: &Datasets, plan: &Plan, seed: u64, out: &Path) -> Result<Vec<Job>, Error> {
    let models = out.join("models");
    let ds1 = Dataset::open(&data.exp1, data.inputs.clone())?;
    ds1.splits(seed)?;
    let mut jobs = Vec::new();
    let mut tuned = Vec::new();
    let mut rechecks = Vec::new();
    for kind in tuned_kinds(plan) {
        let mut best: Option<(f64, ReprConfig)> = None;
        let mut ranked = Vec::new();
        let mut all_done = true;
        for p in tuning::grid(plan, kind) {
            let job = tuning::job(&ds1, kind, p.config, plan, seed, &models);
            if exp1::finished(&job.out) {
                if let Ok(b) = evtac_learn::ModelBundle::load(&job.out) {
                    let v = b.config.metrics.validation.overall;
                    if best.is_none_or(|(bv, _)| v < bv) {
                        best = Some((v, p.config));
                    }
                    ranked.push((v, p));
                }
            } else {
                all_done = false;
                jobs.push(Job::Train(job));
            }
        }
        if all_done && let Some((_, c)) = best {
            tuned.push((kind, c));
            let top = tuning::top(&ranked, plan);
            rechecks.extend(tuning::recheck_jobs(&ds1, kind, &top, plan, seed, &models));
        }
    }
    let chosen = |kind: Kind| tuned.iter().find(|(k, _)| *k == kind).map(|&(_, c)| c);
    // Experiment 1 on the kinds beyond the paper once every one of them is tuned.
    let beyond: Vec<ReprConfig> = tuned
        .iter()
        .filter(|(k, _)| !matches!(k, Kind::Static | Kind::Dynamic))
        .map(|&(_, c)| c)
        .collect();
    let beyond_tuned = beyond.len() == plan.beyond_kinds().len();
    if let (Some(s), Some(d)) = (chosen(Kind::Static), chosen(Kind::Dynamic)) {
        // The recheck of the best settings runs in the same round as Experiments 1 and 2, once
        // both grids are done, so a round never mixes the grids with what follows them.
        jobs.extend(
            rechecks
                .into_iter()
                .filter(|j| !exp1::finished(&j.out))
                .map(Job::Train),
        );
        let reprs = exp1::of_plan(plan, s, d);
        let mut train = exp1::jobs(&ds1, &reprs, plan, seed, &models);
        if beyond_tuned {
            train.extend(exp1::jobs(&ds1, &beyond, plan, seed, &models));
        }
        train.extend(label_noise::jobs(&ds1, &reprs, plan, seed, &models));
        train.extend(capture_filter::jobs((&ds1, &reprs), plan, seed, &models)?);
        if let Some(d2) = &data.exp2 {
            let ds2 = Dataset::open(d2, data.inputs.clone())?;
            ds2.splits(seed)?;
            train.extend(exp2::jobs(&ds2, &reprs, plan, seed, &models));
        }
        jobs.extend(
            train
                .into_iter()
                .filter(|j| !exp1::finished(&j.out))
                .map(Job::Train),
        );
    }
    Ok(jobs)
}
