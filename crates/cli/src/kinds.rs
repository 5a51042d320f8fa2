//! `--repr`: the representation kinds as clap sees them, from [`ReprKind`] (which owns the list,
//! the names and each kind's description), so no command keeps its own copy.

use anyhow::Context;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use evtac_repr::{DenseSettings, ReprConfig, ReprKind};

/// A value parser for `--repr`: every [`ReprKind::name`], each with its description in `--help`.
pub fn parser() -> impl TypedValueParser<Value = ReprKind> {
    PossibleValuesParser::new(
        ReprKind::ALL.map(|kind| PossibleValue::new(kind.name()).help(kind.describe())),
    )
    .try_map(|name| name.parse::<ReprKind>())
}

/// A real-valued kind's config from the flags that set it (`--tau-ms`, `--threshold`,
/// `--window-ms`, `--bins`), checked, or `None` for a binary kind, which these flags set
/// otherwise (`--bins` then is an error: only a voxel grid has bins).
pub fn dense_config(kind: ReprKind, settings: DenseSettings) -> anyhow::Result<Option<ReprConfig>> {
    if kind.is_dense() {
        let config = kind
            .dense_config(settings)
            .with_context(|| format!("--repr {}", kind.name()))?;
        return Ok(Some(config));
    }
    if let Some(bins) = settings.bins {
        anyhow::bail!(
            "--bins {bins}: only --repr voxel-grid has bins (not {})",
            kind.name()
        );
    }
    Ok(None)
}
