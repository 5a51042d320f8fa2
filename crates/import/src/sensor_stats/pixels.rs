//! The pixels at rest: each pixel's events counted over the rest bins, hot pixels told from the
//! background by a Poisson tail, and the background's ON and OFF rates per pixel.
//!
//! At rest every ordinary pixel fires at the same low rate (the simulator's leak and shot noise,
//! drawn uniformly over the sensor), so its count over the rest time is Poisson with the
//! background's mean. A pixel is hot when its count is one that fewer than [`FALSE_HOT`] pixels
//! of the whole sensor would reach by chance: a pixel is only called hot on evidence, whatever
//! the sensor's size and the rest time.

use evtac_events::{Event, Resolution};
use serde::Serialize;

/// Expected number of ordinary pixels called hot by chance over the whole sensor.
pub const FALSE_HOT: f64 = 0.01;

/// Each pixel's events at rest.
#[derive(Debug, Clone)]
pub struct PixelCounts {
    width: usize,
    events: Vec<u32>,
    on: Vec<u32>,
}

impl PixelCounts {
    /// No events yet on a sensor of `resolution`.
    pub fn new(resolution: Resolution) -> Self {
        let n = usize::from(resolution.width) * usize::from(resolution.height);
        Self {
            width: usize::from(resolution.width),
            events: vec![0; n],
            on: vec![0; n],
        }
    }

    /// Counts `e` (the readers have checked it lies on the sensor).
    pub fn add(&mut self, e: &Event) {
        let k = usize::from(e.y) * self.width + usize::from(e.x);
        if let (Some(n), Some(on)) = (self.events.get_mut(k), self.on.get_mut(k)) {
            *n = n.saturating_add(1);
            *on = on.saturating_add(u32::from(e.polarity));
        }
    }
}

/// A pixel that fires far more than the background at rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HotPixel {
    /// Column.
    pub x: u16,
    /// Row.
    pub y: u16,
    /// Its event rate at rest, Hz.
    pub rate_hz: f64,
}

/// The ordinary pixels' activity at rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Background {
    /// The rest time the counts cover, s.
    pub rest_s: f64,
    /// Pixels that are not hot.
    pub pixels: u64,
    /// Fewest events at rest that make a pixel hot.
    pub hot_threshold: u32,
    /// ON events per pixel per second.
    pub on_rate_hz: f64,
    /// OFF events per pixel per second.
    pub off_rate_hz: f64,
}

impl Background {
    /// Events per pixel per second.
    pub fn rate_hz(&self) -> f64 {
        self.on_rate_hz + self.off_rate_hz
    }

    /// The fraction of the background's events that are ON.
    pub fn on_fraction(&self) -> Option<f64> {
        (self.rate_hz() > 0.0).then(|| self.on_rate_hz / self.rate_hz())
    }

    /// The simulator's leak rate (ON only) that gives these rates with [`Self::shot_rate_hz`]:
    /// what ON exceeds OFF by, as shot noise is ON and OFF alike.
    pub fn leak_rate_hz(&self) -> f64 {
        (self.on_rate_hz - self.off_rate_hz).max(0.0)
    }

    /// The simulator's shot-noise rate (ON and OFF together): the rest of the background. When
    /// OFF exceeds ON (which the simulator's noise cannot do) the total rate is still kept.
    pub fn shot_rate_hz(&self) -> f64 {
        self.rate_hz() - self.leak_rate_hz()
    }
}

/// The hot pixels and the background of `counts` over `rest_s` seconds at rest, or `None` when
/// there was no rest.
pub fn split(counts: &PixelCounts, rest_s: f64) -> Option<(Background, Vec<HotPixel>)> {
    let n = counts.events.len();
    if rest_s <= 0.0 || n == 0 {
        return None;
    }
    // The mean first includes the hot pixels' events; once they are known it is taken again
    // without them (the threshold only ever drops).
    let mut threshold = u32::MAX;
    for _ in 0..2 {
        let (sum, kept) = counts
            .events
            .iter()
            .filter(|&&c| c < threshold)
            .fold((0u64, 0u64), |(s, k), &c| (s + u64::from(c), k + 1));
        threshold = poisson_threshold(sum as f64 / kept.max(1) as f64, n);
    }
    let mut hot = Vec::new();
    let (mut on, mut off, mut pixels) = (0u64, 0u64, 0u64);
    for (k, (&events, &on_k)) in counts.events.iter().zip(&counts.on).enumerate() {
        if events >= threshold {
            hot.push(HotPixel {
                x: (k % counts.width) as u16,
                y: (k / counts.width) as u16,
                rate_hz: f64::from(events) / rest_s,
            });
        } else {
            on += u64::from(on_k);
            off += u64::from(events - on_k);
            pixels += 1;
        }
    }
    let per_pixel = |c: u64| c as f64 / (pixels.max(1) as f64 * rest_s);
    let background = Background {
        rest_s,
        pixels,
        hot_threshold: threshold,
        on_rate_hz: per_pixel(on),
        off_rate_hz: per_pixel(off),
    };
    Some((background, hot))
}

/// The smallest count `k` with `pixels * P(X >= k) < FALSE_HOT` for `X` Poisson with `mean`.
/// The tail is summed from the far end, in logs, so it stays exact where `1 - cdf` would round
/// to nothing.
pub fn poisson_threshold(mean: f64, pixels: usize) -> u32 {
    let mean = mean.max(1e-9);
    let last = (mean + 40.0 * mean.sqrt() + 100.0).ceil() as usize;
    let ln_mean = mean.ln();
    let mut ln_pmf = Vec::with_capacity(last + 1);
    let mut ln_p = -mean;
    for j in 0..=last {
        if j > 0 {
            ln_p += ln_mean - (j as f64).ln();
        }
        ln_pmf.push(ln_p);
    }
    let mut tail = 0.0;
    let mut k = last + 1;
    for j in (0..=last).rev() {
        tail += ln_pmf[j].exp();
        if pixels as f64 * tail >= FALSE_HOT {
            break;
        }
        k = j;
    }
    u32::try_from(k).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_threshold_is_the_poisson_tail_over_the_sensor() {
        // Mean 1 over 100 pixels: P(X >= 6) = 5.94e-4, P(X >= 7) = 8.32e-5 (1 minus the sum
        // of exp(-1) / j! for j below 6 and 7): 100 * 8.32e-5 < 0.01 <= 100 * 5.94e-4.
        assert_eq!(poisson_threshold(1.0, 100), 7);
        // A large mean: about 6 sigma above it for a VGA sensor.
        let k = poisson_threshold(10_000.0, 307_200);
        assert!((10_500..10_600).contains(&k), "{k}");
    }

    #[test]
    fn hot_pixels_stand_out_and_the_background_splits_into_on_and_off() {
        let mut counts = PixelCounts::new(Resolution::new(100, 100));
        // Every pixel: 3 ON and 1 OFF event over 10 s; pixel (7, 2) fires 500 events.
        for k in 0..10_000u32 {
            let (x, y) = ((k % 100) as u16, (k / 100) as u16);
            for polarity in [true, true, true, false] {
                counts.add(&Event {
                    t: 0,
                    x,
                    y,
                    polarity,
                });
            }
        }
        for _ in 0..496 {
            counts.add(&Event {
                t: 0,
                x: 7,
                y: 2,
                polarity: false,
            });
        }
        let (bg, hot) = split(&counts, 10.0).unwrap();
        assert_eq!(
            hot,
            [HotPixel {
                x: 7,
                y: 2,
                rate_hz: 50.0
            }]
        );
        assert_eq!(bg.pixels, 9_999);
        assert!((bg.on_rate_hz - 0.3).abs() < 1e-12 && (bg.off_rate_hz - 0.1).abs() < 1e-12);
        assert!((bg.leak_rate_hz() - 0.2).abs() < 1e-12);
        assert!((bg.shot_rate_hz() - 0.2).abs() < 1e-12);
        assert!((bg.on_fraction().unwrap() - 0.75).abs() < 1e-12);
        assert!(split(&counts, 0.0).is_none());
    }
}
