//! The data of the paper's Fig. 2 for one test sample: the events of the last dynamic window,
//! the static, dynamic and combined binary frames, and their 30x30 pooled features.
//!
//! Everything comes from the same [`FeatureExtractor`] the feature cache runs, with the tuned
//! settings and the no-contact masks the report's models were trained with, so the features
//! drawn are the ones the models saw for that sample. The sample is picked without a random
//! draw: the middle motion sample of the first Experiment 1 test trial, halfway through the
//! tilt, where the contact patch is well developed.

use crate::cache::{Error, FeatureCache};
use crate::results::{ReprExample, ReprPanel};
use crate::sampling::Sampling;
use evtac_events::manifest::TrialMeta;
use evtac_repr::{CROP, FeatureExtractor, ReprConfig};

/// Fig. 2's data for the middle motion sample of `meta`, with `reprs` (display name, config:
/// static, dynamic, combined as [`crate::exp1::paper_representations`] lists them). `None` when the
/// trial has no motion sample.
pub fn example(
    cache: &FeatureCache<'_>,
    meta: &TrialMeta,
    reprs: &[ReprConfig],
) -> Result<Option<ReprExample>, Error> {
    let samples = cache.samples(meta, Sampling::MOTION)?;
    let Some(sample) = samples.times.get(samples.times.len() / 2) else {
        return Ok(None);
    };
    let t_k = sample.t_us;
    let masks = reprs
        .iter()
        .map(|c| cache.mask(c))
        .collect::<Result<Vec<_>, _>>()?;
    let mask_refs: Vec<_> = masks.iter().map(|m| m.as_ref()).collect();
    let repr_err = |source| Error::Repr {
        trial: meta.trial.clone(),
        source,
    };
    let mut fx = FeatureExtractor::new_with_masks(reprs, CROP, &mask_refs).map_err(repr_err)?;
    let events = cache.dataset().events(meta)?;
    let mut panels = Vec::new();
    fx.run(&events, &[t_k], |_, fx| {
        panels = reprs
            .iter()
            .enumerate()
            .map(|(i, config)| ReprPanel {
                name: config.kind(),
                frame: fx.frame(i).to_vec(),
                features: fx.features(i).to_vec(),
            })
            .collect();
    })
    .map_err(repr_err)?;
    // The window the dynamic representation counts at t_k, `(t_k - window, t_k]`; without a
    // dynamic part (never in the report), the paper's 640 ms.
    let window_us = reprs
        .iter()
        .find_map(|c| c.dynamic_part())
        .map_or(640_000, |d| d.window_us());
    let (width, height) = (usize::from(CROP.width), usize::from(CROP.height));
    let mut on = vec![0u32; width * height];
    let mut off = vec![0u32; width * height];
    let first = events.partition_point(|e| e.t <= t_k - window_us);
    let last = events.partition_point(|e| e.t <= t_k);
    for e in &events[first..last] {
        let pixel = usize::from(e.y) * width + usize::from(e.x);
        let counts = if e.polarity { &mut on } else { &mut off };
        // Cropped events lie inside the crop; an index outside it is skipped, not a panic.
        if let Some(c) = counts.get_mut(pixel) {
            *c += 1;
        }
    }
    Ok(Some(ReprExample {
        trial: meta.trial.clone(),
        t_ms: (t_k - meta.motion_start_us) as f64 / 1000.0,
        window_ms: window_us as f64 / 1000.0,
        width,
        height,
        on,
        off,
        panels,
    }))
}
