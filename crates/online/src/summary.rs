//! The summary printed when a run ends: latency and processing time, the counters of the
//! ingestion, and what the ROS 2 input and output did.
//!
//! It sits apart from the latency histogram ([`LatencyStats`]) because it gathers every part of
//! a run (the estimator's figures, the ROS 2 publisher's and the ROS 2 input's statistics),
//! while the estimator and the publisher need only the histogram: kept together, they made the
//! estimator, the latency module and the publisher import each other in a circle.
//!
//! Latency is only what it says when the events come at their recorded or live pace. A
//! recording replayed as fast as possible is read far ahead of the estimator, so its chunks
//! wait in the queue and that wait counts into latency (a P99 of milliseconds where a
//! `--realtime` replay of the same file shows about a hundred microseconds). Such a run's
//! summary ([`Summary::paced`] false) leads with the processing time per estimate instead, and
//! says that latency needs a paced replay.

use crate::input::Ros2InputStats;
use crate::latency::LatencyStats;
use crate::ros2::PublishStats;
use std::time::Duration;

/// What a run did, reported when it ends.
#[derive(Debug, Clone)]
pub struct Summary {
    /// Estimates emitted.
    pub estimates: u64,
    /// Median latency.
    pub median: Duration,
    /// 99th-percentile latency.
    pub p99: Duration,
    /// Largest latency.
    pub max: Duration,
    /// Estimates whose latency exceeded the interval.
    pub late: u64,
    /// Median processing time per estimate (the estimator's own work, no waiting: see
    /// `Estimate::processing`).
    pub processing_median: Duration,
    /// 99th-percentile processing time.
    pub processing_p99: Duration,
    /// Largest processing time.
    pub processing_max: Duration,
    /// Whether the events came at their recorded or live pace, so that latency means what it
    /// would live (set by the caller, who knows the source; `true` unless told otherwise).
    pub paced: bool,
    /// The interval between estimates.
    pub interval: Duration,
    /// Events received from the source (on the whole sensor).
    pub events: u64,
    /// Events inside the region of interest, fed to the representation.
    pub events_in_roi: u64,
    /// Events dropped because the estimator was behind (only with dropping enabled).
    pub events_dropped: u64,
    /// Events skipped because they were older than an event already received (a stream out of
    /// time order, e.g. a camera restarted behind a reconnection).
    pub events_out_of_order: u64,
    /// Events the filters removed before the region of interest (with `--filter`).
    pub events_filtered: u64,
    /// Successful reconnections of a network input.
    pub reconnects: u32,
    /// Event time of the first and last event received, in microseconds.
    pub span_us: Option<(i64, i64)>,
    /// Wall-clock time from the first chunk to the end of the run.
    pub wall: Duration,
    /// What publishing on ROS 2 did, when the run published (set by the caller, who owns the
    /// publisher: see [`crate::ros2::Ros2Publisher::finish`]).
    pub ros2: Option<PublishStats>,
    /// What a ROS 2 input received, lost and skipped (set by the caller, who holds its
    /// [`crate::input::Ros2InputReport`]).
    pub ros2_input: Option<Ros2InputStats>,
}

impl Summary {
    /// Fills the latency fields from `stats` and the processing-time fields from `processing`;
    /// counters start at zero, and the run counts as paced.
    pub fn from_stats(stats: &LatencyStats, processing: &LatencyStats) -> Self {
        Self {
            estimates: stats.count(),
            median: stats.quantile(0.5),
            p99: stats.quantile(0.99),
            max: stats.max(),
            late: stats.late(),
            processing_median: processing.quantile(0.5),
            processing_p99: processing.quantile(0.99),
            processing_max: processing.max(),
            paced: true,
            interval: stats.interval(),
            events: 0,
            events_in_roi: 0,
            events_dropped: 0,
            events_out_of_order: 0,
            events_filtered: 0,
            reconnects: 0,
            span_us: None,
            wall: Duration::ZERO,
            ros2: None,
            ros2_input: None,
        }
    }
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let us = |d: Duration| d.as_secs_f64() * 1e6;
        writeln!(
            f,
            "estimates: {} every {:.0} us",
            self.estimates,
            us(self.interval)
        )?;
        let processing = format!(
            "processing time per estimate: median {:.1} us, P99 {:.1} us, max {:.1} us",
            us(self.processing_median),
            us(self.processing_p99),
            us(self.processing_max)
        );
        if self.paced {
            writeln!(
                f,
                "latency: median {:.1} us, P99 {:.1} us, max {:.1} us",
                us(self.median),
                us(self.p99),
                us(self.max)
            )?;
            writeln!(
                f,
                "late (latency > interval): {} of {}",
                self.late, self.estimates
            )?;
            writeln!(f, "{processing}")?;
        } else {
            writeln!(f, "{processing}")?;
            writeln!(
                f,
                "latency: not measured: the recording was replayed as fast as possible, so its \
                 events waited in the queue behind a reader running ahead, and that wait is not \
                 latency; end-to-end latency needs a replay at recorded pace (--realtime)"
            )?;
        }
        writeln!(
            f,
            "events: {} received, {} in the region of interest, {} dropped, {} out of order",
            self.events, self.events_in_roi, self.events_dropped, self.events_out_of_order
        )?;
        if self.events_filtered > 0 {
            writeln!(f, "filters: removed {} events", self.events_filtered)?;
        }
        if let Some((first, last)) = self.span_us {
            writeln!(
                f,
                "event time: {first} .. {last} us ({:.3} s)",
                (last - first) as f64 * 1e-6
            )?;
        }
        if self.reconnects > 0 {
            writeln!(f, "reconnections: {}", self.reconnects)?;
        }
        if let Some(input) = &self.ros2_input {
            writeln!(f, "{input}")?;
        }
        if let Some(ros2) = &self.ros2 {
            writeln!(f, "{ros2}")?;
        }
        write!(f, "wall time: {:.3} s", self.wall.as_secs_f64())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_prints_every_figure() {
        let mut s = LatencyStats::new(Duration::from_millis(1));
        s.record(Duration::from_micros(40));
        let mut p = LatencyStats::new(Duration::from_millis(1));
        p.record(Duration::from_micros(12));
        let mut summary = Summary::from_stats(&s, &p);
        summary.events = 10;
        summary.events_dropped = 0;
        let text = summary.to_string();
        for needle in [
            "estimates: 1",
            "latency: median 40",
            "P99 40",
            "late",
            "processing time per estimate: median 12",
            "10 received",
            "0 dropped",
        ] {
            assert!(text.contains(needle), "{needle:?} missing from:\n{text}");
        }
    }

    #[test]
    fn an_unpaced_summary_leads_with_processing_time_and_names_no_latency() {
        let mut s = LatencyStats::new(Duration::from_millis(1));
        s.record(Duration::from_micros(6500));
        let mut p = LatencyStats::new(Duration::from_millis(1));
        p.record(Duration::from_micros(30));
        let mut summary = Summary::from_stats(&s, &p);
        summary.paced = false;
        let text = summary.to_string();
        let lines: Vec<&str> = text.lines().collect();
        assert!(
            lines[1].starts_with("processing time per estimate: median 30"),
            "{text}"
        );
        assert!(lines[2].contains("--realtime"), "{text}");
        // The queueing-inflated figure is not printed as latency.
        assert!(!text.contains("6500"), "{text}");
        assert!(!text.contains("late (latency"), "{text}");
    }
}
