//! The one check every entry point applies to incoming events before any is used: inside the
//! frame (when a frame is given) and in time order, also relative to earlier chunks.

use crate::ReprError;
use evtac_events::{Event, Resolution, Roi};
use std::collections::VecDeque;

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

/// Queues `events` for a `frame`-sized extractor, continuing from `last_pushed`: in crop
/// coordinates when `roi` is `None`, else in full-sensor coordinates cropped by `roi` (events
/// outside it dropped; `roi.size` must be the frame). The whole chunk is checked first: on error
/// nothing is queued. Both extractors push through here.
pub(crate) fn queue_events(
    pending: &mut VecDeque<Event>,
    last_pushed: &mut Option<i64>,
    frame: Resolution,
    events: &[Event],
    roi: Option<&Roi>,
) -> Result<(), ReprError> {
    match roi {
        None => {
            *last_pushed = check_events(events, Some(frame), *last_pushed)?;
            pending.extend(events);
        }
        Some(roi) => {
            if roi.size != frame {
                return Err(ReprError::RoiSize {
                    roi_width: roi.size.width,
                    roi_height: roi.size.height,
                    width: frame.width,
                    height: frame.height,
                });
            }
            *last_pushed = check_events(events, None, *last_pushed)?;
            pending.extend(events.iter().filter_map(|&e| roi.map(e)));
        }
    }
    Ok(())
}
