//! [`ReprKind`]: the one list of representation kinds, their names (`static` on the command line
//! and in configs, `Static` in reports) and how a kind's config is built from a static and a
//! dynamic part. Every front end (the CLI's `--repr`, the Python package, the experiments, the
//! report) spells kinds through it, so adding a kind touches this file, [`crate::ReprConfig`]
//! and the network that reads it, not every command.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::config::{DynamicConfig, ReprConfig, StaticConfig};

/// A representation kind: the paper's three, then evtac's two learned fusions.
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
}

impl ReprKind {
    /// Every kind, in report order: the paper's three, then the learned fusions.
    pub const ALL: [Self; 5] = [
        Self::Static,
        Self::Dynamic,
        Self::Combined,
        Self::Stacked,
        Self::Late,
    ];
    /// The paper's three kinds.
    pub const PAPER: [Self; 3] = [Self::Static, Self::Dynamic, Self::Combined];
    /// evtac's learned fusions of the static and dynamic frames (not in the paper).
    pub const FUSIONS: [Self; 2] = [Self::Stacked, Self::Late];

    /// The name on the command line, in configs and in folder names: `static`, `dynamic`,
    /// `combined`, `stacked`, `late`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Static => "static",
            Self::Dynamic => "dynamic",
            Self::Combined => "combined",
            Self::Stacked => "stacked",
            Self::Late => "late",
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
        }
    }

    /// Whether the kind has a static part and a dynamic part.
    pub fn parts(self) -> (bool, bool) {
        match self {
            Self::Static => (true, false),
            Self::Dynamic => (false, true),
            Self::Combined | Self::Stacked | Self::Late => (true, true),
        }
    }

    /// Whether the kind is one of evtac's learned fusions ([`Self::FUSIONS`]).
    pub fn is_fusion(self) -> bool {
        Self::FUSIONS.contains(&self)
    }

    /// This kind's config from a static and a dynamic part (a part the kind does not have is
    /// ignored).
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
        }
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

/// Shows the [`ReprKind::title`] (`Static`), as reports and tables print kinds; width and
/// alignment apply (`{:<9}`). Command lines and paths use [`ReprKind::name`].
impl fmt::Display for ReprKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.title())
    }
}

/// A name that is not a representation kind.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown representation kind `{0}` (static, dynamic, combined, stacked or late)")]
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
            ReprKind::PAPER.len() + ReprKind::FUSIONS.len(),
            ReprKind::ALL.len()
        );
        assert!(ReprKind::FUSIONS.iter().all(|k| k.is_fusion()));
        assert!(!ReprKind::PAPER.iter().any(|k| k.is_fusion()));
    }
}
