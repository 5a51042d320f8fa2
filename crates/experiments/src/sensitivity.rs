//! Which of the paper's conclusions survive the simulator's unmeasured parameters: Experiment 1,
//! tuning included, on a dataset simulated with one parameter at [`FACTORS`] times its default,
//! one parameter at a time, beside the same on the defaults (the baseline).
//!
//! Nothing in the simulator is fitted to a NeuroTac (`docs/simulator.md`): contact mechanics,
//! pin layout, the DVS pixel model and the IMU's noise are assumed or v2e's generic defaults. A
//! result on simulated data is a result about the method on this simulator, so each point asks
//! whether the paper's conclusions still hold on a simulator that differs in one of them
//! ([`Conclusions`]):
//!
//! - **static best**: static's test MAE (mean over seeds) is below dynamic's and combined's;
//! - **OR not better than static**: combined's is not below static's;
//! - **dynamic worse at 2 deg/s**: on the test trials, dynamic's error at the slowest speed
//!   rises above its mean over the other speeds by more than static's does (the paper: "larger
//!   errors at 2 deg/s, the increase more pronounced for the dynamic representation");
//! - **dynamic worse at shallow depth**: the same at the shallowest depth.
//!
//! The last two read Experiment 1's own test trials by level (a few per level at small scale,
//! so they are the noisiest), not Experiment 3's datasets, which would mean simulating three
//! datasets per point instead of one.
//!
//! Each point lives in its own folder, `OUT/points/<parameter>/x<factor>/` (`data/`, the
//! dataset, marked done when simulated; `models/`, tuning and Experiment 1 runs, each marked
//! done), so an interrupted study resumes where it stopped. The same plan, master seed and
//! dataset seed serve every point: the trials, splits, camera and training seeds are the
//! baseline's, and only the parameter differs.

use crate::cache::FeatureCache;
use crate::context::RunContext;
use crate::dataset::Dataset;
use crate::error::Error;
use crate::exp1;
use crate::exp3::{self, Axis};
use crate::job::SensitivityPointJob;
use crate::parameters::Slot;
use crate::progress::Progress;
use crate::results::{Exp1Repr, Exp3Point, MaeStats, Tuning};
use crate::splits::Split;
use crate::stage::{FeatureSet, Stage};
use crate::tuning::{self, Kind};
use crate::variant;
use evtac_events::IoError;
use evtac_events::output::write_atomic;
use evtac_import::inputs::Inputs;
use evtac_learn::Model;
use evtac_repr::ReprKind;
use evtac_sim::{Protocol, SimParams};
use std::path::{Path, PathBuf};

pub use crate::error::PerturbError;
pub use crate::parameters::{PARAMETERS, Parameter, names, parameter};
pub use crate::results::{BASELINE, Conclusions, Point, Rise, Study, Tuned, Varied};

/// The factors every parameter is scaled by.
pub const FACTORS: [f64; 2] = [0.5, 1.5];

/// The simulator parameters of the point (`varied`, `factor`): the defaults for the baseline,
/// else the defaults with that parameter scaled.
pub fn params_of(varied: &Varied, factor: f64) -> Result<SimParams, PerturbError> {
    let defaults = SimParams::default();
    let name = match varied {
        Varied::Baseline => return Ok(defaults),
        Varied::Parameter(name) => name,
    };
    let p = parameter(name).ok_or_else(|| PerturbError::Unknown { name: name.clone() })?;
    perturbed(&defaults, &p, factor)
}

/// The plan every point runs: the scale's with the paper's grids (the committed study's), the
/// paper's three representations only, no noise study, no label-noise ablation, no other
/// simulation seeds, no repeats-together split and no recheck of the best settings (each point
/// is one Experiment 1).
pub fn plan(scale: evtac_sim::Scale) -> crate::plan::Plan {
    crate::plan::Plan {
        fusions: false,
        noise_levels: Vec::new(),
        label_noise_deg: None,
        datasets: 1,
        repeat_split: false,
        recheck_top: 0,
        recheck_seeds: 0,
        ..crate::plan::Plan::for_scale(scale).with_grid(crate::plan::Grid::Paper)
    }
}

/// The study's points in order: the baseline, then every parameter at every factor.
pub fn points(parameters: &[Parameter], factors: &[f64]) -> Vec<(Varied, f64)> {
    let mut out = vec![(Varied::Baseline, 1.0)];
    for p in parameters {
        out.extend(factors.iter().map(|&f| (Varied::from(p.name), f)));
    }
    out
}

/// `params` with `parameter`'s fields multiplied by `factor`; integers (pin rings, hot pixels)
/// are rounded to the nearest.
pub fn perturbed(
    params: &SimParams,
    parameter: &Parameter,
    factor: f64,
) -> Result<SimParams, PerturbError> {
    let mut out = params.clone();
    for field in parameter.fields {
        match crate::parameters::slot(&mut out, field) {
            Some(Slot::Real(x)) => *x *= factor,
            Some(Slot::Count(n)) => {
                let scaled = (f64::from(*n) * factor).round() as u64;
                *n = u32::try_from(scaled).map_err(|e| PerturbError::Invalid {
                    field: parameter.fields.join(", "),
                    message: e.to_string(),
                })?;
            }
            None => {
                return Err(PerturbError::NotANumber {
                    field: (*field).to_string(),
                });
            }
        }
    }
    Ok(out)
}

/// What tuning chose, as a point keeps it.
fn tuned(t: &Tuning) -> Tuned {
    Tuned {
        time_ms: t.chosen_time_ms,
        threshold: t.chosen_threshold,
    }
}

/// The folder of one point under the study's output folder.
pub fn point_dir(out: &Path, varied: &Varied, factor: f64) -> PathBuf {
    out.join("points")
        .join(varied.name())
        .join(format!("x{factor}"))
}

/// Static's and dynamic's rise at the lowest level of `points`.
fn rise(points: &[Exp3Point]) -> Rise {
    let mut values: Vec<f64> = points.iter().map(|p| p.value).collect();
    values.sort_by(f64::total_cmp);
    values.dedup();
    let level = values.first().copied().unwrap_or(f64::INFINITY);
    let of = |kind: ReprKind| {
        let at: Vec<&Exp3Point> = points.iter().filter(|p| p.name == kind).collect();
        let extreme = at
            .iter()
            .filter(|p| p.value == level)
            .map(|p| p.stats.overall.mean)
            .sum::<f64>();
        let others: Vec<f64> = at
            .iter()
            .filter(|p| p.value != level)
            .map(|p| p.stats.overall.mean)
            .collect();
        if others.is_empty() {
            0.0
        } else {
            extreme - others.iter().sum::<f64>() / others.len() as f64
        }
    };
    Rise {
        level,
        levels: values.len(),
        static_deg: of(ReprKind::Static),
        dynamic_deg: of(ReprKind::Dynamic),
    }
}

/// The file a finished point's results are kept in, in its folder.
pub const POINT_FILE: &str = "point.json";

/// One point: simulate, tune, Experiment 1 with the paper's three representations, the test
/// trials by speed and by depth, the conclusions. `dir` is the point's folder. A finished point
/// is read back from its [`POINT_FILE`], beside a copy of its dataset's `simulator.json`; unless
/// `keep_data`, finishing a point removes its dataset and feature cache (about 1.1 GB at small
/// scale, of which its models need none), so that a study of 39 points needs the disk of one
/// dataset at a time.
pub fn point(
    (parameter, factor): (&Varied, f64),
    params: &SimParams,
    dir: &Path,
    keep_data: bool,
    run: &RunContext<'_>,
) -> Result<Point, Error> {
    let file = dir.join(POINT_FILE);
    if crate::jobs::is_done(dir)
        && let Ok(text) = std::fs::read_to_string(&file)
        && let Ok(point) = serde_json::from_str::<Point>(&text)
    {
        return Ok(point);
    }
    let point = measure(parameter, factor, params, dir, run)?;
    let json = serde_json::to_string_pretty(&point)
        .map_err(IoError::at(&file))
        .map_err(crate::jobs::Error::from)?;
    // The point's folder exists: its dataset and models are in it.
    write_atomic(&file, json.as_bytes())
        .map_err(IoError::at(&file))
        .map_err(crate::jobs::Error::from)?;
    // What made the point stays beside its results, with or without its dataset.
    let data = dir.join("data");
    let made_by = dir.join(evtac_events::layout::SIMULATOR_FILE);
    std::fs::copy(data.join(evtac_events::layout::SIMULATOR_FILE), &made_by)
        .map_err(IoError::at(&made_by))
        .map_err(crate::jobs::Error::from)?;
    // The marker says the point as a whole is finished (its results and what made them are
    // written): what a Slurm run submits again is what has none, and what is read back is what
    // has one. The dataset goes after it, so a point is never left without both.
    crate::jobs::mark_done(dir)?;
    if !keep_data {
        std::fs::remove_dir_all(&data)
            .map_err(IoError::at(&data))
            .map_err(crate::jobs::Error::from)?;
    }
    Ok(point)
}

/// [`point`]'s measurement, every part of it resuming on its own.
fn measure(
    parameter: &Varied,
    factor: f64,
    params: &SimParams,
    dir: &Path,
    run: &RunContext<'_>,
) -> Result<Point, Error> {
    let data = dir.join("data");
    let config = evtac_sim::DatasetConfig {
        params: params.clone(),
        ..evtac_sim::DatasetConfig::new(Protocol::Exp1, run.plan.scale, run.seed)
    };
    variant::simulate(
        &config,
        &data,
        Stage::Simulating(Protocol::Exp1),
        run.progress,
    )?;
    let ds = Dataset::open(&data, Inputs::FROM_FILES)?;
    let splits = ds.splits(run.seed)?;
    let cache = FeatureCache::new(&ds)?;
    let models = dir.join("models");
    let at = RunContext {
        models: &models,
        ..*run
    };
    let st = tuning::tune(&cache, &splits, Kind::Static, &at)?;
    let dt = tuning::tune(&cache, &splits, Kind::Dynamic, &at)?;
    let reprs = exp1::paper_representations(st.chosen_config, dt.chosen_config);
    let e1 = exp1::run(&cache, &splits, &reprs, &at)?;
    let stats = |kind: ReprKind| -> Result<MaeStats, Error> {
        e1.iter()
            .find(|r| r.name == kind)
            .map(|r: &Exp1Repr| r.test)
            .ok_or(Error::Missing {
                what: "a representation in Experiment 1's results",
            })
    };
    let test = [
        stats(ReprKind::Static)?,
        stats(ReprKind::Dynamic)?,
        stats(ReprKind::Combined)?,
    ];
    // Static and dynamic by level on the test trials.
    let loaded: Vec<(ReprKind, Vec<Model>)> = [ReprKind::Static, ReprKind::Dynamic]
        .into_iter()
        .map(|kind| exp1::models(&models, kind, run.seed, run.plan.seeds).map(|m| (kind, m)))
        .collect::<Result<_, _>>()?;
    let trials = ds.trials(splits.get(Split::Test))?;
    let mut rises = Vec::new();
    for axis in [Axis::Speed, Axis::Depth] {
        let levels = exp3::by_level(
            &cache,
            &trials,
            axis,
            &loaded,
            &[],
            FeatureSet::Exp1,
            run.progress,
        )?;
        rises.push(rise(&levels));
    }
    let (slow, shallow) = (rises[0], rises[1]);
    let mean = |s: &MaeStats| s.overall.mean;
    let [st_mae, dy_mae, co_mae] = [mean(&test[0]), mean(&test[1]), mean(&test[2])];
    Ok(Point {
        parameter: parameter.clone(),
        factor,
        tuned: [tuned(&st), tuned(&dt)],
        test,
        gap_deg: dy_mae - st_mae,
        slow,
        shallow,
        conclusions: Conclusions {
            static_best: st_mae < dy_mae && st_mae < co_mae,
            or_not_better: co_mae >= st_mae,
            dynamic_worse_slow: (slow.levels > 1).then_some(slow.dynamic_deg > slow.static_deg),
            dynamic_worse_shallow: (shallow.levels > 1)
                .then_some(shallow.dynamic_deg > shallow.static_deg),
        },
    })
}

/// Runs the point `job` describes (a Slurm task of `evtac sensitivity`, or `--point`), resuming
/// what is finished, reporting to `progress`: [`point`] with the study's [`plan`] and the
/// parameters of [`params_of`].
pub fn run_point(job: &SensitivityPointJob, progress: &dyn Progress) -> Result<(), Error> {
    evtac_learn::flush_denormals();
    let plan = plan(job.scale);
    let params = params_of(&job.parameter, job.factor)?;
    let models = job.out.join("models");
    let run = RunContext {
        plan: &plan,
        seed: job.seed,
        models: &models,
        progress,
    };
    let at = (&job.parameter, job.factor);
    point(at, &params, &job.out, job.keep_data, &run)?;
    Ok(())
}

/// The study: the baseline, then every parameter of `parameters` at every factor of `factors`
/// ([`points`]), under `out`. `run.models` is unused (each point has its own); `run.plan`
/// ([`plan`]) sizes the datasets, `run.seed` seeds the datasets, splits and training. Points
/// already finished (by an earlier run, or by Slurm tasks) are read back; `keep_data` as in
/// [`point`].
pub fn run(
    parameters: &[Parameter],
    factors: &[f64],
    out: &Path,
    keep_data: bool,
    run: &RunContext<'_>,
) -> Result<Study, Error> {
    evtac_learn::flush_denormals();
    let todo = points(parameters, factors)
        .into_iter()
        .map(|(name, factor)| {
            let params = params_of(&name, factor)?;
            Ok((name, factor, params))
        })
        .collect::<Result<Vec<_>, PerturbError>>()?;
    let started = std::time::Instant::now();
    let mut points = Vec::with_capacity(todo.len());
    for (k, (name, factor, params)) in todo.iter().enumerate() {
        // Resumed points take no time, so early in a resumed study this is pessimistic.
        let eta = match k {
            0 => String::new(),
            _ => {
                let per_point = started.elapsed().as_secs_f64() / k as f64;
                format!(
                    ", about {:.0} min left",
                    per_point * (todo.len() - k) as f64 / 60.0
                )
            }
        };
        run.progress.message(&format!(
            "point {} of {}: {name} x{factor}{eta}",
            k + 1,
            todo.len()
        ));
        let dir = point_dir(out, name, *factor);
        points.push(point((name, *factor), params, &dir, keep_data, run)?);
    }
    Ok(Study {
        scale: run.plan.scale,
        seed: run.seed,
        factors: factors.to_vec(),
        points,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_parameter_scales_its_fields_and_nothing_else() {
        let defaults = SimParams::default();
        let base = serde_json::to_value(&defaults).unwrap();
        for p in PARAMETERS {
            let scaled = serde_json::to_value(perturbed(&defaults, &p, 1.5).unwrap()).unwrap();
            for section in [
                "sensor", "contact", "camera", "dvs", "imu", "timeline", "rig",
            ] {
                let (b, s) = (&base[section], &scaled[section]);
                for (key, bv) in b.as_object().unwrap() {
                    let field = format!("{section}.{key}");
                    let sv = &s[key];
                    if p.fields.contains(&field.as_str()) {
                        let (x, y) = (bv.as_f64().unwrap(), sv.as_f64().unwrap());
                        assert!(
                            x != 0.0,
                            "{field} is 0 by default: scaling it varies nothing"
                        );
                        assert!((y - 1.5 * x).abs() <= 0.5, "{field}: {x} -> {y}");
                    } else {
                        assert_eq!(bv, sv, "{} changed {field}", p.name);
                    }
                }
            }
        }
    }

    #[test]
    fn points_start_with_the_baseline_and_unknown_names_are_refused() {
        let p = [parameter("cutoff").unwrap(), parameter("creep").unwrap()];
        assert_eq!(
            points(&p, &[0.5, 2.0]),
            [
                (Varied::Baseline, 1.0),
                (Varied::from("cutoff"), 0.5),
                (Varied::from("cutoff"), 2.0),
                (Varied::from("creep"), 0.5),
                (Varied::from("creep"), 2.0)
            ]
        );
        assert_eq!(
            params_of(&Varied::Baseline, 1.0).unwrap(),
            SimParams::default()
        );
        assert_eq!(Varied::from(BASELINE), Varied::Baseline);
        // Files spell a point's parameter as its name, the baseline's included.
        assert_eq!(
            serde_json::to_string(&points(&p, &[0.5])[..2]).unwrap(),
            r#"[["baseline",1.0],["cutoff",0.5]]"#
        );
        let e = params_of(&Varied::from("grip"), 2.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"grip\"") && e.contains("cutoff"), "{e}");
    }

    #[test]
    fn integers_round_and_names_are_unique_folders() {
        let rings = parameter("pin_rings").unwrap();
        let half = perturbed(&SimParams::default(), &rings, 0.5).unwrap();
        assert_eq!(half.sensor.rings, 5);
        let mut names: Vec<&str> = PARAMETERS.iter().map(|p| p.name).collect();
        names.push(BASELINE);
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), PARAMETERS.len() + 1);
        assert_eq!(
            point_dir(Path::new("out"), &Varied::from("cutoff"), 0.5),
            Path::new("out/points/cutoff/x0.5")
        );
    }

    #[test]
    fn a_field_that_is_not_a_number_is_named() {
        let bad = Parameter {
            name: "bad",
            what: "",
            fields: &["dvs.no_such_field"],
        };
        let e = perturbed(&SimParams::default(), &bad, 2.0).unwrap_err();
        assert!(e.to_string().contains("dvs.no_such_field"), "{e}");
    }

    fn level(name: ReprKind, value: f64, mae: f64) -> Exp3Point {
        let runs = vec![crate::results::Mae {
            overall: mae,
            pitch: mae,
            roll: mae,
        }];
        Exp3Point {
            name,
            value,
            seen: true,
            trials: 1,
            stats: MaeStats::of(&runs),
            runs,
            truth: None,
        }
    }

    #[test]
    fn the_rise_is_the_lowest_level_against_the_mean_of_the_others() {
        let points = [
            level(ReprKind::Static, 2.0, 0.30),
            level(ReprKind::Static, 4.0, 0.20),
            level(ReprKind::Static, 6.0, 0.10),
            level(ReprKind::Dynamic, 4.0, 0.25),
            level(ReprKind::Dynamic, 2.0, 0.55),
            level(ReprKind::Dynamic, 6.0, 0.35),
        ];
        let r = rise(&points);
        assert_eq!((r.level, r.levels), (2.0, 3));
        assert!((r.static_deg - 0.15).abs() < 1e-12, "{r:?}");
        assert!((r.dynamic_deg - 0.25).abs() < 1e-12, "{r:?}");
    }
}
