//! Data for the report's illustrative figures: an example pause trial's estimated and true
//! curves, and the static and dynamic contour overlays at two speeds and two depths.

use crate::cache::FeatureCache;
use crate::results::{ExampleTrial, Overlay};
use crate::training::Error;
use evtac_events::manifest::TrialMeta;
use evtac_learn::Model;
use evtac_repr::CROP;
use evtac_repr::{FeatureExtractor, ReprConfig, ReprKind};

/// Spacing of the example curves' samples (20 ms: smooth curves, few predictions).
const CURVE_STEP_US: i64 = 20_000;

fn repr_err(trial: &str) -> impl Fn(evtac_repr::ReprError) -> Error + '_ {
    move |source| {
        Error::Cache(crate::cache::Error::Repr {
            trial: trial.to_string(),
            source,
        })
    }
}

/// The example curves of `meta` with `models` (kind, model), every 20 ms of the motion.
pub fn example_trial(
    cache: &FeatureCache<'_>,
    meta: &TrialMeta,
    models: &[(ReprKind, &Model)],
) -> Result<ExampleTrial, Error> {
    let ds = cache.dataset();
    let labels = ds.labels(meta)?;
    let events = ds.events(meta)?;
    let times: Vec<i64> = (0..)
        .map(|k| meta.motion_start_us + k * CURVE_STEP_US)
        .take_while(|&t| t <= meta.motion_end_us)
        .collect();
    let configs: Vec<ReprConfig> = models.iter().map(|(_, m)| m.repr_config()).collect();
    let masks = configs
        .iter()
        .map(|c| cache.mask(c))
        .collect::<Result<Vec<_>, _>>()?;
    let mask_refs: Vec<_> = masks.iter().map(|m| m.as_ref()).collect();
    let mut fx = FeatureExtractor::new_with_masks(&configs, CROP, &mask_refs)
        .map_err(repr_err(&meta.trial))?;
    let mut preds: Vec<Vec<[f32; 2]>> = vec![Vec::with_capacity(times.len()); models.len()];
    evtac_learn::flush_denormals();
    fx.run(&events, &times, |_, fx| {
        for (i, (_, m)) in models.iter().enumerate() {
            preds[i].push(m.predictor.predict_one(fx.features(i)));
        }
    })
    .map_err(repr_err(&meta.trial))?;
    let t0 = meta.motion_start_us as f64;
    Ok(ExampleTrial {
        trial: meta.trial.clone(),
        stop_s: meta
            .stop_start_us
            .zip(meta.stop_end_us)
            .map(|(a, b)| ((a as f64 - t0) / 1e6, (b as f64 - t0) / 1e6)),
        t_s: times.iter().map(|&t| (t as f64 - t0) / 1e6).collect(),
        truth: times
            .iter()
            .map(|&t| {
                let (p, r) = labels.at(t);
                [p as f32, r as f32]
            })
            .collect(),
        predictions: models.iter().map(|(n, _)| *n).zip(preds).collect(),
    })
}

/// The time at which `meta` reaches half its total tilt (10 degrees: the paper tilts to 20).
fn mid_tilt_time(meta: &TrialMeta) -> i64 {
    let t = meta.motion_start_us + (meta.total_deg / 2.0 / meta.speed_deg_s.max(1e-9) * 1e6) as i64;
    t.clamp(meta.motion_start_us, meta.motion_end_us)
}

fn closest(values: impl Iterator<Item = f64>, target: f64) -> Option<f64> {
    values.min_by(|a, b| (a - target).abs().total_cmp(&(b - target).abs()))
}

/// A pair of trials differing only in one condition, in the same direction.
fn pair(
    trials: &[TrialMeta],
    fixed: impl Fn(&TrialMeta) -> bool,
    varied: impl Fn(&TrialMeta) -> f64,
) -> Option<(&TrialMeta, &TrialMeta)> {
    let pool: Vec<&TrialMeta> = trials
        .iter()
        .filter(|t| fixed(t) && t.stop_start_us.is_none())
        .collect();
    let lo = pool.iter().map(|t| varied(t)).fold(f64::INFINITY, f64::min);
    let hi = pool
        .iter()
        .map(|t| varied(t))
        .fold(f64::NEG_INFINITY, f64::max);
    if lo >= hi {
        return None;
    }
    let mut dirs: Vec<f64> = pool.iter().map(|t| t.direction_deg).collect();
    dirs.sort_by(f64::total_cmp);
    dirs.dedup();
    for d in dirs {
        let a = pool
            .iter()
            .find(|t| t.direction_deg == d && varied(t) == lo);
        let b = pool
            .iter()
            .find(|t| t.direction_deg == d && varied(t) == hi);
        if let (Some(a), Some(b)) = (a, b) {
            return Some((a, b));
        }
    }
    None
}

fn frames(
    cache: &FeatureCache<'_>,
    meta: &TrialMeta,
    configs: &[ReprConfig],
) -> Result<Vec<Vec<u8>>, Error> {
    let masks = configs
        .iter()
        .map(|c| cache.mask(c))
        .collect::<Result<Vec<_>, _>>()?;
    let mask_refs: Vec<_> = masks.iter().map(|m| m.as_ref()).collect();
    let mut fx = FeatureExtractor::new_with_masks(configs, CROP, &mask_refs)
        .map_err(repr_err(&meta.trial))?;
    let events = cache.dataset().events(meta)?;
    let mut out = Vec::new();
    fx.run(&events, &[mid_tilt_time(meta)], |_, fx| {
        out = (0..configs.len()).map(|i| fx.frame(i).to_vec()).collect();
    })
    .map_err(repr_err(&meta.trial))?;
    Ok(out)
}

/// Static and dynamic binary frames at half the total tilt: slowest vs fastest speed at the
/// depth closest to 2 mm, and shallowest vs deepest depth at the speed closest to 6 deg/s, each
/// pair in one direction (as the paper's figure).
pub fn overlays(
    cache: &FeatureCache<'_>,
    static_cfg: ReprConfig,
    dynamic_cfg: ReprConfig,
) -> Result<Vec<Overlay>, Error> {
    let trials = &cache.dataset().manifest.trials;
    let depth = closest(trials.iter().map(|t| t.depth_mm), 2.0);
    let speed = closest(trials.iter().map(|t| t.speed_deg_s), 6.0);
    let configs = [static_cfg, dynamic_cfg];
    // One pair per axis: the trials at the extremes of the varied level, the other level fixed.
    let mut pairs = Vec::new();
    if let Some(depth) = depth
        && let Some((a, b)) = pair(trials, |t| t.depth_mm == depth, |t| t.speed_deg_s)
    {
        let fixed = format!("depth {depth} mm");
        let label = |t: &TrialMeta| format!("{} deg/s", t.speed_deg_s);
        pairs.push(("speed", fixed, a, b, label(a), label(b)));
    }
    if let Some(speed) = speed
        && let Some((a, b)) = pair(trials, |t| t.speed_deg_s == speed, |t| t.depth_mm)
    {
        let fixed = format!("speed {speed} deg/s");
        let label = |t: &TrialMeta| format!("{} mm", t.depth_mm);
        pairs.push(("depth", fixed, a, b, label(a), label(b)));
    }
    let mut panels: Vec<(String, Overlay)> = Vec::new();
    for (axis, fixed, a, b, first_label, second_label) in pairs {
        let fa = frames(cache, a, &configs)?;
        let fb = frames(cache, b, &configs)?;
        for (i, kind) in ["Static", "Dynamic"].into_iter().enumerate() {
            panels.push((
                format!("{kind}-{axis}"),
                Overlay {
                    title: format!(
                        "{kind}: {axis} ({fixed}, direction {} deg)",
                        a.direction_deg
                    ),
                    first_label: first_label.clone(),
                    second_label: second_label.clone(),
                    width: usize::from(CROP.width),
                    height: usize::from(CROP.height),
                    first: fa[i].clone(),
                    second: fb[i].clone(),
                },
            ));
        }
    }
    // Rows: static (speed, depth), then dynamic (speed, depth), as the paper lays them out.
    let order = [
        "Static-speed",
        "Static-depth",
        "Dynamic-speed",
        "Dynamic-depth",
    ];
    let mut out = Vec::new();
    for key in order {
        if let Some((_, o)) = panels.iter().find(|(k, _)| k == key) {
            out.push(o.clone());
        }
    }
    Ok(out)
}
