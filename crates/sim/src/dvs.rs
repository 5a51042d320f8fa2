//! The DVS pixel model (after v2e, Hu, Liu and Delbruck 2021), evaluated sparsely.
//!
//! Each pixel turns its brightness `I` into `L = ln(I + log_eps)`, low-pass filters it with the
//! photoreceptor's first-order response (3 dB cutoff `cutoff_hz` at full brightness, scaled by
//! `(255 I + 20) / 275` as in v2e so dark pixels are slower), and emits an ON (OFF) event each
//! time the filtered value rises (falls) by its own threshold from the level memorised at its last
//! event. Thresholds differ per pixel (normal, `sigma_thres`); after an event the pixel is blind
//! for `refractory_period_s` (a crossing in that time fires when it ends). Event times are
//! interpolated linearly within a simulation step.
//!
//! Only pixels near pins that moved since they were last drawn are re-rendered, plus pixels whose
//! filter is still settling; everything else is known to be static. Noise (leak ON events, shot
//! noise of both polarities, hot pixels) is drawn as Poisson processes over the whole sensor,
//! never pixel by pixel.

use evtac_events::Event;
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::params::{CameraParams, DvsParams};
use crate::sensor::PinImage;

/// The fixed pattern of one camera: per-pixel thresholds and hot pixels. Shared by every trial
/// of a dataset (it is the same camera).
#[derive(Debug, Clone)]
pub struct PixelArray {
    width: usize,
    pos_thres: Vec<f32>,
    neg_thres: Vec<f32>,
    /// Hot pixels: (pixel index, rate in Hz).
    hot: Vec<(usize, f64)>,
}

impl PixelArray {
    /// Draws the camera's fixed pattern from `seed`.
    pub fn new(dvs: &DvsParams, camera: &CameraParams, seed: u64) -> Self {
        let width = usize::from(camera.width);
        let n = width * usize::from(camera.height);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut draw = |mean: f64| -> Vec<f32> {
            match Normal::new(mean, dvs.sigma_thres.max(0.0)) {
                Ok(normal) => (0..n)
                    .map(|_| normal.sample(&mut rng).max(dvs.min_thres) as f32)
                    .collect(),
                Err(_) => vec![mean.max(dvs.min_thres) as f32; n],
            }
        };
        let pos_thres = draw(dvs.pos_thres);
        let neg_thres = draw(dvs.neg_thres);
        let [lo, hi] = dvs.hot_pixel_rate_hz;
        let hot = (0..dvs.hot_pixels)
            .filter(|_| n > 0)
            .map(|_| {
                (
                    rng.random_range(0..n),
                    lo + (hi - lo).max(0.0) * rng.random::<f64>(),
                )
            })
            .collect();
        Self {
            width,
            pos_thres,
            neg_thres,
            hot,
        }
    }

    /// The hot pixels as `(x, y, rate_hz)`.
    pub fn hot_pixels(&self) -> Vec<(u16, u16, f64)> {
        self.hot
            .iter()
            .map(|&(i, r)| ((i % self.width) as u16, (i / self.width) as u16, r))
            .collect()
    }
}

/// The scene's brightness: dark background with a soft vignette plus the pins' blobs. Pins are
/// looked up through a coarse grid so that a pixel only sums the few blobs that reach it.
struct Scene {
    width: usize,
    height: usize,
    background: f32,
    vignetting: f32,
    brightness: f32,
    cutoff: f32,
    /// Pins as last drawn.
    pins: Vec<PinImage>,
    cells_x: usize,
    /// Pin indices per grid cell.
    cells: Vec<Vec<u32>>,
}

const CELL: usize = 8;

impl Scene {
    fn new(camera: &CameraParams) -> Self {
        let (width, height) = (usize::from(camera.width), usize::from(camera.height));
        let cells_x = width.div_ceil(CELL);
        let cells_y = height.div_ceil(CELL);
        Self {
            width,
            height,
            background: camera.background as f32,
            vignetting: camera.vignetting as f32,
            brightness: camera.pin_brightness as f32,
            cutoff: camera.blob_cutoff_sigmas as f32,
            pins: Vec::new(),
            cells_x,
            cells: vec![Vec::new(); cells_x * cells_y],
        }
    }

    /// Pixel bounds `[x0, x1) x [y0, y1)` a blob reaches.
    fn bounds(&self, p: &PinImage) -> (usize, usize, usize, usize) {
        let r = self.cutoff * p.sigma;
        let clamp = |v: f32, hi: usize| (v.max(0.0) as usize).min(hi);
        (
            clamp((p.x - r).floor(), self.width),
            clamp((p.x + r).ceil() + 1.0, self.width),
            clamp((p.y - r).floor(), self.height),
            clamp((p.y + r).ceil() + 1.0, self.height),
        )
    }

    fn rebuild_grid(&mut self) {
        for c in &mut self.cells {
            c.clear();
        }
        for (i, p) in self.pins.iter().enumerate() {
            let (x0, x1, y0, y1) = self.bounds(p);
            if x0 >= x1 || y0 >= y1 {
                continue;
            }
            for cy in y0 / CELL..=(y1 - 1) / CELL {
                for cx in x0 / CELL..=(x1 - 1) / CELL {
                    self.cells[cy * self.cells_x + cx].push(i as u32);
                }
            }
        }
    }

    /// Linear brightness at pixel `(x, y)`.
    fn brightness(&self, x: usize, y: usize) -> f32 {
        let (fx, fy) = (x as f32, y as f32);
        let (cx, cy) = (self.width as f32 / 2.0, self.height as f32 / 2.0);
        let r2 = ((fx - cx) * (fx - cx) + (fy - cy) * (fy - cy)) / (cx * cx + cy * cy);
        let mut v = self.background * (1.0 - self.vignetting * r2);
        let cell = (y / CELL) * self.cells_x + x / CELL;
        let limit = self.cutoff * self.cutoff;
        let floor = (-0.5 * limit).exp();
        for &i in &self.cells[cell] {
            let p = &self.pins[i as usize];
            let (dx, dy) = (fx - p.x, fy - p.y);
            let q = (dx * dx + dy * dy) / (p.sigma * p.sigma);
            if q < limit {
                v += self.brightness * ((-0.5 * q).exp() - floor);
            }
        }
        v
    }
}

/// One trial's event camera: pixel states, the scene, and the noise processes.
pub struct Dvs<'a> {
    array: &'a PixelArray,
    params: DvsParams,
    scene: Scene,
    /// Log brightness the pixel currently sees.
    input: Vec<f32>,
    /// The photoreceptor's speed at the current brightness, `2 pi cutoff (255 I + 20) / 275`.
    rate: Vec<f32>,
    /// The photoreceptor's low-pass filtered log brightness.
    filtered: Vec<f32>,
    /// The log level memorised at the pixel's last event.
    memory: Vec<f32>,
    /// Time of the pixel's last event (seconds), for the refractory period.
    last_event: Vec<f64>,
    /// Step number at which a pixel was last queued (deduplicates the work list).
    stamp: Vec<u32>,
    /// Whether a queued pixel must be re-rendered this step.
    rerender: Vec<bool>,
    step: u32,
    /// Pixels still settling, carried into the next step.
    active: Vec<u32>,
    work: Vec<u32>,
    noise: NoiseProcess,
    /// Events of the current step, sorted before they are handed out.
    scratch: Vec<Event>,
    time: f64,
    /// Smallest pin motion (pixels) that makes a pin be redrawn.
    redraw_px: f32,
}

impl<'a> Dvs<'a> {
    /// A camera looking at `pins` at time zero (every pixel starts settled on that image).
    pub fn new(
        array: &'a PixelArray,
        params: &DvsParams,
        camera: &CameraParams,
        pins: &[PinImage],
        noise_seed: u64,
    ) -> Self {
        let mut scene = Scene::new(camera);
        scene.pins = pins.to_vec();
        scene.rebuild_grid();
        let n = scene.width * scene.height;
        let eps = params.log_eps as f32;
        let mut input = Vec::with_capacity(n);
        let mut rate = Vec::with_capacity(n);
        for y in 0..scene.height {
            for x in 0..scene.width {
                let b = scene.brightness(x, y);
                input.push((b + eps).ln());
                rate.push(photoreceptor_rate(params.cutoff_hz, b));
            }
        }
        let noise = NoiseProcess::new(array, params, n, noise_seed);
        Self {
            array,
            params: params.clone(),
            filtered: input.clone(),
            memory: input.clone(),
            input,
            rate,
            last_event: vec![f64::NEG_INFINITY; n],
            stamp: vec![0; n],
            rerender: vec![false; n],
            step: 0,
            active: Vec::new(),
            work: Vec::new(),
            noise,
            scratch: Vec::new(),
            time: 0.0,
            redraw_px: params.redraw_px as f32,
            scene,
        }
    }

    /// Advances the camera to time `t1` (seconds), with the pins now at `pins`, appending the
    /// step's events (time-sorted) to `out`.
    pub fn step(&mut self, t1: f64, pins: &[PinImage], out: &mut Vec<Event>) {
        let t0 = self.time;
        let dt = t1 - t0;
        if dt <= 0.0 {
            return;
        }
        self.step = self.step.wrapping_add(1).max(1);
        self.work.clear();
        self.scratch.clear();

        // Pins that moved enough since they were last drawn: queue their old and new footprint.
        let mut moved = false;
        for (i, new) in pins.iter().enumerate() {
            let Some(old) = self.scene.pins.get(i).copied() else {
                continue;
            };
            let shift = (new.x - old.x).abs().max((new.y - old.y).abs());
            if shift < self.redraw_px && (new.sigma - old.sigma).abs() < 0.01 * old.sigma {
                continue;
            }
            moved = true;
            for p in [old, *new] {
                let (x0, x1, y0, y1) = self.scene.bounds(&p);
                for y in y0..y1 {
                    for x in x0..x1 {
                        let k = y * self.scene.width + x;
                        if self.stamp[k] != self.step {
                            self.stamp[k] = self.step;
                            self.work.push(k as u32);
                        }
                        self.rerender[k] = true;
                    }
                }
            }
            self.scene.pins[i] = *new;
        }
        if moved {
            self.scene.rebuild_grid();
        }
        for &k in &self.active {
            if self.stamp[k as usize] != self.step {
                self.stamp[k as usize] = self.step;
                self.work.push(k);
            }
        }
        self.active.clear();

        let eps = self.params.log_eps as f32;
        let dt32 = dt as f32;
        let refractory = self.params.refractory_period_s;
        let width = self.scene.width;
        for wi in 0..self.work.len() {
            let k = self.work[wi] as usize;
            if std::mem::take(&mut self.rerender[k]) {
                let b = self.scene.brightness(k % width, k / width);
                self.input[k] = (b + eps).ln();
                self.rate[k] = photoreceptor_rate(self.params.cutoff_hz, b);
            }
            let target = self.input[k];
            let before = self.filtered[k];
            // Exact first-order response to an input held over the step.
            let after = target + (before - target) * (-self.rate[k] * dt32).exp();
            self.filtered[k] = after;
            self.fire(k, t0, t1, before, after, refractory);
            // Settled to a tenth of a threshold: no event can come from the remainder alone.
            let settled = (target - after).abs() < 0.02;
            let pending = {
                let diff = after - self.memory[k];
                diff >= self.array.pos_thres[k] || -diff >= self.array.neg_thres[k]
            };
            if !settled || pending {
                self.active.push(k as u32);
            }
        }
        self.noise.emit(t0, t1, width, &mut self.scratch);
        self.scratch
            .sort_unstable_by_key(|e| (e.t, e.y, e.x, e.polarity));
        out.extend_from_slice(&self.scratch);
        self.time = t1;
    }

    /// Emits the threshold crossings of pixel `k` while its filtered level goes from `before`
    /// (at `t0`) to `after` (at `t1`).
    fn fire(&mut self, k: usize, t0: f64, t1: f64, before: f32, after: f32, refractory: f64) {
        let (x, y) = ((k % self.scene.width) as u16, (k / self.scene.width) as u16);
        let span = after - before;
        loop {
            let diff = after - self.memory[k];
            let (on, thres) = if diff >= self.array.pos_thres[k] {
                (true, self.array.pos_thres[k])
            } else if -diff >= self.array.neg_thres[k] {
                (false, self.array.neg_thres[k])
            } else {
                return;
            };
            let level = self.memory[k] + if on { thres } else { -thres };
            // Where the level was crossed within the step (at t0 if it was already crossed when
            // the refractory period held the event back).
            let frac = if span.abs() > f32::EPSILON {
                f64::from(((level - before) / span).clamp(0.0, 1.0))
            } else {
                0.0
            };
            let t = (t0 + frac * (t1 - t0)).max(self.last_event[k] + refractory);
            if t > t1 {
                return;
            }
            self.memory[k] = level;
            self.last_event[k] = t;
            self.scratch.push(Event {
                t: (t * 1e6).round() as i64,
                x,
                y,
                polarity: on,
            });
        }
    }

    /// Number of pixels whose filter is still settling (for tests and diagnostics).
    pub fn settling_pixels(&self) -> usize {
        self.active.len()
    }

    /// The linear brightness image as last drawn (row-major, full sensor), for figures.
    pub fn brightness_image(&self) -> Vec<f32> {
        let mut img = Vec::with_capacity(self.scene.width * self.scene.height);
        for y in 0..self.scene.height {
            for x in 0..self.scene.width {
                img.push(self.scene.brightness(x, y));
            }
        }
        img
    }
}

/// The photoreceptor's low-pass rate (1/s) at linear brightness `b`: v2e's intensity-dependent
/// bandwidth, `(255 b + 20) / 275` of the cutoff, so dark pixels respond slower.
fn photoreceptor_rate(cutoff_hz: f64, b: f32) -> f32 {
    (2.0 * std::f64::consts::PI * cutoff_hz) as f32 * (255.0 * b.max(0.0) + 20.0) / 275.0
}

/// Leak, shot and hot-pixel noise as one merged Poisson process.
struct NoiseProcess {
    rng: ChaCha8Rng,
    pixels: usize,
    leak_rate: f64,
    shot_rate: f64,
    hot: Vec<(usize, f64)>,
    total: f64,
    next: f64,
}

impl NoiseProcess {
    fn new(array: &PixelArray, params: &DvsParams, pixels: usize, seed: u64) -> Self {
        let leak_rate = params.leak_rate_hz.max(0.0) * pixels as f64;
        let shot_rate = params.shot_noise_rate_hz.max(0.0) * pixels as f64;
        let hot_rate: f64 = array.hot.iter().map(|h| h.1.max(0.0)).sum();
        let mut p = Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
            pixels,
            leak_rate,
            shot_rate,
            hot: array.hot.clone(),
            total: leak_rate + shot_rate + hot_rate,
            next: 0.0,
        };
        p.next = p.interval();
        p
    }

    fn interval(&mut self) -> f64 {
        if self.total <= 0.0 {
            return f64::INFINITY;
        }
        // Exponential inter-arrival times; 1 - u avoids ln(0).
        -(1.0 - self.rng.random::<f64>()).ln() / self.total
    }

    fn emit(&mut self, t0: f64, t1: f64, width: usize, out: &mut Vec<Event>) {
        while self.next < t1 {
            let t = self.next.max(t0);
            self.next += self.interval();
            let pick = self.rng.random::<f64>() * self.total;
            let (k, on) = if pick < self.leak_rate {
                (self.rng.random_range(0..self.pixels), true)
            } else if pick < self.leak_rate + self.shot_rate {
                (self.rng.random_range(0..self.pixels), self.rng.random())
            } else {
                let mut r = pick - self.leak_rate - self.shot_rate;
                let mut chosen = self.hot.last().map_or(0, |h| h.0);
                for &(i, rate) in &self.hot {
                    if r < rate {
                        chosen = i;
                        break;
                    }
                    r -= rate;
                }
                (chosen, self.rng.random())
            };
            out.push(Event {
                t: (t * 1e6).round() as i64,
                x: (k % width) as u16,
                y: (k / width) as u16,
                polarity: on,
            });
        }
    }
}

/// Draws a standard normal value (used for IMU noise).
pub(crate) fn gaussian<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    rand_distr::StandardNormal.sample(rng)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quiet() -> DvsParams {
        DvsParams::noiseless()
    }

    fn pin(x: f32) -> PinImage {
        PinImage {
            x,
            y: 240.0,
            sigma: 2.5,
        }
    }

    #[test]
    fn static_scene_makes_no_events_and_moving_pin_does() {
        let (dvs, cam) = (quiet(), CameraParams::default());
        let array = PixelArray::new(&dvs, &cam, 1);
        let mut cam_model = Dvs::new(&array, &dvs, &cam, &[pin(300.0)], 2);
        let mut events = Vec::new();
        for i in 1..=100 {
            cam_model.step(f64::from(i) * 1e-3, &[pin(300.0)], &mut events);
        }
        assert!(events.is_empty());
        for i in 101..=200 {
            let x = 300.0 + 0.2 * (i - 100) as f32;
            cam_model.step(f64::from(i) * 1e-3, &[pin(x)], &mut events);
        }
        let on = events.iter().filter(|e| e.polarity).count();
        let off = events.len() - on;
        assert!(on > 50 && off > 50, "on {on} off {off}");
        assert!(events.windows(2).all(|w| w[0].t <= w[1].t));
        assert!(events.iter().all(|e| e.t > 100_000 && e.t <= 200_000));
        // Moving right: ON events lead (right of the pin), OFF events trail.
        let mean_x = |p: bool| {
            let v: Vec<f64> = events
                .iter()
                .filter(|e| e.polarity == p)
                .map(|e| f64::from(e.x))
                .collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        assert!(mean_x(true) > mean_x(false));
    }

    #[test]
    fn refractory_period_is_respected() {
        let (dvs, cam) = (quiet(), CameraParams::default());
        let array = PixelArray::new(&dvs, &cam, 1);
        let mut model = Dvs::new(&array, &dvs, &cam, &[pin(300.0)], 2);
        let mut events = Vec::new();
        // A jump: many thresholds at once in one pixel.
        model.step(1e-3, &[pin(310.0)], &mut events);
        for i in 2..50 {
            model.step(f64::from(i) * 1e-3, &[pin(310.0)], &mut events);
        }
        let mut by_pixel = std::collections::HashMap::<(u16, u16), Vec<i64>>::new();
        for e in &events {
            by_pixel.entry((e.x, e.y)).or_default().push(e.t);
        }
        assert!(by_pixel.values().any(|v| v.len() > 3));
        for times in by_pixel.values() {
            assert!(times.windows(2).all(|w| w[1] - w[0] >= 499), "{times:?}");
        }
    }

    #[test]
    fn noise_rate_matches_parameters() {
        let cam = CameraParams::default();
        let dvs = DvsParams {
            leak_rate_hz: 0.05,
            shot_noise_rate_hz: 0.05,
            hot_pixels: 0,
            ..DvsParams::default()
        };
        let array = PixelArray::new(&dvs, &cam, 1);
        let mut model = Dvs::new(&array, &dvs, &cam, &[], 3);
        let mut events = Vec::new();
        model.step(1.0, &[], &mut events);
        let expected = 0.1 * 640.0 * 480.0;
        let n = events.len() as f64;
        assert!(
            (n - expected).abs() < 5.0 * expected.sqrt(),
            "{n} vs {expected}"
        );
    }
}
