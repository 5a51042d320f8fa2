//! The values evtac had to choose because the paper does not state them, as the report's section
//! "Choices the paper does not state": each with the value the run used, why, and the flag or
//! file that changes it.
//!
//! Every value is read from the constant, default or plan that the code runs with (never retyped
//! here), so the section cannot drift from what a reproduction does. What the paper does state
//! (the crop, 8x8 pooling, the 900-256-128-64-2 layer sizes, SmoothL1 beta 1, AdamW's learning rate
//! and weight decay, batch 32, 100 epochs, ten runs, 70:15:15 splits, 50 + 10 samples on a 1 ms
//! grid, the 500 ms stop, the chosen tau, window and thresholds) is not listed.

use crate::plan::Plan;
pub use crate::results::Choice;
use crate::sampling::{GRID_US, MOTION_POINTS, STOP_POINTS};
use crate::splits::RATIOS;
use evtac_labels::LabelConfig;
use evtac_learn::TrainConfig;
use evtac_repr::{Comparison, DynamicConfig, StaticConfig};
use evtac_sim::SimParams;
use serde::Serialize;

fn row(what: &str, value: String, why: &str, change: &str) -> Choice {
    Choice {
        what: what.into(),
        value,
        why: why.into(),
        change: change.into(),
    }
}

/// A serde enum's name as written in config files (`gt`, `potential`, `total-rotation`): its
/// JSON, unquoted when it is a string.
fn name_of(value: impl Serialize) -> String {
    match serde_json::to_string(&value) {
        Ok(json) => serde_json::from_str::<String>(&json).unwrap_or(json),
        Err(e) => format!("? ({e})"),
    }
}

fn symbol(c: Comparison) -> &'static str {
    match c {
        Comparison::Gt => ">",
        Comparison::Ge => ">=",
    }
}

/// The dynamic count rule as the code applies it: `>` if a count equal to the threshold is not
/// set, `>=` otherwise.
fn dynamic_symbol() -> &'static str {
    let d = DynamicConfig {
        count_threshold: 1,
        ..DynamicConfig::default()
    };
    if evtac_repr::combine::dynamic_is_set(&d, 1) {
        ">="
    } else {
        ">"
    }
}

fn list<T: std::fmt::Display>(values: &[T]) -> String {
    values
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Every choice a reproduction under `plan` with master `seed` makes that the paper leaves open,
/// in the order of the pipeline (data, labels, representations, training, evaluation).
/// `exp1_sim` and `exp2_sim` are the simulator parameters of the Experiment 1 and 2 datasets
/// (their `simulator.json`), `None` for recorded data.
pub fn of_run(
    plan: &Plan,
    seed: u64,
    exp1_sim: Option<&SimParams>,
    exp2_sim: Option<&SimParams>,
) -> Vec<Choice> {
    [
        data(exp1_sim, exp2_sim),
        labels(),
        representations(exp1_sim),
        tuning_and_evaluation(plan, exp1_sim),
        training(plan, seed),
        studies(plan, exp1_sim),
    ]
    .concat()
}

/// What a choice says of a value that recorded data brings with it.
const RECORDED: &str = "recorded data (no `simulator.json`): the recordings' own";

/// How a tuning grid is searched: every combination, or a cross through its centre.
fn grid_text(full: bool, (time, threshold): (f64, String)) -> String {
    if full {
        "every combination".to_string()
    } else {
        format!("a cross through {time} ms, threshold {threshold}")
    }
}

/// The choices of the data: the simulated sensor, or the recordings' own.
fn data(exp1_sim: Option<&SimParams>, exp2_sim: Option<&SimParams>) -> Vec<Choice> {
    vec![
        row(
            "Simulated sensor",
            exp1_sim.map_or(RECORDED.into(), |sim| {
                format!(
                    "evtac's simulator: background noise leak {} Hz + shot {} Hz per pixel, {} \
                     hot pixels at {}-{} Hz; every parameter in `docs/simulator.md`",
                    sim.dvs.leak_rate_hz,
                    sim.dvs.shot_noise_rate_hz,
                    sim.dvs.hot_pixels,
                    sim.dvs.hot_pixel_rate_hz[0],
                    sim.dvs.hot_pixel_rate_hz[1]
                )
            }),
            "the paper's recordings are not public; the sensor, its noise and the robot's timing \
             are modelled, not fitted to the paper's sensor",
            "`evtac simulate --params FILE`, or `evtac reproduce --data DIR` with recordings",
        ),
        row(
            "Stop angle (Experiment 2)",
            exp2_sim.map_or(RECORDED.into(), |sim| {
                format!(
                    "uniform in {}..{} deg of tilt",
                    sim.timeline.stop_range_deg[0], sim.timeline.stop_range_deg[1]
                )
            }),
            "the paper says \"a random theta angle\"; the range keeps the stop away from the \
             motion's start and end ramps",
            "`timeline.stop_range_deg` in `evtac simulate --params FILE`",
        ),
    ]
}

/// The choices of the labels computed from the IMU.
fn labels() -> Vec<Choice> {
    let labels = LabelConfig::default();
    let train = TrainConfig::default();
    vec![
        row(
            "Label filter",
            format!(
                "Butterworth, order {} per pass, cutoff {} Hz, applied forward and backward to \
                 the integrated tilt",
                labels.filter_order, labels.cutoff_hz
            ),
            "the paper says \"zero-phase filtered\" only, and lists the filter before the \
             integration: evtac reorders the two steps (integrates the rate, then filters the \
             tilt; both linear, they differ only near the recording's ends); the cutoff keeps \
             the robot's acceleration ramps and removes most of the gyroscope's white noise",
            "`evtac labels DATASET --cutoff-hz HZ` or `--config FILE` (`filter_order`), before \
             `evtac reproduce --data`",
        ),
        row(
            "Label units and angles",
            format!(
                "degrees for labels, predictions and the loss, so SmoothL1's beta = {} is {} \
                 deg; pitch = atan2(n_x, n_z), roll = atan2(n_y, n_z) of the plane's normal n in \
                 the sensor frame (positive towards the sensor's +x and +y)",
                train.huber_beta, train.huber_beta
            ),
            "the paper gives beta 1 without a unit and names pitch and roll without axes or \
             signs; in radians the same beta would make the loss quadratic over the whole tilt \
             (1 rad is 57 deg)",
            "`crates/labels/src/geometry.rs`; the unit is fixed",
        ),
        row(
            "Label bias and scale",
            format!(
                "bias: mean rate before onset, ending {} ms before it; scale: `{}`",
                labels.bias_margin_us / 1000,
                name_of(labels.scale)
            ),
            "the paper says \"bias-compensated, scale-calibrated\"; scaling onto the commanded \
             total rotation leaves the stop angle free to validate the labels",
            "`evtac labels DATASET --scale METHOD` or `--config FILE`",
        ),
    ]
}

/// The choices of the representations and their mask.
fn representations(exp1_sim: Option<&SimParams>) -> Vec<Choice> {
    let st = StaticConfig::default();
    vec![
        row(
            "Static accumulator",
            format!(
                "eta {}, potential limits {}..{}, neutral {}, polarity `{}`",
                st.eta,
                st.min_potential,
                st.max_potential,
                st.neutral_potential,
                name_of(st.polarity)
            ),
            "the paper uses dv-processing's accumulator and states none of these; these are its \
             constructor defaults, and signed polarity matches the paper's `+ eta p_k`",
            "`StaticConfig::default` in `crates/repr/src/config.rs`; for one model `evtac train \
             --repr-json FILE`",
        ),
        row(
            "Static threshold",
            format!(
                "on the `{}` (float32), pixel set when V {} threshold x eta",
                name_of(st.threshold_space),
                symbol(st.comparison)
            ),
            "the paper gives the threshold in event contributions without its space or \
             comparison; this mirrors the dynamic rule and makes threshold 0 mean any positive \
             potential, without 8-bit rounding",
            "`threshold_space`, `comparison` of `StaticConfig` (`crates/repr/src/config.rs`, or \
             `evtac train --repr-json FILE`)",
        ),
        row(
            "Dynamic threshold",
            format!(
                "pixel set when its window count {} threshold",
                dynamic_symbol()
            ),
            "the paper's threshold 0 must keep pixels with events and drop empty ones",
            "`crates/repr/src/combine.rs`",
        ),
        row(
            "No-contact mask",
            format!(
                "the no-contact recording ({}) through the model's own static config; a pixel is \
                 masked when its 8-bit frame value is not the neutral one; dynamic frames are not \
                 masked",
                exp1_sim.map_or("recorded".into(), |sim| format!(
                    "{} s simulated, plane {} mm away",
                    sim.timeline.no_contact_s, sim.contact.no_contact_gap_mm
                ))
            ),
            "the paper masks the \"non-zero\" pixels of a no-contact frame without its length or \
             accumulator settings; the same config makes the mask match the frames it cleans",
            "`no_contact.aedat4` in the dataset; `crates/repr/src/mask.rs`",
        ),
    ]
}

/// The choices of tuning, model selection and how the experiments are scored.
fn tuning_and_evaluation(plan: &Plan, exp1_sim: Option<&SimParams>) -> Vec<Choice> {
    vec![
        row(
            "Tuning grids",
            format!(
                "static tau {} ms x threshold {} ({}); dynamic window {} ms x threshold {} ({}); \
                 the {} grid{}",
                list(&plan.static_taus_ms),
                list(&plan.static_thresholds),
                grid_text(
                    plan.full_grid,
                    (plan.static_center.0, plan.static_center.1.to_string())
                ),
                list(&plan.dynamic_windows_ms),
                list(&plan.dynamic_thresholds),
                grid_text(
                    plan.full_grid,
                    (plan.dynamic_center.0, plan.dynamic_center.1.to_string())
                ),
                plan.grid.name(),
                plan.recheck_text()
                    .map_or(String::new(), |text| format!("; {text}")),
            ),
            "the paper names only some values it tried (100 and 1000 ms, thresholds 0-2, windows \
             up to 640 ms); the paper grid brackets them; the extended grid adds static decays \
             of 3, 5 and 10 s, because the paper grid's static optimum sat on its largest decay \
             with validation MAE still falling; one run per setting ranks settings a seed's \
             spread apart by chance, hence the recheck",
            "`evtac reproduce --scale`, `--grid paper` or `extended`; `crates/experiments/src/plan.rs`",
        ),
        row(
            "Trial timeline",
            exp1_sim.map_or(RECORDED.into(), |sim| {
                let t = &sim.timeline;
                format!(
                    "indentation {} s (a cosine ramp), rest {} s, tilt to {} deg at the trial's \
                     speed with {} deg/s^2 ramps, hold {} s; each trial's representation starts \
                     at its recording's first event, so at motion onset the accumulator has the \
                     indentation and the rest behind it",
                    t.indent_s, t.settle_s, t.total_deg, t.accel_deg_s2, t.hold_s
                )
            }),
            "the paper describes the motion, not the timing around it nor where the \
             representation starts",
            "`timeline` in `evtac simulate --params FILE`; `crates/experiments/src/cache.rs`",
        ),
        row(
            "Model selection",
            "lowest validation MAE (mean of pitch and roll), checkpoint at the best epoch \
             (earliest on ties)"
                .into(),
            "the paper says \"best validation performance\" without its metric",
            "`crates/experiments/src/tuning.rs`, `crates/learn/src/training.rs`",
        ),
        row(
            "Experiment 2 checkpoints",
            "the epoch with the lowest validation MAE over the phases the setting trains on: \
             motion for pause-motion, motion and stop for pause-motion-stop; continuous-only \
             keeps Experiment 1's checkpoints"
                .into(),
            "the paper says \"best validation performance\" without saying over which phases",
            "`crates/experiments/src/exp2.rs`",
        ),
        row(
            "Experiment 3 levels and rule",
            "the Experiment 1 models, not retrained, on a speed-wise and a depth-wise dataset; \
             a level is seen when its trials are marked `group = seen` (else when Experiment 1 \
             trained on it); per level, the MAE over all its trials' samples, mean ± std over \
             the seeds; the levels are evtac's"
                .into(),
            "the paper gives 30 trials per level and says unseen levels are interpolated, but \
             neither the levels nor their count",
            "`crates/sim/src/protocol.rs` (the datasets' levels); \
             `crates/experiments/src/exp3.rs`",
        ),
        row(
            "MAE pooling",
            format!(
                "over samples: every sampled point of every test trial weighs the same (each \
                 trial has the same {MOTION_POINTS} motion points, so trials weigh equally \
                 within a phase)"
            ),
            "the paper does not say whether errors are averaged per sample or per trial",
            "`crates/experiments/src/results.rs` (`Mae::of`)",
        ),
        row(
            "Overall MAE",
            "mean of the pitch and roll MAE".into(),
            "the paper does not define it; its table's overall values are the means of its \
             pitch and roll ones, to rounding",
            "`crates/learn/src/metrics.rs`",
        ),
    ]
}

/// The choices of the network, its training and its samples, splits and seeds.
fn training(plan: &Plan, seed: u64) -> Vec<Choice> {
    let train = TrainConfig::default();
    let opt = &train.optimizer;
    vec![
        row(
            "Activation",
            format!(
                "{} after every hidden layer, linear output",
                evtac_learn::model::ACTIVATION
            ),
            "the paper gives the layer sizes only; ReLU is the usual MLP choice",
            "`crates/learn/src/model.rs`",
        ),
        row(
            "Initialisation and AdamW moments",
            format!(
                "PyTorch's `nn.Linear` default (uniform within 1/sqrt(fan_in)); betas {} / {}, \
                 eps {:e}",
                opt.beta1, opt.beta2, opt.epsilon
            ),
            "the paper gives lr and weight decay only; PyTorch's defaults are the likely ones",
            "`crates/learn/src/model.rs`, `crates/learn/src/adamw.rs`",
        ),
        row(
            "Sample points",
            format!(
                "{MOTION_POINTS} motion (+{STOP_POINTS} stop) points on the {} ms grid: the \
                 first and last grid point of each phase and evenly spaced indices between \
                 (rounded)",
                GRID_US / 1000
            ),
            "the paper says \"equally spaced\" without the end points",
            "`crates/experiments/src/sampling.rs`",
        ),
        row(
            "Split balancing",
            format!(
                "{} by trial, greedy in a seeded random order: each trial to the split furthest \
                 below its share for the trial's speed, depth and direction",
                RATIOS.map(|r| format!("{}", (r * 100.0).round())).join(":")
            ),
            "the paper balances the marginals \"approximately\" without a method; a plain \
             random split leaves them off by several trials",
            "`splits.json` in the dataset (kept if present); `crates/experiments/src/splits.rs`",
        ),
        row(
            "Seeds",
            format!(
                "master seed {seed}: simulation, splits, and Experiment 1's runs with seeds {} \
                 (weights and shuffling from `ChaCha8Rng`)",
                list(&crate::exp1::seeds(seed, plan.seeds))
            ),
            "the paper states ten runs, not their seeds",
            "`evtac reproduce --seed`",
        ),
    ]
}

/// The choices of the studies evtac adds to the paper's, and the latency study.
fn studies(plan: &Plan, exp1_sim: Option<&SimParams>) -> Vec<Choice> {
    vec![
        row(
            "Background noise study",
            format!(
                "Experiment 1 at noise x{} (leak, shot and hot pixels scaled together), with the \
                 settings tuned at x1",
                list(&plan.noise_levels).replace(", ", ", x")
            ),
            "not in the paper: it tells the simulator's noise apart from the representations",
            "`evtac reproduce --noise-levels`",
        ),
        row(
            "Sensor seating per pass",
            exp1_sim.map_or("recorded".into(), |sim| {
                let r = &sim.rig;
                format!(
                    "the sensor seated again before each pass over the conditions (each repeat \
                     of Experiments 1 and 2, each other protocol): a turn of N(0, {} deg) about \
                     its axis, which the labels do not see, a tilt of N(0, {} deg) per axis and \
                     a reach of N(0, {} mm)",
                    r.reseat_rotation_sd_deg, r.reseat_tilt_sd_deg, r.reseat_height_sd_mm
                )
            }),
            "the paper says nothing of how its repeats were recorded; a real rig's repeats \
             differ by more than its robot's repeatability (assumed values, not measured)",
            "`evtac simulate --params` (`rig.reseat_*`); `crates/sim/src/rig.rs`",
        ),
        row(
            "Datasets",
            if plan.datasets > 1 {
                format!(
                    "Experiment 1 on {} simulated datasets (the next seeds after its own), with \
                     the settings tuned on the first; a difference is claimed only beyond both \
                     the training seeds' and the datasets' spread",
                    plan.datasets
                )
            } else {
                "Experiment 1's dataset alone: the spread is the training seeds' only".to_string()
            },
            "the paper has one dataset; a simulated one can be drawn again",
            "`evtac reproduce --datasets`",
        ),
        row(
            "Learned fusions",
            if plan.fusions {
                "stacked and late trained and reported beside the paper's three representations"
                    .to_string()
            } else {
                "left out: the paper's three representations only".to_string()
            },
            "not in the paper: does a learned fusion beat the OR?",
            "`evtac reproduce --no-fusions`",
        ),
        row(
            "Latency study",
            format!(
                "intervals {} ms, up to {} test trials, the first seed's model of each \
                 representation, one thread; timed: the estimator's processing of each \
                 estimate (crop, representation update, pooling, MLP, and the work done ahead \
                 of it between estimates), events at recorded pace; not timed: reading the \
                 recording, queueing",
                list(&plan.latency_intervals_ms),
                plan.latency_trials
            ),
            "the paper's figure shows its intervals and hardware (a GPU for inference); evtac \
             runs on this CPU",
            "`evtac reproduce --scale`; `crates/experiments/src/plan.rs`",
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_sim::Scale;

    fn value(choices: &[Choice], what: &str) -> String {
        choices
            .iter()
            .find(|c| c.what == what)
            .unwrap_or_else(|| panic!("no `{what}` choice"))
            .value
            .clone()
    }

    #[test]
    fn values_come_from_the_code() {
        let plan = Plan::for_scale(Scale::Tiny);
        let sim = SimParams::default();
        let c = of_run(&plan, 7, Some(&sim), Some(&sim));
        assert!(value(&c, "Static accumulator").starts_with(&format!(
            "eta {}, potential limits 0..1",
            StaticConfig::default().eta
        )));
        assert!(value(&c, "Static threshold").contains("`potential`"));
        assert!(value(&c, "Static threshold").contains("V > threshold"));
        assert!(value(&c, "Dynamic threshold").contains("count > threshold"));
        let l = LabelConfig::default();
        assert!(value(&c, "Label filter").contains(&format!(
            "order {} per pass, cutoff {} Hz",
            l.filter_order, l.cutoff_hz
        )));
        assert!(value(&c, "Label bias and scale").contains("`total-rotation`"));
        assert!(value(&c, "Label units and angles").starts_with("degrees"));
        assert!(value(&c, "Sensor seating per pass").contains(&format!(
            "N(0, {} deg) about its axis",
            sim.rig.reseat_rotation_sd_deg
        )));
        assert!(value(&c, "Datasets").starts_with(&format!(
            "Experiment 1 on {} simulated datasets",
            plan.datasets
        )));
        assert!(value(&c, "Label units and angles").contains("beta = 1 is 1 deg"));
        assert!(
            value(&c, "Trial timeline")
                .contains(&format!("indentation {} s", sim.timeline.indent_s))
        );
        assert!(value(&c, "MAE pooling").contains(&format!("{MOTION_POINTS} motion points")));
        assert!(value(&c, "Experiment 2 checkpoints").contains("motion and stop"));
        assert!(value(&c, "Experiment 3 levels and rule").contains("the levels are evtac's"));
        assert!(value(&c, "Latency study").contains("not timed: reading"));
        assert!(value(&c, "Tuning grids").contains("a cross through 1000 ms, threshold 2"));
        assert!(value(&c, "Seeds").contains("seeds 7, 8"));
        assert!(value(&c, "Split balancing").starts_with("70:15:15"));
        assert!(value(&c, "Activation").starts_with("ReLU"));
        assert!(
            value(&c, "Background noise study").starts_with("Experiment 1 at noise x0, x1, x3")
        );
        assert!(value(&c, "Stop angle (Experiment 2)").starts_with(&format!(
            "uniform in {}..{} deg",
            sim.timeline.stop_range_deg[0], sim.timeline.stop_range_deg[1]
        )));
        assert!(value(&c, "Learned fusions").starts_with("stacked and late"));
        let paper_only = Plan {
            fusions: false,
            ..plan.clone()
        };
        let p = of_run(&paper_only, 7, Some(&sim), Some(&sim));
        assert!(value(&p, "Learned fusions").starts_with("left out"));
        let recorded = of_run(&Plan::for_scale(Scale::Paper), 0, None, None);
        assert!(value(&recorded, "Tuning grids").contains("every combination"));
        assert!(value(&recorded, "Simulated sensor").starts_with("recorded data"));
        assert!(value(&recorded, "Trial timeline").starts_with("recorded data"));
        for choice in &c {
            assert!(
                [&choice.what, &choice.value, &choice.why, &choice.change]
                    .iter()
                    .all(|s| !s.is_empty() && !s.contains('|') && !s.contains('\n')),
                "{choice:?} must fit in one table row"
            );
        }
    }
}
