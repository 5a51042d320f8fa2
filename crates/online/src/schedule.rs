//! When estimates are due: a fixed grid in event time.
//!
//! Estimates fall on the multiples of the interval (`t_k = k * interval`), starting with the first
//! multiple at or after the first event, so that two runs over the same stream, or two sensors
//! with the same clock, sample the same instants whatever the chunking. An estimate at `t_k` is
//! due once the stream has shown that no further event with `t <= t_k` can arrive: an event with
//! `t > t_k` arrived (streams are in time order), a source vouched for it (a *horizon*, e.g. a
//! paced replay that read ahead), or the stream ended.

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An interval that is zero or negative.
    #[error("the estimate interval must be at least 1 us (got {interval_us} us)")]
    Interval {
        /// The interval given, in microseconds.
        interval_us: i64,
    },
}

/// The grid of estimate times, and which of them are due.
#[derive(Debug, Clone)]
pub struct Schedule {
    interval: i64,
    next: Option<i64>,
}

impl Schedule {
    /// A grid with `interval_us` microseconds between estimates; it starts at the first event.
    pub fn new(interval_us: i64) -> Result<Self, Error> {
        if interval_us < 1 {
            return Err(Error::Interval { interval_us });
        }
        Ok(Self {
            interval: interval_us,
            next: None,
        })
    }

    /// The interval in microseconds.
    pub fn interval_us(&self) -> i64 {
        self.interval
    }

    /// The next estimate time, once the first event has been seen.
    pub fn next(&self) -> Option<i64> {
        self.next
    }

    /// Starts the grid at the first multiple of the interval at or after `first_t` (no effect
    /// once started).
    pub fn start(&mut self, first_t: i64) {
        if self.next.is_none() {
            let floor = first_t.div_euclid(self.interval) * self.interval;
            self.next = Some(if floor < first_t {
                floor.saturating_add(self.interval)
            } else {
                floor
            });
        }
    }

    /// Starts the grid at `t` exactly (no effect once started): for a caller that knows when
    /// estimates matter, such as the latency study, which estimates from a trial's motion onset.
    pub fn start_at(&mut self, t: i64) {
        self.next.get_or_insert(t);
    }

    /// The next estimate time if it is at or before `horizon` (all events with `t <= horizon`
    /// have arrived), advancing the grid; `None` when nothing is due.
    #[inline]
    pub fn pop_due(&mut self, horizon: i64) -> Option<i64> {
        let t = self.next?;
        if t > horizon {
            return None;
        }
        // Saturating: a stream whose clock reaches i64::MAX stops producing estimates rather
        // than wrapping to the distant past.
        self.next = t.checked_add(self.interval);
        Some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn due(s: &mut Schedule, horizon: i64) -> Vec<i64> {
        std::iter::from_fn(|| s.pop_due(horizon)).collect()
    }

    #[test]
    fn grid_is_aligned_to_multiples_of_the_interval() {
        let mut s = Schedule::new(1000).unwrap();
        assert_eq!(s.pop_due(i64::MAX), None, "nothing before the first event");
        s.start(12_345);
        assert_eq!(s.next(), Some(13_000));
        assert_eq!(due(&mut s, 12_999), Vec::<i64>::new());
        assert_eq!(due(&mut s, 15_000), vec![13_000, 14_000, 15_000]);
        s.start(0);
        assert_eq!(s.next(), Some(16_000), "start only once");

        let mut s = Schedule::new(1000).unwrap();
        s.start(2000);
        assert_eq!(
            s.next(),
            Some(2000),
            "an event on the grid is included at its own time"
        );
        let mut s = Schedule::new(1000).unwrap();
        s.start(-1500);
        assert_eq!(s.next(), Some(-1000));
    }

    #[test]
    fn a_grid_started_at_a_time_keeps_it() {
        let mut s = Schedule::new(1000).unwrap();
        s.start_at(12_345);
        s.start(0);
        assert_eq!(due(&mut s, 14_345), vec![12_345, 13_345, 14_345]);
        s.start_at(0);
        assert_eq!(s.next(), Some(15_345), "start only once");
    }

    #[test]
    fn rejects_empty_intervals_and_stops_at_the_end_of_time() {
        assert!(Schedule::new(0).is_err());
        assert!(Schedule::new(-5).is_err());
        let mut s = Schedule::new(i64::MAX / 2).unwrap();
        s.start(i64::MAX - 10);
        assert_eq!(due(&mut s, i64::MAX), vec![i64::MAX - 1]);
        let mut s = Schedule::new(10).unwrap();
        s.start(i64::MAX - 15);
        assert_eq!(due(&mut s, i64::MAX), vec![i64::MAX - 7]);
        assert_eq!(s.pop_due(i64::MAX), None);
    }
}
