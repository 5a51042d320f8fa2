//! `--repr`: the representation kinds as clap sees them, from [`ReprKind`] (which owns the list,
//! the names and each kind's description), so no command keeps its own copy.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use evtac_repr::ReprKind;

/// A value parser for `--repr`: every [`ReprKind::name`], each with its description in `--help`.
pub fn parser() -> impl TypedValueParser<Value = ReprKind> {
    PossibleValuesParser::new(
        ReprKind::ALL.map(|kind| PossibleValue::new(kind.name()).help(kind.describe())),
    )
    .try_map(|name| name.parse::<ReprKind>())
}
