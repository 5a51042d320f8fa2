//! Validation shared by every reader: events must lie inside the declared resolution and their
//! timestamps must not go backwards.
//!
//! Readers decode a chunk first and validate the finished slice afterwards (a tight loop the
//! compiler vectorises); only when a check fails is the offending event searched for, so the
//! happy path costs little.

use crate::{Event, Resolution};

/// Why a decoded event was rejected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CheckError {
    /// An event lies outside the sensor the file declares.
    #[error(
        "event {index} at (x={x}, y={y}) lies outside the {width}x{height} sensor \
         (x must be < {width} and y < {height})"
    )]
    OutOfBounds {
        /// Zero-based index of the event in the file.
        index: u64,
        /// Its column.
        x: u16,
        /// Its row.
        y: u16,
        /// The declared width.
        width: u16,
        /// The declared height.
        height: u16,
    },
    /// An event is older than the event before it.
    #[error("timestamps go backwards at event {index}: {current} us after {previous} us")]
    TimeBackwards {
        /// Zero-based index of the event in the file.
        index: u64,
        /// Timestamp of the event before it (us).
        previous: i64,
        /// Its timestamp (us).
        current: i64,
    },
}

impl CheckError {
    /// Zero-based index in the file of the event the error is about (readers turn it into a
    /// byte offset or line number).
    pub fn index(&self) -> u64 {
        match *self {
            Self::OutOfBounds { index, .. } | Self::TimeBackwards { index, .. } => index,
        }
    }
}

/// What validating a chunk needs besides its first and last timestamps: whether its events lie
/// inside the resolution checked against, and whether their timestamps never decrease within
/// it. A reader may gather it while decoding (see [`EventCheck::check_summarized`]) to spare a
/// second pass over the events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkSummary {
    /// Whether every event lies inside the resolution (`true` when there is none).
    pub in_bounds: bool,
    /// Whether every timestamp is at least the one before it (within the chunk).
    pub ordered: bool,
}

impl ChunkSummary {
    /// The summary of no events.
    pub const EMPTY: Self = Self {
        in_bounds: true,
        ordered: true,
    };

    /// Computes the summary of `events` against `resolution` (branch-free reductions the
    /// compiler vectorises).
    fn of(events: &[Event], resolution: Option<Resolution>) -> Self {
        let (mut max_x, mut max_y) = (0u16, 0u16);
        let mut ordered = true;
        let mut previous = events.first().map_or(0, |e| e.t);
        for e in events {
            max_x = max_x.max(e.x);
            max_y = max_y.max(e.y);
            ordered &= e.t >= previous;
            previous = e.t;
        }
        Self {
            in_bounds: resolution.is_none_or(|r| max_x < r.width && max_y < r.height),
            ordered,
        }
    }
}

/// Running validation state over a stream of event chunks.
#[derive(Debug, Clone, Default)]
pub struct EventCheck {
    resolution: Option<Resolution>,
    /// Number of events validated so far (the index of the next one).
    count: u64,
    last_t: Option<i64>,
}

impl EventCheck {
    /// A checker against `resolution` (`None`: only the time order is checked).
    pub fn new(resolution: Option<Resolution>) -> Self {
        Self {
            resolution,
            count: 0,
            last_t: None,
        }
    }

    /// The resolution events are checked against.
    pub fn resolution(&self) -> Option<Resolution> {
        self.resolution
    }

    /// Replaces the resolution events are checked against from now on.
    pub fn set_resolution(&mut self, resolution: Option<Resolution>) {
        self.resolution = resolution;
    }

    /// Number of events validated so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Validates the next chunk of the stream.
    pub fn check(&mut self, events: &[Event]) -> Result<(), CheckError> {
        self.check_summarized(events, ChunkSummary::of(events, self.resolution))
    }

    /// Validates the next chunk given its `summary`, which the caller computed from exactly
    /// these events and against [`resolution`](Self::resolution).
    pub fn check_summarized(
        &mut self,
        events: &[Event],
        summary: ChunkSummary,
    ) -> Result<(), CheckError> {
        let (Some(first), Some(last)) = (events.first(), events.last()) else {
            return Ok(());
        };
        let in_order = summary.ordered && self.last_t.is_none_or(|t| first.t >= t);
        if !(summary.in_bounds && in_order) {
            return Err(self.locate(events));
        }
        self.count += events.len() as u64;
        self.last_t = Some(last.t);
        Ok(())
    }

    /// Finds the first bad event of a chunk known to hold one.
    fn locate(&self, events: &[Event]) -> CheckError {
        let mut last = self.last_t;
        for (i, e) in events.iter().enumerate() {
            let index = self.count + i as u64;
            if let Some(r) = self.resolution
                && !r.contains(e.x, e.y)
            {
                return CheckError::OutOfBounds {
                    index,
                    x: e.x,
                    y: e.y,
                    width: r.width,
                    height: r.height,
                };
            }
            if let Some(previous) = last
                && e.t < previous
            {
                return CheckError::TimeBackwards {
                    index,
                    previous,
                    current: e.t,
                };
            }
            last = Some(e.t);
        }
        // `check` only calls this when some event failed, so the loop above returned; keep a
        // truthful answer anyway rather than panicking.
        CheckError::TimeBackwards {
            index: self.count,
            previous: self.last_t.unwrap_or(0),
            current: events.first().map_or(0, |e| e.t),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(t: i64, x: u16, y: u16) -> Event {
        Event {
            t,
            x,
            y,
            polarity: true,
        }
    }

    #[test]
    fn accepts_ordered_events_inside() {
        let mut c = EventCheck::new(Some(Resolution::new(10, 5)));
        c.check(&[ev(1, 0, 0), ev(1, 9, 4)]).unwrap();
        c.check(&[ev(2, 3, 3)]).unwrap();
        assert_eq!(c.count(), 3);
    }

    #[test]
    fn names_the_event_outside() {
        let mut c = EventCheck::new(Some(Resolution::new(10, 5)));
        c.check(&[ev(1, 0, 0)]).unwrap();
        let err = c.check(&[ev(2, 1, 1), ev(3, 10, 1)]).unwrap_err();
        assert_eq!(
            err,
            CheckError::OutOfBounds {
                index: 2,
                x: 10,
                y: 1,
                width: 10,
                height: 5
            }
        );
        assert!(err.to_string().contains("x must be < 10"));
    }

    #[test]
    fn names_the_event_going_back_across_chunks() {
        let mut c = EventCheck::new(None);
        c.check(&[ev(5, 0, 0)]).unwrap();
        let err = c.check(&[ev(4, 0, 0)]).unwrap_err();
        assert_eq!(
            err,
            CheckError::TimeBackwards {
                index: 1,
                previous: 5,
                current: 4
            }
        );
        let mut c = EventCheck::new(None);
        let err = c
            .check(&[ev(5, 0, 0), ev(6, 0, 0), ev(2, 0, 0)])
            .unwrap_err();
        assert!(matches!(err, CheckError::TimeBackwards { index: 2, .. }));
    }
}
