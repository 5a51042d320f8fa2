//! The simulated sensor behaves as the paper's did: more events when faster and deeper, only
//! noise without contact, recoil then quiet in a stop.

use evtac_events::Event;
use evtac_sim::params::DvsParams;
use evtac_sim::{Protocol, Scale, SimParams, Simulator, TrialRecording, TrialSpec, plan};

/// A simulator without noise (so counts are the sensor's own), tilting to 10 degrees only to
/// keep the tests fast.
fn quiet() -> Simulator {
    let mut params = SimParams {
        dvs: DvsParams::noiseless(),
        ..SimParams::default()
    };
    params.timeline.total_deg = 10.0;
    Simulator::new(params, 3)
}

fn spec(protocol: Protocol, speed: f64, depth: f64) -> TrialSpec {
    let mut s = plan(protocol, Scale::Tiny, 1, &Default::default()).remove(1);
    s.speed_deg_s = speed;
    s.depth_mm = depth;
    s
}

fn rate(events: &[Event], from_us: i64, to_us: i64) -> f64 {
    let n = events
        .iter()
        .filter(|e| e.t >= from_us && e.t < to_us)
        .count();
    n as f64 / ((to_us - from_us) as f64 * 1e-6)
}

fn motion_rate(r: &TrialRecording) -> f64 {
    rate(&r.events, r.motion_start_us, r.motion_end_us)
}

#[test]
fn event_rate_grows_with_speed_and_depth() {
    let sim = quiet();
    let slow = motion_rate(&sim.simulate(&spec(Protocol::Exp1, 4.0, 2.0)));
    let fast = motion_rate(&sim.simulate(&spec(Protocol::Exp1, 10.0, 2.0)));
    let shallow = motion_rate(&sim.simulate(&spec(Protocol::Exp1, 10.0, 1.0)));
    let deep = motion_rate(&sim.simulate(&spec(Protocol::Exp1, 10.0, 3.0)));
    assert!(fast > 1.5 * slow, "speed: {slow} -> {fast}");
    assert!(
        deep > 1.5 * fast && fast > 1.2 * shallow,
        "depth: {shallow} {fast} {deep}"
    );
    // Realistic magnitudes for a DVXplorer on a NeuroTac.
    assert!((50e3..600e3).contains(&deep), "{deep}");
}

#[test]
fn no_contact_is_sparse_uniform_noise() {
    let sim = Simulator::new(SimParams::default(), 3);
    let rest = sim.simulate_rest(8);
    let moving = sim.simulate(&spec(Protocol::NoContact, 10.0, 0.0));
    let hot: Vec<(u16, u16)> = sim
        .pixel_array()
        .hot_pixels()
        .iter()
        .map(|h| (h.0, h.1))
        .collect();
    for r in [&rest, &moving] {
        let secs = r.duration_us as f64 * 1e-6;
        let noise: Vec<&Event> = r
            .events
            .iter()
            .filter(|e| !hot.contains(&(e.x, e.y)))
            .collect();
        let expected = (0.01 + 0.02) * 640.0 * 480.0 * secs;
        let n = noise.len() as f64;
        assert!(
            (n - expected).abs() < 5.0 * expected.sqrt(),
            "{n} vs {expected}"
        );
        // As dense inside the pin array's crop as outside it.
        let inside = noise
            .iter()
            .filter(|e| (200..440).contains(&e.x) && (120..360).contains(&e.y))
            .count() as f64;
        let share = inside / n;
        let area = (240.0 * 240.0) / (640.0 * 480.0);
        assert!((share - area).abs() < 0.04, "{share} vs {area}");
    }
}

#[test]
fn a_stop_shows_recoil_then_quiet() {
    let sim = quiet();
    let mut s = spec(Protocol::Exp2, 10.0, 3.0);
    s.stop_deg = Some(5.0);
    let r = sim.simulate(&s);
    let (s0, s1) = r.stop_us.unwrap();
    let moving = rate(&r.events, r.motion_start_us + 100_000, s0);
    let recoil = rate(&r.events, s0, s0 + 100_000);
    let late = rate(&r.events, s1 - 200_000, s1);
    assert!(recoil > 0.05 * moving, "recoil {recoil} vs motion {moving}");
    assert!(late < 0.1 * recoil, "late {late} vs recoil {recoil}");
    // What is left late in the stop is the skin's creep: a trickle.
    assert!(late < 0.05 * moving, "late {late} vs motion {moving}");
    // The rate decays through the stop.
    let quarters: Vec<f64> = (0..4)
        .map(|q| rate(&r.events, s0 + q * 125_000, s0 + (q + 1) * 125_000))
        .collect();
    assert!(quarters.windows(2).all(|w| w[1] <= w[0]), "{quarters:?}");
}
