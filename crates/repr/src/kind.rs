//! [`ReprKind`]: the one list of representation kinds, their names (`static` on the command line
//! and in configs, `Static` in reports) and how a kind's config is built from a static and a
//! dynamic part. Every front end (the CLI's `--repr`, the Python package, the experiments, the
//! report) spells kinds through it, so adding a kind touches this file, [`crate::ReprConfig`]
//! and the network that reads it, not every command.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::ReprError;
use crate::config::{DynamicConfig, ReprConfig, StaticConfig};
use crate::dense::{HistogramConfig, TimeSurfaceConfig, VoxelGridConfig};

/// A representation kind: the paper's three, evtac's two learned fusions, then the real-valued
/// kinds the paper did not choose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ReprKind {
    /// Exponential-decay accumulator, masked and thresholded.
    Static,
    /// Sliding-window event count, thresholded.
    Dynamic,
    /// Pixel-wise OR of the static and dynamic binary frames.
    Combined,
    /// Both frames pooled side by side (1800 features) into one dense network (learned fusion).
    Stacked,
    /// Both frames pooled side by side into a network with one branch per frame, joined before
    /// the head (learned late fusion).
    Late,
    /// Per-polarity time surface (tonic's), continuous or binarized.
    TimeSurface,
    /// Per-polarity event counts over a window (tonic's frame with `time_window`).
    Histogram,
    /// Signed bilinear voxel grid of B bins over a window (tonic's).
    VoxelGrid,
}

impl ReprKind {
    /// Every kind, in report order: the paper's three, the learned fusions, then the kinds the
    /// paper did not choose.
    pub const ALL: [Self; 8] = [
        Self::Static,
        Self::Dynamic,
        Self::Combined,
        Self::Stacked,
        Self::Late,
        Self::TimeSurface,
        Self::Histogram,
        Self::VoxelGrid,
    ];
    /// The paper's three kinds.
    pub const PAPER: [Self; 3] = [Self::Static, Self::Dynamic, Self::Combined];
    /// evtac's learned fusions of the static and dynamic frames (not in the paper).
    pub const FUSIONS: [Self; 2] = [Self::Stacked, Self::Late];
    /// The real-valued kinds the paper did not choose (`crate::dense`), each tuned on its own
    /// grid: Experiment 1's "beyond the paper" rows.
    pub const BEYOND: [Self; 3] = [Self::TimeSurface, Self::Histogram, Self::VoxelGrid];
    /// The kinds built from a static and a dynamic part: the paper's three and the fusions.
    pub const BINARY: [Self; 5] = [
        Self::Static,
        Self::Dynamic,
        Self::Combined,
        Self::Stacked,
        Self::Late,
    ];

    /// The name on the command line, in configs and in folder names: `static`, `dynamic`,
    /// `combined`, `stacked`, `late`, `time-surface`, `histogram`, `voxel-grid`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Static => "static",
            Self::Dynamic => "dynamic",
            Self::Combined => "combined",
            Self::Stacked => "stacked",
            Self::Late => "late",
            Self::TimeSurface => "time-surface",
            Self::Histogram => "histogram",
            Self::VoxelGrid => "voxel-grid",
        }
    }

    /// The name in reports, tables and `results.json`: `Static`, `Dynamic`, ...
    pub fn title(self) -> &'static str {
        match self {
            Self::Static => "Static",
            Self::Dynamic => "Dynamic",
            Self::Combined => "Combined",
            Self::Stacked => "Stacked",
            Self::Late => "Late",
            Self::TimeSurface => "Time surface",
            Self::Histogram => "Histogram",
            Self::VoxelGrid => "Voxel grid",
        }
    }

    /// One line on what the kind is (the CLI's help for each value).
    pub fn describe(self) -> &'static str {
        match self {
            Self::Static => "Exponential-decay accumulator, masked and thresholded",
            Self::Dynamic => "Sliding-window event count, thresholded",
            Self::Combined => "Pixel-wise OR of the static and dynamic binary frames",
            Self::Stacked => {
                "Both frames pooled side by side (1800 features) into one dense network \
                 (learned fusion)"
            }
            Self::Late => {
                "Both frames pooled side by side into one 900-128 branch per frame, joined \
                 before the head (learned late fusion)"
            }
            Self::TimeSurface => {
                "Per-polarity time surface exp(-age/tau) (tonic's), continuous or binarized \
                 (--tau-ms, --threshold)"
            }
            Self::Histogram => "Per-polarity event counts over a window (tonic's; --window-ms)",
            Self::VoxelGrid => {
                "Signed voxel grid of B bins over a window (tonic's; --window-ms, --bins)"
            }
        }
    }

    /// Whether the kind has a static part and a dynamic part (the real-valued kinds have
    /// neither: [`Self::is_dense`]).
    pub fn parts(self) -> (bool, bool) {
        match self {
            Self::Static => (true, false),
            Self::Dynamic => (false, true),
            Self::Combined | Self::Stacked | Self::Late => (true, true),
            Self::TimeSurface | Self::Histogram | Self::VoxelGrid => (false, false),
        }
    }

    /// Whether the kind is real-valued, one the paper did not choose ([`Self::BEYOND`]).
    pub fn is_dense(self) -> bool {
        Self::BEYOND.contains(&self)
    }

    /// Whether the kind is one of evtac's learned fusions ([`Self::FUSIONS`]).
    pub fn is_fusion(self) -> bool {
        Self::FUSIONS.contains(&self)
    }

    /// This kind's config from a static and a dynamic part (a part the kind does not have is
    /// ignored; a real-valued kind has neither and takes its default settings).
    pub fn config(self, static_part: StaticConfig, dynamic_part: DynamicConfig) -> ReprConfig {
        match self {
            Self::Static => ReprConfig::Static(static_part),
            Self::Dynamic => ReprConfig::Dynamic(dynamic_part),
            Self::Combined => ReprConfig::Combined {
                static_part,
                dynamic_part,
            },
            Self::Stacked => ReprConfig::Stacked {
                static_part,
                dynamic_part,
            },
            Self::Late => ReprConfig::Late {
                static_part,
                dynamic_part,
            },
            Self::TimeSurface => ReprConfig::TimeSurface(TimeSurfaceConfig::default()),
            Self::Histogram => ReprConfig::Histogram(HistogramConfig::default()),
            Self::VoxelGrid => ReprConfig::VoxelGrid(VoxelGridConfig::default()),
        }
    }

    /// A real-valued kind's config from the settings given (`None` keeps the kind's default:
    /// time surface tau 100 ms, continuous; windows 640 ms; 5 bins), checked. A setting the
    /// kind does not take is an error naming it, as is a binary kind.
    pub fn dense_config(self, settings: DenseSettings) -> Result<ReprConfig, ReprError> {
        let (takes, reason): (&[&str], _) = match self {
            Self::TimeSurface => (
                &["tau_ms", "threshold"],
                "a time surface takes tau_ms and threshold",
            ),
            Self::Histogram => (&["window_ms"], "a histogram takes window_ms"),
            Self::VoxelGrid => (
                &["window_ms", "bins"],
                "a voxel grid takes window_ms and bins",
            ),
            Self::Static | Self::Dynamic | Self::Combined | Self::Stacked | Self::Late => (
                &[],
                "only time-surface, histogram and voxel-grid take these settings",
            ),
        };
        let refuse = |field: &'static str, value: String| ReprError::InvalidConfig {
            field,
            value,
            reason,
        };
        if !self.is_dense() {
            return Err(refuse("kind", self.name().to_string()));
        }
        let DenseSettings {
            tau_ms,
            threshold,
            window_ms,
            bins,
        } = settings;
        let given = [
            ("tau_ms", tau_ms.map(|v| v.to_string())),
            ("threshold", threshold.map(|v| v.to_string())),
            ("window_ms", window_ms.map(|v| v.to_string())),
            ("bins", bins.map(|v| v.to_string())),
        ];
        if let Some((field, Some(value))) = given
            .into_iter()
            .find(|(field, value)| value.is_some() && !takes.contains(field))
        {
            return Err(refuse(field, value));
        }
        let config = match self {
            Self::TimeSurface => {
                let d = TimeSurfaceConfig::default();
                ReprConfig::TimeSurface(TimeSurfaceConfig {
                    tau_ms: tau_ms.unwrap_or(d.tau_ms),
                    threshold: threshold.or(d.threshold),
                })
            }
            Self::Histogram => ReprConfig::Histogram(HistogramConfig {
                window_ms: window_ms.unwrap_or(HistogramConfig::default().window_ms),
            }),
            // The binary kinds were refused above.
            _ => {
                let d = VoxelGridConfig::default();
                ReprConfig::VoxelGrid(VoxelGridConfig {
                    window_ms: window_ms.unwrap_or(d.window_ms),
                    bins: bins.unwrap_or(d.bins),
                })
            }
        };
        config.validate()?;
        Ok(config)
    }

    /// The kind whose [`Self::title`] is `title`.
    pub fn from_title(title: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.title() == title)
    }

    /// The kinds among `kinds` (in any order, repeated), in report order.
    pub fn in_order(kinds: impl IntoIterator<Item = Self>) -> Vec<Self> {
        let kinds: Vec<Self> = kinds.into_iter().collect();
        Self::ALL
            .into_iter()
            .filter(|k| kinds.contains(k))
            .collect()
    }
}

/// The settings of a real-valued kind as a front end takes them (the CLI's `--tau-ms`,
/// `--threshold`, `--window-ms`, `--bins`; Python's keywords), for [`ReprKind::dense_config`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DenseSettings {
    /// A time surface's decay constant, ms.
    pub tau_ms: Option<f64>,
    /// A time surface's binarization threshold, in (0, 1).
    pub threshold: Option<f64>,
    /// A histogram's or voxel grid's window, ms.
    pub window_ms: Option<f64>,
    /// A voxel grid's bins.
    pub bins: Option<u32>,
}

/// Shows the [`ReprKind::title`] (`Static`), as reports and tables print kinds; width and
/// alignment apply (`{:<9}`). Command lines and paths use [`ReprKind::name`].
impl fmt::Display for ReprKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.title())
    }
}

/// A name that is not a representation kind.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown representation kind `{0}` (static, dynamic, combined, stacked, late, \
     time-surface, histogram or voxel-grid)"
)]
pub struct UnknownKind(pub String);

impl FromStr for ReprKind {
    type Err = UnknownKind;

    /// Parses [`ReprKind::name`] or [`ReprKind::title`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s || k.title() == s)
            .ok_or_else(|| UnknownKind(s.to_string()))
    }
}

/// Serialized as its [`ReprKind::title`] (`"Static"`), the way `results.json` has always
/// spelled it; either spelling is read.
impl Serialize for ReprKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.title())
    }
}

impl<'de> Deserialize<'de> for ReprKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Serde `with` module writing a [`ReprKind`] as its [`ReprKind::name`] (`"static"`), for files
/// that have always spelled kinds the CLI's way; either spelling is read.
pub mod kind_name {
    use super::ReprKind;
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes `kind`'s [`ReprKind::name`].
    pub fn serialize<S: Serializer>(kind: &ReprKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(kind.name())
    }

    /// Reads a name or a title.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<ReprKind, D::Error> {
        ReprKind::deserialize(d)
    }
}

impl ReprConfig {
    /// This config's kind.
    pub fn kind(&self) -> ReprKind {
        match self {
            Self::Static(_) => ReprKind::Static,
            Self::Dynamic(_) => ReprKind::Dynamic,
            Self::Combined { .. } => ReprKind::Combined,
            Self::Stacked { .. } => ReprKind::Stacked,
            Self::Late { .. } => ReprKind::Late,
            Self::TimeSurface(_) => ReprKind::TimeSurface,
            Self::Histogram(_) => ReprKind::Histogram,
            Self::VoxelGrid(_) => ReprKind::VoxelGrid,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_match_the_configs() {
        for kind in ReprKind::ALL {
            assert_eq!(kind.name().parse::<ReprKind>(), Ok(kind));
            assert_eq!(kind.title().parse::<ReprKind>(), Ok(kind));
            assert_eq!(ReprKind::from_title(kind.title()), Some(kind));
            let config = kind.config(StaticConfig::default(), DynamicConfig::default());
            assert_eq!(config.kind(), kind);
            assert_eq!(config.kind_name(), kind.name());
            assert_eq!(
                kind.parts(),
                (
                    config.static_part().is_some(),
                    config.dynamic_part().is_some()
                )
            );
            let json = serde_json::to_string(&kind).expect("serializes");
            assert_eq!(json, format!("\"{}\"", kind.title()));
            assert_eq!(serde_json::from_str::<ReprKind>(&json).ok(), Some(kind));
        }
        assert_eq!(format!("[{:<8}]", ReprKind::Late), "[Late    ]");
        let err = "pooled".parse::<ReprKind>().expect_err("not a kind");
        assert!(err.to_string().contains("`pooled`"), "{err}");
    }

    #[test]
    fn report_order_is_the_papers_then_the_fusions() {
        use ReprKind::*;
        assert_eq!(
            ReprKind::in_order([Late, Static, Late, Combined]),
            [Static, Combined, Late]
        );
        assert_eq!(
            ReprKind::PAPER.len() + ReprKind::FUSIONS.len() + ReprKind::BEYOND.len(),
            ReprKind::ALL.len()
        );
        assert_eq!(ReprKind::in_order(ReprKind::BEYOND), ReprKind::BEYOND);
        assert!(ReprKind::BEYOND.iter().all(|k| k.is_dense()));
        assert!(ReprKind::BINARY.iter().all(|k| !k.is_dense()));
        assert!(ReprKind::FUSIONS.iter().all(|k| k.is_fusion()));
        assert!(!ReprKind::PAPER.iter().any(|k| k.is_fusion()));
    }
}
