//! The one check every entry point applies to incoming events before any is used: inside the
//! frame (when a frame is given) and in time order, also relative to earlier chunks.

use crate::ReprError;
use evtac_events::{Event, Resolution};

/// Checks `events` against `frame` (when `Some`) and for non-decreasing time, continuing from
/// `previous` (the latest time already accepted). Returns the latest time after the chunk.
/// On error nothing of the chunk may be applied by the caller.
pub(crate) fn check_events(
    events: &[Event],
    frame: Option<Resolution>,
    mut previous: Option<i64>,
) -> Result<Option<i64>, ReprError> {
    for (index, e) in events.iter().enumerate() {
        if let Some(frame) = frame
            && !frame.contains(e.x, e.y)
        {
            return Err(ReprError::EventOutOfFrame {
                index,
                t: e.t,
                x: e.x,
                y: e.y,
                width: frame.width,
                height: frame.height,
            });
        }
        if let Some(p) = previous
            && e.t < p
        {
            return Err(ReprError::EventOutOfOrder {
                index,
                t: e.t,
                previous: p,
            });
        }
        previous = Some(e.t);
    }
    Ok(previous)
}
