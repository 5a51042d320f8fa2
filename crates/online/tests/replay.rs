//! Replay of a simulated trial: the online pipeline's estimates are those of the offline
//! pipeline (cropped events, `extract_features` at the same times, `Predictor::predict_one`).

use crate::support::{self, SENSOR};
use evtac_events::{Event, Resolution, Roi};
use evtac_formats::aedat::Compression;
use evtac_learn::Model;
use evtac_online::input::{self, MemorySource, OpenOptions, SourceSpec};
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::{Estimate, Estimator};
use evtac_repr::extract_features;
use evtac_sim::{Protocol, Scale, SimParams, Simulator, plan};
use std::ops::ControlFlow;

/// Simulator settings for short trials: a 5 degree tilt instead of 20, half a second of
/// no-contact recording (indentation, settling and holding as evtac's simulated protocol has them).
fn short_params() -> SimParams {
    let mut params = SimParams::default();
    params.timeline.total_deg = 5.0;
    params.timeline.no_contact_s = 0.5;
    params
}

/// A fast, deep trial of the tiny Experiment 1 plan (about 1.8 s of events).
fn simulated_trial() -> (Vec<Event>, evtac_sim::TrialRecording) {
    let params = short_params();
    let trials = plan(Protocol::Exp1, Scale::Tiny, 7, &params.timeline);
    let spec = trials
        .iter()
        .find(|t| t.speed_deg_s == 10.0 && t.depth_mm == 3.0)
        .unwrap_or(&trials[0]);
    let sim = Simulator::new(params, 7);
    let recording = sim.simulate(spec);
    (recording.events.clone(), recording)
}

/// Offline: crop, features at `times`, one prediction per row.
fn offline(model: &Model, events: &[Event], times: &[i64]) -> Vec<[f32; 2]> {
    evtac_learn::flush_denormals();
    let crop = Resolution::new(240, 240);
    let roi = Roi::centered(SENSOR, crop).unwrap();
    let mut cropped = Vec::new();
    roi.crop_into(events, &mut cropped);
    let features =
        extract_features(&[model.repr_config()], crop, model.mask(), &cropped, times).unwrap();
    features[0]
        .chunks_exact(model.predictor.inputs())
        .map(|row| model.predictor.predict_one(row))
        .collect()
}

fn run_online(model: &Model, source: impl input::EventSource + 'static) -> Vec<Estimate> {
    let estimator = Estimator::for_model(model, SENSOR, 1000).unwrap();
    let mut estimates = Vec::new();
    let summary = pipeline::run(source, estimator, &PipelineConfig::default(), |out| {
        if let Output::Estimate(e) = out {
            estimates.push(e);
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    assert_eq!(summary.estimates, estimates.len() as u64);
    assert_eq!(summary.events_dropped, 0);
    assert_eq!(summary.events_out_of_order, 0);
    estimates
}

fn assert_same(online: &[Estimate], offline: &[[f32; 2]], what: &str) {
    assert_eq!(online.len(), offline.len(), "{what}: number of estimates");
    for (e, o) in online.iter().zip(offline) {
        assert_eq!(
            [e.pitch_deg.to_bits(), e.roll_deg.to_bits()],
            [o[0].to_bits(), o[1].to_bits()],
            "{what}: estimate at t = {} us differs: online {:?}, offline {o:?}",
            e.t_us,
            [e.pitch_deg, e.roll_deg]
        );
    }
}

#[test]
fn replayed_simulated_trial_matches_the_offline_pipeline_at_every_interval() {
    let (events, recording) = simulated_trial();
    assert!(
        events.len() > 10_000,
        "the trial has {} events",
        events.len()
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("trial.aedat4");
    evtac_sim::dataset::write_recording(&file, &recording, SENSOR, Compression::Lz4).unwrap();

    // A no-contact mask from the simulator's rest recording, as training would use.
    let rest = Simulator::new(short_params(), 7).simulate_rest(3);
    let crop = Resolution::new(240, 240);
    let roi = Roi::centered(SENSOR, crop).unwrap();
    let mut rest_cropped = Vec::new();
    roi.crop_into(&rest.events, &mut rest_cropped);
    let mask = evtac_repr::Mask::from_no_contact(crop, &Default::default(), &rest_cropped).unwrap();

    for (name, repr) in support::representations() {
        let model_dir = dir.path().join(name);
        support::seeded_bundle(&model_dir, 11, &repr, Some(mask.clone()));
        let model = Model::load(&model_dir).unwrap();
        assert!(model.mask().is_some());

        let opened = input::open(
            &SourceSpec::File(file.clone()),
            &OpenOptions::default(),
            &mut |_| {},
        )
        .unwrap();
        assert_eq!(opened.resolution, Some(SENSOR));
        let online = run_online(&model, opened.source);

        // Every grid time from the first multiple of 1 ms at or after the first event to the
        // last event, none missing, none twice.
        let first = events[0].t.div_euclid(1000) * 1000
            + if events[0].t.rem_euclid(1000) == 0 {
                0
            } else {
                1000
            };
        let last = events.last().unwrap().t;
        let times: Vec<i64> = (first..=last).step_by(1000).collect();
        let online_times: Vec<i64> = online.iter().map(|e| e.t_us).collect();
        assert_eq!(online_times, times, "{name}: estimate times");

        let expected = offline(&model, &events, &times);
        assert_same(&online, &expected, name);
        let distinct: std::collections::BTreeSet<u32> =
            expected.iter().map(|p| p[0].to_bits()).collect();
        assert!(
            distinct.len() > 10,
            "{name}: predictions barely vary ({} distinct), the comparison would be weak",
            distinct.len()
        );

        // Chunking does not matter: single events, odd sizes, and large blocks.
        for chunk in [1, 7, 65_536] {
            let part: Vec<Event> = events.iter().copied().take(60_000).collect();
            let online = run_online(&model, MemorySource::new(part.clone(), chunk));
            let times: Vec<i64> = online.iter().map(|e| e.t_us).collect();
            assert_same(&online, &offline(&model, &part, &times), name);
        }
    }
}

#[test]
fn realtime_replay_paces_and_still_matches() {
    let (events, _) = simulated_trial();
    // 300 ms of the trial from its busiest part keeps the test short.
    let mid = events[events.len() / 2].t;
    let part: Vec<Event> = events
        .iter()
        .copied()
        .filter(|e| e.t >= mid && e.t < mid + 300_000)
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let (_, repr) = support::representations()[2];
    support::seeded_bundle(dir.path(), 5, &repr, None);
    let model = Model::load(dir.path()).unwrap();
    let started = std::time::Instant::now();
    let paced = input::Paced::new(MemorySource::new(part.clone(), 4096), 1000);
    let online = run_online(&model, paced);
    let elapsed = started.elapsed();
    assert!(
        elapsed.as_secs_f64() >= 0.29,
        "a 300 ms replay at recorded pace took {elapsed:?}"
    );
    let times: Vec<i64> = online.iter().map(|e| e.t_us).collect();
    assert!(
        times.len() >= 299,
        "one estimate per millisecond: {}",
        times.len()
    );
    assert!(times.windows(2).all(|w| w[1] - w[0] == 1000));
    assert_same(&online, &offline(&model, &part, &times), "paced");
}
