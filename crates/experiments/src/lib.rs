//! The paper's experiments on datasets of trials: splits, sampling, feature caches, training
//! jobs, Experiments 1-3 and the latency study, and their [`results`]. Where the paper states no
//! value evtac chose one; [`choices`] lists them all, with the value used. The report, its
//! figures and rendered recordings are `evtac-report`'s, which reads [`results::Results`].
//!
//! - [`dataset`]: a dataset folder (`trials.csv`, recordings, `calibration.json`,
//!   `no_contact.aedat4`, `labels/`), labels computed when missing, opened with
//!   `evtac_import::inputs` (whether its calibration and mask come from its files or were opted
//!   out of); [`LabelCheck`]: its labels against the commanded stop angles and the ground truth.
//!   Making and checking datasets (import, clock sync, motions, `evtac check`, sensor
//!   statistics) is `evtac-import`'s.
//! - [`splits`]: 70:15:15 train/validation/test trials with balanced marginals, `splits.json`.
//! - [`sampling`]: 50 equally spaced motion points per trial on the 1 ms grid (+10 stop points).
//! - [`cache`]: pooled features per (trial, representation config, mask, sampling) as NPY,
//!   computed in one pass for many configs, reused.
//! - [`context`]: the plan, seed, model folder and progress an experiment run shares.
//! - [`job`]: one unit of work as data (simulate, train, reproduce, a sensitivity point), run by
//!   the module that owns the work ([`simulation`], [`training`], [`pipeline`],
//!   [`sensitivity`]).
//! - [`jobs`]: jobs with `done` markers, run in parallel, resumed after interruption; their
//!   [`stage`]s and what each is expected to cost (for progress bars with an ETA), reported
//!   through [`progress`]; the crate's `schedule` starts a stage's training runs longest first.
//! - [`training`]: one training job (`evtac train`), model loading and evaluation.
//! - [`plan`], [`tuning`], [`exp1`], [`latency`] (processing time per estimate),
//!   [`paced_latency`] (end to end at recorded pace, queueing included), [`truth`] (errors
//!   against the simulator's exact truth) and the crate's own `noise`, `exp2`, `exp3` and
//!   `examples`: the experiments; [`repr_example`] (the paper's Fig. 2 for one sample) and
//!   [`sensor_view`] (the sensor at rest and in contact) the data of two illustrative figures;
//!   [`pipeline`] runs them all (or, with [`slurm`], submits them to a Slurm cluster);
//!   [`results`] is what they measured, as plain typed data (it imports nothing from the
//!   experiments); [`choices`] lists the values evtac chose where the paper states none.
//! - [`sensitivity`]: Experiment 1, tuning included, with each unmeasured simulator parameter
//!   scaled, one at a time: which of the paper's conclusions hold on which simulator.
//! - [`dataset_seeds`]: Experiment 1 on datasets simulated with other seeds, the spread across
//!   datasets the report sets beside the training seeds'; [`repeat_split`]: what a condition's
//!   repeats on both sides of the split are worth.
//!
//! Modules that only the pipeline calls (`noise`, `variant`, `exp2`, `exp3`, `examples`,
//! `label_check`) are private: their results are in [`results`], their errors in
//! [`pipeline::Error`].
//!
//! ```no_run
//! use evtac_experiments::progress::Quiet;
//! use evtac_experiments::pipeline::{Datasets, reproduce};
//! use evtac_experiments::plan::Plan;
//! use evtac_experiments::stage_log::StageLog;
//! use std::path::Path;
//!
//! // Datasets as `evtac simulate` writes them: data/exp1, data/exp2, data/exp3-speed, ...
//! let data = Datasets::in_dir(Path::new("data"));
//! let plan = Plan::for_scale(evtac_sim::Scale::Small);
//! let out = Path::new("out");
//! // Each stage's time is appended to out/stage-times.csv as it finishes.
//! let log = StageLog::open(out)?;
//! let results = reproduce(&data, &plan, 0, out, &log, &Quiet)?;
//! println!("static test MAE {}", results.exp1[0].test.overall.display());
//! # Ok::<(), evtac_experiments::pipeline::Error>(())
//! ```

pub mod cache;
pub mod capture_filter;
pub mod choices;
pub mod context;
pub mod dataset;
pub mod dataset_seeds;
pub mod dense_grid;
mod error;
mod examples;
pub mod exp1;
mod exp2;
mod exp3;
pub mod job;
pub mod jobs;
mod label_check;
pub mod label_noise;
pub mod latency;
mod noise;
mod paced_extent;
pub mod paced_latency;
mod parameters;
pub mod pipeline;
pub mod plan;
pub mod progress;
pub mod repeat_split;
pub mod repr_example;
pub mod results;
pub mod sampling;
mod schedule;
pub mod sensitivity;
pub mod sensor_view;
pub mod simulation;
pub mod slurm;
pub mod splits;
pub mod stage;
pub mod stage_log;
pub mod training;
pub mod truth;
pub mod tuning;
mod variant;

pub use label_check::LabelCheck;
