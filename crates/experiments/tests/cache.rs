//! Feature caches: computed once, reused (a second run computes no features).

use crate::simulate;
use evtac_experiments::cache::FeatureCache;
use evtac_experiments::dataset::Dataset;
use evtac_experiments::plan;
use evtac_experiments::sampling::{Phase, Sampling};
use evtac_import::inputs::Inputs;
use evtac_sim::Protocol;

#[test]
fn second_run_computes_no_features_and_loads_the_same() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path(), Protocol::Exp1, 3);
    let ds = Dataset::open(dir.path(), Inputs::FROM_FILES).unwrap();
    let cache = FeatureCache::new(&ds).unwrap();
    let trials: Vec<_> = ds.manifest.trials.iter().collect();
    let configs = [
        plan::static_config(1000.0, 2.0),
        plan::static_config(100.0, 0.0),
        plan::dynamic_config(640.0, 0),
    ];
    // Each trial reports whether it was found cached whole (a resumed run's ETA skips those).
    let calls = std::sync::Mutex::new(Vec::new());
    let record = |reused: bool| calls.lock().unwrap().push(reused);
    let first = cache
        .ensure(&trials, &configs, Sampling::MOTION, &record)
        .unwrap();
    assert_eq!((first.computed, first.reused), (9, 0));
    assert_eq!(std::mem::take(&mut *calls.lock().unwrap()), [false; 3]);
    let a = cache
        .load(&trials, &configs[0], Sampling::MOTION, &[Phase::Motion])
        .unwrap();
    let second = cache
        .ensure(&trials, &configs, Sampling::MOTION, &record)
        .unwrap();
    assert_eq!((second.computed, second.reused), (0, 9));
    assert_eq!(std::mem::take(&mut *calls.lock().unwrap()), [true; 3]);
    // A fresh cache object (a new run) reuses the files too.
    let again = FeatureCache::new(&ds).unwrap();
    let third = again
        .ensure(&trials, &configs, Sampling::MOTION, &|_| {})
        .unwrap();
    assert_eq!(third.computed, 0);
    let b = again
        .load(&trials, &configs[0], Sampling::MOTION, &[Phase::Motion])
        .unwrap();
    assert_eq!(a.set.features, b.set.features);
    assert_eq!(a.set.labels, b.set.labels);
    assert_eq!(a.samples.len(), 3 * 50);
    assert_eq!(a.set.features.len(), 3 * 50 * 900);
    // Features are fractions of set pixels, and the contact shows up in them.
    assert!(a.set.features.iter().all(|v| (0.0..=1.0).contains(v)));
    assert!(a.set.features.iter().any(|&v| v > 0.0));
    // Labels follow the tilt: the last sample of a trial is tilted further than the first.
    let (l0, l49) = (&a.set.labels[0..2], &a.set.labels[98..100]);
    assert!(
        l49[0].hypot(l49[1]) > l0[0].hypot(l0[1]) + 5.0,
        "{l0:?} {l49:?}"
    );
}

/// Stacked and late share one folder of 1800-feature rows (computed once per trial), whose
/// halves are the static and dynamic configs' own features.
#[test]
fn stacked_and_late_share_features_that_are_static_then_dynamic() {
    use evtac_repr::{ReprConfig, ReprKind};
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path(), Protocol::Exp1, 2);
    let ds = Dataset::open(dir.path(), Inputs::FROM_FILES).unwrap();
    let cache = FeatureCache::new(&ds).unwrap();
    let trials: Vec<_> = ds.manifest.trials.iter().collect();
    let (st, dy) = (
        plan::static_config(1000.0, 2.0),
        plan::dynamic_config(640.0, 0),
    );
    let (static_part, dynamic_part) = (*st.static_part().unwrap(), *dy.dynamic_part().unwrap());
    let [stacked, late] =
        [ReprKind::Stacked, ReprKind::Late].map(|k| k.config(static_part, dynamic_part));
    let stats = cache
        .ensure(&trials, &[stacked, late], Sampling::MOTION, &|_| {})
        .unwrap();
    assert_eq!(stats.computed, 2, "one computation per trial for both");
    let load = |c: &ReprConfig| {
        cache
            .load(&trials, c, Sampling::MOTION, &[Phase::Motion])
            .unwrap()
    };
    let (both, s, d) = (load(&late), load(&st), load(&dy));
    assert_eq!(both.set.width, 1800);
    assert_eq!(both.set.features, load(&stacked).set.features);
    assert_eq!(both.samples.len(), 2 * 50);
    for k in 0..both.samples.len() {
        assert_eq!(&both.set.row(k)[..900], s.set.row(k));
        assert_eq!(&both.set.row(k)[900..], d.set.row(k));
    }
    assert_eq!(both.set.labels, s.set.labels);
}
