//! `evtac.filter` and `Recording.filter`: events through a chain of filters given as the
//! command line's SPECs (`evtac_filters`), with the events each filter removed;
//! `hot-pixels=auto` learns the hot pixels from the events given (`evtac_import::filtering`).

use evtac_events::Resolution;
use evtac_events::check::EventCheck;
use evtac_filters::{Filter, FilterSpec};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

use crate::error;
use crate::records::{self, Layout};

/// Each filter's SPEC (written out) with the events it removed, in the chain's order.
pub type Removed = Vec<(String, u64)>;

/// Filters `events` (packed event records) of a `resolution` sensor through `specs` in order;
/// the kept events (packed) and each filter's SPEC (written out) with the events it removed.
pub fn run(
    events: &[u8],
    resolution: Resolution,
    specs: &[String],
) -> PyResult<(Vec<u8>, Removed)> {
    let specs: Vec<FilterSpec> = specs
        .iter()
        .map(|s| s.parse::<FilterSpec>().map_err(error::value))
        .collect::<PyResult<_>>()?;
    let events = records::decode_events(events)?;
    // The filters index per-pixel state by the event's pixel and assume time order.
    EventCheck::new(Some(resolution))
        .check(&events)
        .map_err(|e| error::value(format!("events to filter: {e}")))?;
    let (kept, chain, _) = evtac_import::filtering::filter_events(
        std::path::Path::new("the events"),
        resolution,
        &specs,
        events,
    )
    .map_err(error::value)?;
    let removed = specs
        .iter()
        .zip(chain.filters())
        .map(|(spec, f)| (spec.to_string(), f.removed()))
        .collect();
    Ok((records::encode_events(&kept)?, removed))
}

/// `evtac.filter`: `events` (packed records) of a `(width, height)` sensor through the filters
/// `specs`; the kept events and `[(spec, removed)]`.
#[pyfunction]
pub fn filter<'py>(
    py: Python<'py>,
    events: PyReadonlyArray1<'_, u8>,
    resolution: (u16, u16),
    specs: Vec<String>,
) -> PyResult<(Bound<'py, PyAny>, Removed)> {
    let bytes = events.as_slice().map_err(error::value)?;
    let resolution = Resolution::new(resolution.0, resolution.1);
    let (kept, removed) = py.detach(|| run(bytes, resolution, &specs))?;
    Ok((Layout::Event.to_numpy(py, kept)?, removed))
}
