//! Latency accounting: an allocation-free histogram of per-estimate latencies (and of processing
//! times), which the estimator and the ROS 2 publisher fill and a run's [`Summary`] reads.
//!
//! [`Summary`]: crate::Summary

use hdrhistogram::Histogram;
use std::time::Duration;

/// Largest latency the histogram resolves (larger ones are recorded as this value).
const MAX_TRACKED_NS: u64 = 60_000_000_000;

/// Per-estimate latencies, in nanoseconds, with 3 significant digits.
///
/// The histogram's buckets are allocated once, up front, so recording never allocates; this is
/// what lets the estimation thread run for hours with flat memory.
#[derive(Debug, Clone)]
pub struct LatencyStats {
    histogram: Histogram<u64>,
    interval: Duration,
    late: u64,
}

impl LatencyStats {
    /// Empty statistics; an estimate is *late* when its latency exceeds `interval`.
    pub fn new(interval: Duration) -> Self {
        // The bounds are constants that hdrhistogram accepts (low >= 1, high >= 2 * low,
        // sigfig <= 5), so construction cannot fail.
        let histogram = Histogram::new_with_bounds(1, MAX_TRACKED_NS, 3)
            .unwrap_or_else(|_| unreachable!("constant histogram bounds are valid"));
        Self {
            histogram,
            interval,
            late: 0,
        }
    }

    /// Records one estimate's latency.
    #[inline]
    pub fn record(&mut self, latency: Duration) {
        let ns = u64::try_from(latency.as_nanos()).unwrap_or(u64::MAX);
        self.histogram
            .saturating_record(ns.clamp(1, MAX_TRACKED_NS));
        if latency > self.interval {
            self.late += 1;
        }
    }

    /// Number of estimates recorded.
    pub fn count(&self) -> u64 {
        self.histogram.len()
    }

    /// The interval past which an estimate is late.
    pub fn interval(&self) -> Duration {
        self.interval
    }

    /// Estimates whose latency exceeded the interval.
    pub fn late(&self) -> u64 {
        self.late
    }

    /// The latency at quantile `q` (0..=1), or zero without estimates.
    pub fn quantile(&self, q: f64) -> Duration {
        if self.histogram.is_empty() {
            return Duration::ZERO;
        }
        Duration::from_nanos(self.histogram.value_at_quantile(q))
    }

    /// The largest latency recorded, or zero without estimates.
    pub fn max(&self) -> Duration {
        if self.histogram.is_empty() {
            return Duration::ZERO;
        }
        Duration::from_nanos(self.histogram.max())
    }

    /// The underlying histogram (nanoseconds), e.g. for plotting a distribution.
    pub fn histogram(&self) -> &Histogram<u64> {
        &self.histogram
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_and_late_counts() {
        let mut s = LatencyStats::new(Duration::from_micros(1000));
        assert_eq!(s.quantile(0.5), Duration::ZERO);
        for us in 1..=100u64 {
            s.record(Duration::from_micros(us * 20));
        }
        assert_eq!(s.count(), 100);
        // 51..=100 * 20 us exceed 1000 us.
        assert_eq!(s.late(), 50);
        let median = s.quantile(0.5).as_secs_f64() * 1e6;
        assert!((median - 1000.0).abs() <= 1.0, "{median}");
        let max = s.max().as_secs_f64() * 1e6;
        assert!((max - 2000.0).abs() <= 2.0, "{max}");
        s.record(Duration::from_secs(3600));
        assert_eq!(s.max(), Duration::from_nanos(s.histogram().max()));
        assert!(s.max() >= Duration::from_secs(59));
    }
}
