//! Prints the event rate during the tilt and the simulation speed for a few speed-depth
//! combinations: `cargo run -p evtac-sim --example rates`.

use evtac_sim::{Protocol, Scale, SimParams, Simulator, plan};

fn main() {
    let params = SimParams::default();
    let sim = Simulator::new(params.clone(), 1);
    let base = plan(Protocol::Exp1, Scale::Tiny, 1, &params.timeline).remove(0);
    println!("speed depth  motion_rate(ev/s)  crop_rate  total_events  sim_s/wall_s");
    for (speed, depth) in [(2.0, 1.0), (2.0, 3.0), (6.0, 2.0), (10.0, 1.0), (10.0, 3.0)] {
        let mut spec = base.clone();
        spec.speed_deg_s = speed;
        spec.depth_mm = depth;
        let start = std::time::Instant::now();
        let r = sim.simulate(&spec);
        let wall = start.elapsed().as_secs_f64();
        let in_motion =
            |e: &&evtac_events::Event| e.t >= r.motion_start_us && e.t < r.motion_end_us;
        let secs = (r.motion_end_us - r.motion_start_us) as f64 * 1e-6;
        let n = r.events.iter().filter(in_motion).count();
        let crop = r
            .events
            .iter()
            .filter(in_motion)
            .filter(|e| (200..440).contains(&e.x) && (120..360).contains(&e.y))
            .count();
        println!(
            "{speed:5} {depth:5} {:18.0} {:10.0} {:13} {:12.2}",
            n as f64 / secs,
            crop as f64 / secs,
            r.events.len(),
            r.duration_us as f64 * 1e-6 / wall
        );
    }
}
