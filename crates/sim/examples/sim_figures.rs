//! Renders the documentation figures of `docs/simulator.md` into `docs/img/`:
//! `cargo run -p evtac-sim --example sim_figures [-- OUT_DIR]`.
//!
//! `sim_frames.png`: one trial (tilt direction 0, 6 deg/s, 2.5 mm) at four commanded tilts; rows
//! are the camera's brightness (what a frame camera inside the tip would see, gamma 0.5), the dynamic view
//! (events of the last 50 ms, ON red, OFF blue) and the static view (per-pixel exponentially
//! decayed accumulation, tau 1 s, ON and OFF contributions added with their signs), all on the
//! centered 240x240 crop. `sim_stop.png`: the event rate of an Experiment 2 trial, with the stop
//! shaded and a grey line every second, showing the recoil after the stop and the quiet that follows.

use std::path::{Path, PathBuf};

use evtac_events::Event;
use evtac_sim::{Protocol, Scale, SimParams, Simulator, SkinPose, plan};

const CROP: usize = 240;
const X0: usize = 200;
const Y0: usize = 120;
const GAP: usize = 6;

/// An RGB image being composed.
struct Canvas {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            rgb: vec![255; width * height * 3],
        }
    }

    fn put(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let k = (y * self.width + x) * 3;
            self.rgb[k..k + 3].copy_from_slice(&c);
        }
    }

    fn save(&self, path: &Path) -> Result<(), Box<dyn std::error::Error>> {
        let file = std::io::BufWriter::new(std::fs::File::create(path)?);
        let mut enc = png::Encoder::new(file, self.width as u32, self.height as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.write_header()?.write_image_data(&self.rgb)?;
        Ok(())
    }
}

fn in_crop(e: &Event) -> Option<(usize, usize)> {
    let (x, y) = (usize::from(e.x), usize::from(e.y));
    ((X0..X0 + CROP).contains(&x) && (Y0..Y0 + CROP).contains(&y)).then(|| (x - X0, y - Y0))
}

/// Red for positive, blue for negative, white at zero; `v` in [-1, 1].
fn diverging(v: f32) -> [u8; 3] {
    let v = v.clamp(-1.0, 1.0);
    let fade = |a: f32| (255.0 * (1.0 - a)) as u8;
    if v >= 0.0 {
        [255, fade(v), fade(v)]
    } else {
        [fade(-v), fade(-v), 255]
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("docs/img"));
    std::fs::create_dir_all(&out)?;
    let params = SimParams::default();
    let sim = Simulator::new(params.clone(), 1);
    let mut spec = plan(Protocol::Exp1, Scale::Tiny, 1, &params.timeline).remove(0);
    spec.direction_deg = 0.0;
    spec.speed_deg_s = 6.0;
    spec.depth_mm = 2.5;
    let rec = sim.simulate(&spec);
    let tilts = [0.0, 5.0, 12.0, 20.0];
    let mut canvas = Canvas::new(4 * CROP + 3 * GAP, 3 * CROP + 2 * GAP);
    for (col, &tilt) in tilts.iter().enumerate() {
        // The time the commanded tilt reaches `tilt` (the truth is at 1 kHz).
        let t_us = rec
            .truth
            .iter()
            .find(|s| s.t_us >= rec.motion_start_us && s.theta_deg >= tilt - 1e-9)
            .map_or(rec.motion_start_us, |s| s.t_us);
        let ox = col * (CROP + GAP);
        // Row 1: brightness at the commanded pose (skin lag ignored), log-scaled grey.
        let pose = SkinPose {
            theta_deg: tilt,
            phi_deg: spec.direction_deg,
            depth_mm: spec.depth_mm,
            lag_deg: 0.0,
        };
        let img = sim.brightness_image(&pose);
        for y in 0..CROP {
            for x in 0..CROP {
                let b = img[(y + Y0) * usize::from(params.camera.width) + x + X0];
                // Gamma 0.5: the dark background stays dark, the blobs do not saturate.
                let g = b.clamp(0.0, 1.0).sqrt();
                let v = (255.0 * g) as u8;
                canvas.put(ox + x, y, [v, v, v]);
            }
        }
        // Row 2: the last 50 ms of events.
        let mut counts = vec![0i32; CROP * CROP];
        for e in rec
            .events
            .iter()
            .filter(|e| e.t > t_us - 50_000 && e.t <= t_us)
        {
            if let Some((x, y)) = in_crop(e) {
                counts[y * CROP + x] += if e.polarity { 1 } else { -1 };
            }
        }
        for y in 0..CROP {
            for x in 0..CROP {
                let c = counts[y * CROP + x] as f32 / 3.0;
                canvas.put(ox + x, CROP + GAP + y, diverging(c));
            }
        }
        // Row 3: decayed accumulation with tau = 1 s from the start of the recording.
        let mut potential = vec![0f32; CROP * CROP];
        let mut last = vec![0i64; CROP * CROP];
        for e in rec.events.iter().filter(|e| e.t <= t_us) {
            if let Some((x, y)) = in_crop(e) {
                let k = y * CROP + x;
                let decay = (-((e.t - last[k]) as f32) * 1e-6).exp();
                potential[k] = potential[k] * decay + if e.polarity { 1.0 } else { -1.0 };
                last[k] = e.t;
            }
        }
        for y in 0..CROP {
            for x in 0..CROP {
                let k = y * CROP + x;
                let v = potential[k] * (-((t_us - last[k]) as f32) * 1e-6).exp();
                canvas.put(ox + x, 2 * (CROP + GAP) + y, diverging(v / 3.0));
            }
        }
    }
    canvas.save(&out.join("sim_frames.png"))?;

    // The stop: event rate in 10 ms bins of an Experiment 2 trial.
    let mut stop_spec = plan(Protocol::Exp2, Scale::Tiny, 1, &params.timeline).remove(0);
    stop_spec.speed_deg_s = 10.0;
    stop_spec.depth_mm = 3.0;
    stop_spec.stop_deg = Some(10.0);
    let rec = sim.simulate(&stop_spec);
    let (s0, s1) = rec.stop_us.unwrap_or((0, 0));
    let bin = 10_000;
    let bins = (rec.duration_us / bin + 1) as usize;
    let mut rate = vec![0f32; bins];
    for e in &rec.events {
        rate[(e.t / bin) as usize] += 1.0;
    }
    let peak = rate.iter().copied().fold(1.0, f32::max);
    let (w, h) = (bins.min(1200), 300);
    let mut plot = Canvas::new(w, h);
    for (i, r) in rate.iter().enumerate().take(w) {
        let t = i as i64 * bin;
        let shade = if t % 1_000_000 < bin {
            [180, 180, 180] // a grey line every second
        } else if (s0..s1).contains(&t) {
            [235, 235, 200]
        } else {
            [255, 255, 255]
        };
        let top = h - 1 - ((r / peak) * (h - 10) as f32) as usize;
        for y in 0..h {
            plot.put(i, y, if y >= top { [40, 40, 40] } else { shade });
        }
    }
    plot.save(&out.join("sim_stop.png"))?;
    println!(
        "wrote {} and {} (stop {}..{} us, peak {} events per 10 ms)",
        out.join("sim_frames.png").display(),
        out.join("sim_stop.png").display(),
        s0,
        s1,
        peak
    );
    Ok(())
}
