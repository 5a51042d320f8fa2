//! The sensor as the report shows it: what the camera inside the tip sees at rest and in contact.
//!
//! A simulated dataset (one with `simulator.json`) is rendered by its own simulator: the
//! camera's linear brightness image of the pins with the skin out of contact, and pressed in at
//! the trial's depth and tilt ([`evtac_sim::Simulator::brightness_image`]). A recorded dataset
//! has no frames to show, only events, so its panels are event-count images instead: the
//! no-contact recording, and the contact trial's motion phase. [`SensorKind`] says which, and
//! the report's caption with it.

use crate::cache::Error;
use crate::dataset::{self, Dataset};
use crate::results::{SensorKind, SensorPanel, SensorView};
use evtac_events::Resolution;
use evtac_events::layout::NO_CONTACT_FILE;
use evtac_events::manifest::TrialMeta;
use evtac_import::inputs::MaskSource;
use evtac_sim::{Simulator, SkinPose};

/// The sensor at rest and in contact with `meta`'s depth and direction at `theta_deg` of tilt:
/// simulated images when `ds` was simulated, else event-count images of its recordings.
pub fn view(ds: &Dataset, meta: &TrialMeta, theta_deg: f64) -> Result<SensorView, Error> {
    match ds.simulator()? {
        Some(sim) => Ok(simulated(sim.params, sim.seed, meta, theta_deg)),
        None => recorded(ds, meta),
    }
}

/// The simulator's camera image of the pins at rest (out of contact by the no-contact gap) and
/// pressed in.
fn simulated(
    params: evtac_sim::SimParams,
    seed: u64,
    meta: &TrialMeta,
    theta_deg: f64,
) -> SensorView {
    let resolution = Resolution::new(params.camera.width, params.camera.height);
    let rest_gap = params.contact.no_contact_gap_mm;
    // The seed only draws the pixels' fixed pattern, which the brightness image does not show.
    let sim = Simulator::new(params, seed);
    let image = |pose: &SkinPose| {
        // Gamma 0.5 (as `docs/img/sim_frames.png`): the dark background stays dark and the
        // pins' blobs do not saturate.
        sim.brightness_image(pose)
            .into_iter()
            .map(|b| b.clamp(0.0, 1.0).sqrt())
            .collect()
    };
    let rest = SkinPose {
        depth_mm: -rest_gap,
        ..SkinPose::default()
    };
    let contact = SkinPose {
        theta_deg,
        phi_deg: meta.direction_deg,
        depth_mm: meta.depth_mm,
        lag_deg: 0.0,
    };
    SensorView {
        kind: SensorKind::Simulated,
        resolution,
        panels: vec![
            SensorPanel {
                title: format!("At rest ({rest_gap} mm from the plane)"),
                values: image(&rest),
            },
            SensorPanel {
                title: format!(
                    "In contact ({} mm deep, tilt {theta_deg:.1} deg towards {} deg)",
                    meta.depth_mm, meta.direction_deg
                ),
                values: image(&contact),
            },
        ],
    }
}

/// Event counts per pixel, log-scaled to 0..1 (a few hot pixels would otherwise leave the rest
/// black).
fn count_image(resolution: Resolution, events: &[evtac_events::Event]) -> Vec<f32> {
    let width = usize::from(resolution.width);
    let mut counts = vec![0u32; width * usize::from(resolution.height)];
    for e in events {
        if e.x < resolution.width
            && let Some(c) = counts.get_mut(usize::from(e.y) * width + usize::from(e.x))
        {
            *c += 1;
        }
    }
    let top = counts.iter().copied().max().unwrap_or(0).max(1);
    let scale = 1.0 / (1.0 + top as f32).ln();
    counts
        .into_iter()
        .map(|c| (1.0 + c as f32).ln() * scale)
        .collect()
}

/// Event-count images of the no-contact recording (when the dataset was opened with its mask)
/// and of `meta`'s motion phase, on the full sensor.
fn recorded(ds: &Dataset, meta: &TrialMeta) -> Result<SensorView, Error> {
    let (resolution, events) = dataset::read_full(&ds.dir.join(&meta.file))?;
    let mut panels = Vec::new();
    if ds.inputs.mask == MaskSource::NoContact {
        let (rest_resolution, rest) = dataset::read_full(&ds.dir.join(NO_CONTACT_FILE))?;
        if rest_resolution == resolution {
            let seconds = rest
                .first()
                .zip(rest.last())
                .map_or(0.0, |(a, b)| (b.t - a.t) as f64 * 1e-6);
            panels.push(SensorPanel {
                title: format!("No contact: events in {seconds:.1} s"),
                values: count_image(resolution, &rest),
            });
        }
    }
    let first = events.partition_point(|e| e.t < meta.motion_start_us);
    let last = events.partition_point(|e| e.t <= meta.motion_end_us);
    panels.push(SensorPanel {
        title: format!("Trial {}: events during the motion", meta.trial),
        values: count_image(resolution, &events[first..last]),
    });
    Ok(SensorView {
        kind: SensorKind::EventCounts,
        resolution,
        panels,
    })
}
