//! Which stretches of a recording are at rest, read from its events alone: the recording is cut
//! into [`BIN_US`] bins, and a bin is at rest when it holds no more events than the quietest
//! bins plus their Poisson scatter, and so do both its neighbours.
//!
//! The events decide, not the IMU: an indentation moves the pins without turning the sensor,
//! and the skin keeps creeping for a while after the robot stops; both make events the
//! background rate must not include. The neighbours keep out the first milliseconds of a motion
//! (slow, so they may not yet fill a bin with events while the gyroscope already turns).

use serde::Serialize;

/// Length of a bin, us: long enough that a bin at rest holds hundreds of background events on a
/// VGA sensor (so the Poisson scatter is small against the rest level), short enough to keep a
/// 0.3 s hold between motions.
pub const BIN_US: i64 = 50_000;

/// The quantile of the bins' counts taken as the rest level: low enough to be at rest when only
/// a twentieth of the recording is, high enough that one bin of dropped events does not set it.
const QUIET_QUANTILE: f64 = 0.05;

/// Poisson standard deviations a rest bin may lie above the rest level (the quantile sits about
/// 1.6 below the mean, so nearly every bin at rest passes).
const SCATTER_SIGMAS: f64 = 6.0;

/// One bin of the recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct RateBin {
    /// Start of the bin, us on the recording's clock.
    pub start_us: i64,
    /// Events in the bin.
    pub events: u64,
    /// ON events in the bin.
    pub on: u64,
    /// Whether the bin is at rest (a full bin, quiet, between quiet bins).
    pub rest: bool,
}

/// Marks the rest bins of `bins` (the last is taken as partial, never at rest) and returns the
/// most events a rest bin may hold, or `None` when there is no full bin.
pub fn mark_rest(bins: &mut [RateBin]) -> Option<u64> {
    let full = bins.len().checked_sub(1).filter(|&n| n > 0)?;
    let mut counts: Vec<u64> = bins[..full].iter().map(|b| b.events).collect();
    counts.sort_unstable();
    let level = counts[((full - 1) as f64 * QUIET_QUANTILE).round() as usize] as f64;
    // The + 1 keeps an all-but-empty recording's bins (level 0) from all being motion.
    let limit = (level + SCATTER_SIGMAS * level.sqrt() + 1.0).floor() as u64;
    let quiet: Vec<bool> = (0..bins.len())
        .map(|k| k < full && bins[k].events <= limit)
        .collect();
    for (k, bin) in bins.iter_mut().enumerate() {
        // A missing neighbour (the recording's first bin) does not count against a bin.
        let before = k == 0 || quiet[k - 1];
        let after = quiet.get(k + 1).copied().unwrap_or(true);
        bin.rest = quiet[k] && before && after;
    }
    Some(limit)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bins(counts: &[u64]) -> Vec<RateBin> {
        counts
            .iter()
            .enumerate()
            .map(|(k, &events)| RateBin {
                start_us: k as i64 * BIN_US,
                events,
                on: 0,
                rest: false,
            })
            .collect()
    }

    #[test]
    fn quiet_bins_between_quiet_bins_are_at_rest() {
        let mut b = bins(&[100, 95, 105, 98, 5000, 7000, 102, 99, 101, 97, 100, 30]);
        let limit = mark_rest(&mut b).unwrap();
        assert!((150..170).contains(&limit), "{limit}");
        let rest: Vec<bool> = b.iter().map(|b| b.rest).collect();
        let want = [
            true, true, true, false, false, false, false, true, true, true, false, false,
        ];
        assert_eq!(rest, want);
    }

    #[test]
    fn a_recording_shorter_than_two_bins_has_no_rest() {
        let mut b = bins(&[100]);
        assert_eq!(mark_rest(&mut b), None);
        assert!(!b[0].rest);
    }
}
