//! The data of the report's image figures: the paper's Fig. 2 for one sample is what the models
//! were fed, and the sensor view is the simulator's camera or, for a recorded dataset, event
//! counts.

use crate::simulate;
use evtac_experiments::cache::FeatureCache;
use evtac_experiments::dataset::Dataset;
use evtac_experiments::results::SensorKind;
use evtac_experiments::sampling::{Phase, Sampling};
use evtac_experiments::{exp1, plan, repr_example, sensor_view};
use evtac_import::inputs::Inputs;
use evtac_sim::Protocol;

#[test]
fn the_fig2_sample_shows_the_cached_features_and_the_window_events() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path(), Protocol::Exp1, 1);
    let ds = Dataset::open(dir.path(), Inputs::FROM_FILES).unwrap();
    let cache = FeatureCache::new(&ds).unwrap();
    let meta = &ds.manifest.trials[0];
    let reprs = exp1::paper_representations(
        plan::static_config(1000.0, 2.0),
        plan::dynamic_config(640.0, 0),
    );
    let ex = repr_example::example(&cache, meta, &reprs)
        .unwrap()
        .expect("the trial has motion samples");
    assert_eq!(ex.panels.len(), 3);
    assert_eq!((ex.width, ex.height, ex.window_ms), (240, 240, 640.0));
    cache
        .ensure(&[meta], &reprs, Sampling::MOTION, &|_| {})
        .unwrap();
    for (config, panel) in reprs.iter().zip(&ex.panels) {
        let name = config.kind();
        assert_eq!(panel.name, name);
        // The middle of the 50 motion samples, as the models saw it (the cache, masks included).
        let loaded = cache
            .load(&[meta], config, Sampling::MOTION, &[Phase::Motion])
            .unwrap();
        assert_eq!(loaded.samples.len(), 50);
        assert_eq!(
            panel.features,
            loaded.set.features[25 * 900..26 * 900],
            "{name}"
        );
        // The features pool the frame drawn above them.
        for (cell, &f) in panel.features.iter().enumerate() {
            let (cx, cy) = (cell % 30, cell / 30);
            let set: u32 = (0..64)
                .map(|k| u32::from(panel.frame[(cy * 8 + k / 8) * 240 + cx * 8 + k % 8]))
                .sum();
            assert_eq!(f, set as f32 / 64.0, "{name} cell {cell}");
        }
    }
    // At count threshold 0 the dynamic frame is exactly the pixels with events in the window.
    let dynamic = &ex.panels[1].frame;
    let with_events: Vec<u8> = ex
        .on
        .iter()
        .zip(&ex.off)
        .map(|(&on, &off)| u8::from(on + off > 0))
        .collect();
    assert_eq!(*dynamic, with_events);
    assert!(ex.on.iter().sum::<u32>() > 0 && ex.off.iter().sum::<u32>() > 0);
}

#[test]
fn the_sensor_view_is_the_simulated_camera_or_the_recorded_events() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path(), Protocol::Exp1, 1);
    let ds = Dataset::open(dir.path(), Inputs::FROM_FILES).unwrap();
    let meta = &ds.manifest.trials[0];
    let view = sensor_view::view(&ds, meta, 10.0).unwrap();
    assert_eq!(view.kind, SensorKind::Simulated);
    assert_eq!(view.panels.len(), 2);
    let pixels = usize::from(view.resolution.width) * usize::from(view.resolution.height);
    for p in &view.panels {
        assert_eq!(p.values.len(), pixels);
        assert!(p.values.iter().all(|v| (0.0..=1.0).contains(v)));
    }
    // Pressed in, the pins move: the images differ.
    let moved = view.panels[0]
        .values
        .iter()
        .zip(&view.panels[1].values)
        .filter(|(a, b)| (*a - *b).abs() > 0.05)
        .count();
    assert!(moved > 1000, "{moved} pixels changed");

    // Without simulator.json the dataset counts as recorded: event counts, the no-contact
    // recording first.
    std::fs::remove_file(dir.path().join(evtac_events::layout::SIMULATOR_FILE)).unwrap();
    let view = sensor_view::view(&ds, meta, 10.0).unwrap();
    assert_eq!(view.kind, SensorKind::EventCounts);
    assert_eq!(view.panels.len(), 2);
    assert!(view.panels[0].title.starts_with("No contact"));
    for p in &view.panels {
        assert!(p.values.iter().any(|&v| v > 0.0));
        assert!(p.values.iter().all(|v| (0.0..=1.0).contains(v)));
    }
}
