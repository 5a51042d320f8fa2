//! Trapezoidal integration of a rate sampled at irregular times, readable at any instant.
//!
//! The rate is taken as piecewise linear between samples, so the running integral at a sample is
//! exactly the cumulative trapezoid rule (`scipy.integrate.cumulative_trapezoid`) and between
//! samples it is the exact integral of the linear interpolant. That lets integration start at the
//! motion onset and stop at its end even when those fall between IMU samples.

/// What makes a series unintegrable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IntegrationError {
    /// Times and values differ in number.
    #[error("{times} times but {values} values")]
    LengthMismatch {
        /// Number of times.
        times: usize,
        /// Number of values.
        values: usize,
    },
    /// Nothing to integrate.
    #[error("no samples to integrate")]
    Empty,
    /// Times must strictly increase.
    #[error("time {t_us} us at index {index} is not after the previous time {previous_us} us")]
    NotIncreasing {
        /// Index of the offending time.
        index: usize,
        /// The offending time.
        t_us: i64,
        /// The time before it.
        previous_us: i64,
    },
}

/// The running integral `I(t) = integral from t[0] to t of y`, with `t` in microseconds and `y`
/// per second (deg/s in, deg out).
#[derive(Debug, Clone, PartialEq)]
pub struct CumulativeTrapezoid {
    t_us: Vec<i64>,
    y: Vec<f64>,
    cumulative: Vec<f64>,
}

impl CumulativeTrapezoid {
    /// Integrates `y` sampled at the strictly increasing times `t_us`.
    pub fn new(t_us: &[i64], y: &[f64]) -> Result<Self, IntegrationError> {
        if t_us.len() != y.len() {
            return Err(IntegrationError::LengthMismatch {
                times: t_us.len(),
                values: y.len(),
            });
        }
        if t_us.is_empty() {
            return Err(IntegrationError::Empty);
        }
        let mut cumulative = Vec::with_capacity(y.len());
        let mut sum = 0.0;
        cumulative.push(sum);
        for i in 1..t_us.len() {
            if t_us[i] <= t_us[i - 1] {
                return Err(IntegrationError::NotIncreasing {
                    index: i,
                    t_us: t_us[i],
                    previous_us: t_us[i - 1],
                });
            }
            sum = step(sum, (t_us[i - 1], y[i - 1]), (t_us[i], y[i]));
            cumulative.push(sum);
        }
        Ok(Self {
            t_us: t_us.to_vec(),
            y: y.to_vec(),
            cumulative,
        })
    }

    /// The running integral at each sample time (the cumulative trapezoid rule, starting at 0).
    pub fn at_samples(&self) -> &[f64] {
        &self.cumulative
    }

    /// The integral from the first sample to `t_us`. Outside the sampled span the rate counts as
    /// zero, so the integral holds its end values there.
    pub fn at(&self, t_us: i64) -> f64 {
        let n = self.t_us.len();
        if t_us <= self.t_us[0] {
            return 0.0;
        }
        if t_us >= self.t_us[n - 1] {
            return self.cumulative[n - 1];
        }
        // The sample at or before t_us: t[i] <= t_us < t[i + 1].
        let i = self.t_us.partition_point(|&s| s <= t_us) - 1;
        let (before, after) = ((self.t_us[i], self.y[i]), (self.t_us[i + 1], self.y[i + 1]));
        interpolate(self.cumulative[i], before, after, t_us)
    }

    /// The integral from `from_us` to `to_us`.
    pub fn between(&self, from_us: i64, to_us: i64) -> f64 {
        self.at(to_us) - self.at(from_us)
    }
}

/// The running integral `sum` at sample `(t0, y0)` carried to the next sample `(t1, y1)`: one
/// step of the cumulative trapezoid rule.
fn step(sum: f64, (t0, y0): (i64, f64), (t1, y1): (i64, f64)) -> f64 {
    let dt = (t1 - t0) as f64 * 1e-6;
    sum + 0.5 * (y1 + y0) * dt
}

/// The running integral at `t_us`, between the samples `(t0, y0)` (where it is `at0`) and
/// `(t1, y1)`: the exact integral of the linear interpolant.
fn interpolate(at0: f64, (t0, y0): (i64, f64), (t1, y1): (i64, f64), t_us: i64) -> f64 {
    let span = (t1 - t0) as f64;
    let frac = (t_us - t0) as f64 / span;
    let y_t = y0 + frac * (y1 - y0);
    let dt = (t_us - t0) as f64 * 1e-6;
    at0 + 0.5 * (y0 + y_t) * dt
}

/// [`CumulativeTrapezoid`] built sample by sample, for a series too long to hold: it keeps the
/// last sample and its running integral only, and answers [`CumulativeTrapezoid::at`] (the same
/// value, bit for bit) for instants before the next sample, which is how a caller streaming a
/// long series asks, in time order.
///
/// ```
/// use evtac_labels::integration::{CumulativeTrapezoid, RunningTrapezoid};
///
/// let (t, y) = ([0, 1_000, 2_500], [1.0, 3.0, 2.0]);
/// let whole = CumulativeTrapezoid::new(&t, &y).unwrap();
/// let mut running = RunningTrapezoid::default();
/// assert_eq!(running.at(-5, Some((t[0], y[0]))), whole.at(-5));
/// running.push(t[0], y[0]);
/// running.push(t[1], y[1]);
/// assert_eq!(running.at(1_700, Some((t[2], y[2]))), whole.at(1_700));
/// running.push(t[2], y[2]);
/// assert_eq!(running.at(9_000, None), whole.at(9_000));
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunningTrapezoid {
    /// The first sample's time.
    first: Option<i64>,
    /// The last sample and the running integral there.
    last: Option<((i64, f64), f64)>,
}

impl RunningTrapezoid {
    /// Adds the next sample; its time must be after the last one's (the caller's series is
    /// sorted and deduplicated, as [`CumulativeTrapezoid::new`] demands).
    pub fn push(&mut self, t_us: i64, y: f64) {
        let sum = match self.last {
            Some((previous, sum)) => step(sum, previous, (t_us, y)),
            None => 0.0,
        };
        self.first.get_or_insert(t_us);
        self.last = Some(((t_us, y), sum));
    }

    /// The integral from the first sample to `t_us`, as [`CumulativeTrapezoid::at`] gives it
    /// over the whole series, for `t_us` at or after the last sample pushed and before `next`,
    /// the sample to come (`None` once the series has ended). With no sample yet, or none at
    /// all, it is 0.
    pub fn at(&self, t_us: i64, next: Option<(i64, f64)>) -> f64 {
        let (Some(first), Some((last, sum))) = (self.first, self.last) else {
            return 0.0;
        };
        if t_us <= first {
            return 0.0;
        }
        match next {
            Some(next) if t_us < next.0 => interpolate(sum, last, next, t_us),
            _ => sum,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_trapezoid_rule_and_linear_rates_exactly() {
        // y = 2 + 3 t (t in s) integrates to 2 t + 1.5 t^2, which the rule gets exactly.
        let t_us: Vec<i64> = vec![0, 1_000, 2_500, 3_000, 7_000];
        let y: Vec<f64> = t_us.iter().map(|&t| 2.0 + 3.0 * t as f64 * 1e-6).collect();
        let integral = CumulativeTrapezoid::new(&t_us, &y).unwrap();
        let exact = |t_us: i64| {
            let t = t_us as f64 * 1e-6;
            2.0 * t + 1.5 * t * t
        };
        for (&t, &c) in t_us.iter().zip(integral.at_samples()) {
            assert!((c - exact(t)).abs() < 1e-15);
        }
        for t in [1, 999, 1_000, 1_700, 4_321, 6_999] {
            assert!((integral.at(t) - exact(t)).abs() < 1e-15, "t = {t}");
        }
        assert_eq!(integral.at(-5), 0.0);
        assert_eq!(integral.at(9_000), integral.at(7_000));
        assert!((integral.between(1_700, 4_321) - (exact(4_321) - exact(1_700))).abs() < 1e-15);
    }

    #[test]
    fn rejects_bad_series() {
        assert_eq!(
            CumulativeTrapezoid::new(&[0, 1], &[1.0]),
            Err(IntegrationError::LengthMismatch {
                times: 2,
                values: 1
            })
        );
        assert_eq!(
            CumulativeTrapezoid::new(&[], &[]),
            Err(IntegrationError::Empty)
        );
        assert!(matches!(
            CumulativeTrapezoid::new(&[0, 5, 5], &[1.0; 3]),
            Err(IntegrationError::NotIncreasing { index: 2, .. })
        ));
    }
}

#[cfg(test)]
mod properties {
    use super::*;
    use proptest::prelude::*;

    /// Strictly increasing times with values beside them.
    fn series() -> impl Strategy<Value = (Vec<i64>, Vec<f64>)> {
        prop::collection::vec((1i64..5_000, -50.0f64..50.0), 2..60).prop_map(|steps| {
            let mut t = -1_000;
            steps
                .into_iter()
                .map(|(dt, y)| {
                    t += dt;
                    (t, y)
                })
                .unzip()
        })
    }

    proptest! {
        #[test]
        fn integrals_add_up((t, y) in series(), a in -2_000i64..300_000, b in -2_000i64..300_000, c in -2_000i64..300_000) {
            let integral = CumulativeTrapezoid::new(&t, &y).unwrap();
            let whole = integral.between(a, c);
            let parts = integral.between(a, b) + integral.between(b, c);
            prop_assert!((whole - parts).abs() < 1e-9);
            for (k, &tk) in t.iter().enumerate() {
                prop_assert!((integral.at(tk) - integral.at_samples()[k]).abs() < 1e-12);
            }
        }

        /// Built sample by sample and asked in time order (instants before, on, between and
        /// after the samples), the running integral is the whole one, bit for bit.
        #[test]
        fn the_running_integral_is_the_whole_one_bit_for_bit(
            (t, y) in series(),
            mut at in prop::collection::vec(-3_000i64..300_000, 0..40),
        ) {
            let whole = CumulativeTrapezoid::new(&t, &y).unwrap();
            at.extend(&t);
            at.sort_unstable();
            let mut running = RunningTrapezoid::default();
            let (mut next, mut got) = (0, Vec::new());
            for &x in &at {
                while next < t.len() && t[next] <= x {
                    running.push(t[next], y[next]);
                    next += 1;
                }
                got.push(running.at(x, t.get(next).map(|&tn| (tn, y[next]))).to_bits());
            }
            let want: Vec<u64> = at.iter().map(|&x| whole.at(x).to_bits()).collect();
            prop_assert_eq!(got, want);
        }
    }
}
