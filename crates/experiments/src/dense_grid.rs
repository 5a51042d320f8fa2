//! The tuning grids of the representations the paper did not choose (time surfaces, polarity
//! histograms, voxel grids: `evtac_repr::dense`), evtac's choice since the paper tunes none of
//! them: each kind's own two settings, every combination, around the paper's own time scales
//! (its static tau of 1000 ms and dynamic window of 640 ms) and down to the tens of
//! milliseconds a contact phase lasts.
//!
//! | kind | time axis | second axis |
//! | --- | --- | --- |
//! | time surface | tau, ms | binarization threshold; 0 stands for the continuous surface |
//! | histogram | window, ms | none (always 0) |
//! | voxel grid | window, ms | bins |

use evtac_repr::{HistogramConfig, ReprConfig, ReprKind, TimeSurfaceConfig, VoxelGridConfig};
use evtac_sim::Scale;
use serde::{Deserialize, Serialize};

/// The grids of the real-valued kinds at one scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DenseGrids {
    /// Time surface decay constants, ms.
    pub time_surface_taus_ms: Vec<f64>,
    /// Time surface thresholds, in (0, 1), and 0 for the continuous surface.
    pub time_surface_thresholds: Vec<f64>,
    /// Histogram windows, ms.
    pub histogram_windows_ms: Vec<f64>,
    /// Voxel grid windows, ms.
    pub voxel_windows_ms: Vec<f64>,
    /// Voxel grid bins (at most `evtac_learn::MAX_FRAMES`, the channels a network reads).
    pub voxel_bins: Vec<u32>,
}

impl Default for DenseGrids {
    /// `small`'s grids (plans written before these kinds existed searched none of them; the
    /// default only fills the field).
    fn default() -> Self {
        Self::for_scale(Scale::Small)
    }
}

impl DenseGrids {
    /// The grids of `scale`: `paper` and `small` search every listed value, `tiny` (tests) two
    /// of each.
    pub fn for_scale(scale: Scale) -> Self {
        match scale {
            Scale::Paper => Self {
                time_surface_taus_ms: vec![10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0],
                time_surface_thresholds: vec![0.0, 0.1, 0.3, 0.5],
                histogram_windows_ms: vec![10.0, 40.0, 160.0, 640.0, 1280.0, 2560.0],
                voxel_windows_ms: vec![40.0, 160.0, 640.0, 1280.0, 2560.0],
                voxel_bins: vec![2, 3, 5, 8],
            },
            Scale::Small => Self {
                time_surface_taus_ms: vec![30.0, 100.0, 300.0, 1000.0],
                time_surface_thresholds: vec![0.0, 0.3],
                histogram_windows_ms: vec![40.0, 160.0, 640.0, 1280.0],
                voxel_windows_ms: vec![160.0, 640.0, 1280.0],
                voxel_bins: vec![2, 5],
            },
            Scale::Tiny => Self {
                time_surface_taus_ms: vec![100.0, 1000.0],
                time_surface_thresholds: vec![0.0, 0.3],
                histogram_windows_ms: vec![80.0, 640.0],
                voxel_windows_ms: vec![640.0],
                voxel_bins: vec![2, 3],
            },
        }
    }

    /// The grid of `kind`: (time, second axis, config); empty for a kind with no grid here
    /// (the binary kinds: `crate::plan`'s).
    pub fn points(&self, kind: ReprKind) -> Vec<(f64, f64, ReprConfig)> {
        match kind {
            ReprKind::TimeSurface => self.time_surface(),
            ReprKind::Histogram => self.histogram(),
            ReprKind::VoxelGrid => self.voxel_grid(),
            ReprKind::Static
            | ReprKind::Dynamic
            | ReprKind::Combined
            | ReprKind::Stacked
            | ReprKind::Late => Vec::new(),
        }
    }

    /// The time surface grid: (tau, threshold, config), threshold 0 continuous.
    pub fn time_surface(&self) -> Vec<(f64, f64, ReprConfig)> {
        let mut out = Vec::new();
        for &tau_ms in &self.time_surface_taus_ms {
            for &th in &self.time_surface_thresholds {
                let threshold = (th > 0.0).then_some(th);
                let config = ReprConfig::TimeSurface(TimeSurfaceConfig { tau_ms, threshold });
                out.push((tau_ms, th, config));
            }
        }
        out
    }

    /// The histogram grid: (window, 0, config).
    pub fn histogram(&self) -> Vec<(f64, f64, ReprConfig)> {
        self.histogram_windows_ms
            .iter()
            .map(|&window_ms| {
                let config = ReprConfig::Histogram(HistogramConfig { window_ms });
                (window_ms, 0.0, config)
            })
            .collect()
    }

    /// The voxel grid's grid: (window, bins, config).
    pub fn voxel_grid(&self) -> Vec<(f64, f64, ReprConfig)> {
        let mut out = Vec::new();
        for &window_ms in &self.voxel_windows_ms {
            for &bins in &self.voxel_bins {
                let config = ReprConfig::VoxelGrid(VoxelGridConfig { window_ms, bins });
                out.push((window_ms, f64::from(bins), config));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_learn::Architecture;

    #[test]
    fn every_point_is_valid_distinct_and_trainable() {
        for scale in [Scale::Tiny, Scale::Small, Scale::Paper] {
            let grids = DenseGrids::for_scale(scale);
            let points = [grids.time_surface(), grids.histogram(), grids.voxel_grid()].concat();
            let keys: std::collections::HashSet<String> =
                points.iter().map(|p| p.2.cache_key()).collect();
            assert_eq!(keys.len(), points.len(), "{scale:?}");
            for (_, _, config) in &points {
                config.validate().expect("valid");
                assert!(Architecture::for_repr(config).is_supported(), "{config:?}");
            }
        }
        let tiny = DenseGrids::for_scale(Scale::Tiny).time_surface();
        assert_eq!(tiny.len(), 4);
        assert!(
            tiny.iter().any(|p| p.1 == 0.0
                && matches!(p.2, ReprConfig::TimeSurface(c) if c.threshold.is_none()))
        );
        let json = serde_json::to_string(&DenseGrids::default()).unwrap();
        assert_eq!(
            serde_json::from_str::<DenseGrids>(&json).unwrap(),
            DenseGrids::default()
        );
    }
}
