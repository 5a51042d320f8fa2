//! What the capture does to a simulated recording before it is saved: a seam (as ripgrep's
//! `Sink`), so that `evtac simulate --filter` saves the trials as a filtering capture would (the
//! NeuroTac lab's passes every recording through dv-processing's background-activity filter)
//! while the simulator knows nothing of filters. [`AsSimulated`] saves the events as they are.

use evtac_events::{Event, Resolution};

/// A capture's treatment of each recording's events, called once per recording (each trial
/// and the no-contact recording) with its whole event stream, from worker threads.
pub trait Capture: Sync {
    /// The events of the recording `name` (its file name) on a `resolution` sensor, as the
    /// capture saves them, or why it cannot.
    fn save(
        &self,
        name: &str,
        resolution: Resolution,
        events: Vec<Event>,
    ) -> Result<Vec<Event>, String>;

    /// What the capture does, in words for `simulator.json` (the filters' SPECs); empty for
    /// a capture that saves the events as simulated.
    fn describe(&self) -> Vec<String>;
}

/// The events saved as simulated.
#[derive(Debug, Clone, Copy, Default)]
pub struct AsSimulated;

impl Capture for AsSimulated {
    fn save(&self, _: &str, _: Resolution, events: Vec<Event>) -> Result<Vec<Event>, String> {
        Ok(events)
    }

    fn describe(&self) -> Vec<String> {
        Vec::new()
    }
}
