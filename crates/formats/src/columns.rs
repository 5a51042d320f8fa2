//! The names other tools give the four event fields, in one place: every reader of named
//! columns (NPY and NPZ fields, CSV header lines, HDF5 datasets) asks [`Field::of`] which event
//! field a name is.
//!
//! The names come from the tools evtac's users export with: evtac and tonic write `t, x, y, p`;
//! dv-processing's `EventStore.numpy()` writes `timestamp, x, y, polarity`; the `aedat` Python
//! package writes `t, x, y, on`; event_utils' HDF5 writes `ts, xs, ys, ps`; DSEC's writes
//! `t, x, y, p`. A name is matched exactly (lower case, as they all write it): a near miss such as
//! `time` is not guessed at, and the error lists what is accepted.

use std::fmt;

/// One of the four fields of an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Field {
    /// The timestamp.
    T,
    /// The column.
    X,
    /// The row.
    Y,
    /// The polarity (1 or true: ON).
    P,
}

impl Field {
    /// The four fields in evtac's own order (`t, x, y, p`).
    pub const ALL: [Self; 4] = [Self::T, Self::X, Self::Y, Self::P];

    /// The names each field is accepted under.
    pub const fn names(self) -> &'static [&'static str] {
        match self {
            Self::T => &["t", "timestamp", "ts"],
            Self::X => &["x", "xs"],
            Self::Y => &["y", "ys"],
            Self::P => &["p", "polarity", "on", "ps"],
        }
    }

    /// The field a column named `name` holds, if it is one of [`names`](Self::names).
    pub fn of(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.names().contains(&name))
    }

    /// evtac's own name for the field (`t`, `x`, `y`, `p`).
    pub const fn name(self) -> &'static str {
        self.names()[0]
    }

    /// The accepted names of every field, for error messages: `t|timestamp|ts, x|xs, ...`.
    pub fn accepted() -> String {
        Self::ALL
            .iter()
            .map(|f| f.names().join("|"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which of the four fields sit where: one slot per field, filled once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slots<T> {
    slots: [Option<T>; 4],
}

// Not derived: the derive would ask `T: Default`, which an empty slot does not need.
impl<T> Default for Slots<T> {
    fn default() -> Self {
        Self {
            slots: [None, None, None, None],
        }
    }
}

impl<T: Copy> Slots<T> {
    /// Records where `field` is; an error naming both columns when it was already found.
    pub fn set(&mut self, field: Field, at: T, name: &str) -> Result<(), String> {
        let slot = &mut self.slots[field as usize];
        if slot.is_some() {
            return Err(format!(
                "two columns hold the event field `{field}` (the second is `{name}`)"
            ));
        }
        *slot = Some(at);
        Ok(())
    }

    /// Where `field` is, if found.
    pub fn get(&self, field: Field) -> Option<T> {
        self.slots[field as usize]
    }

    /// Where each of the four fields is, or an error naming the first one missing.
    pub fn complete(&self) -> Result<[T; 4], String> {
        let mut out = [None; 4];
        for field in Field::ALL {
            out[field as usize] = Some(self.get(field).ok_or_else(|| {
                format!(
                    "no column holds the event field `{field}` (accepted names: {})",
                    field.names().join(", ")
                )
            })?);
        }
        Ok(out.map(|v| v.expect("every slot was checked above")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tools_names_map_to_fields() {
        for (name, field) in [
            ("timestamp", Field::T),
            ("polarity", Field::P),
            ("on", Field::P),
            ("xs", Field::X),
            ("ts", Field::T),
        ] {
            assert_eq!(Field::of(name), Some(field), "{name}");
        }
        assert_eq!(Field::of("time"), None);
        assert_eq!(Field::of("T"), None);
        assert_eq!(
            Field::accepted(),
            "t|timestamp|ts, x|xs, y|ys, p|polarity|on|ps"
        );
    }

    #[test]
    fn slots_refuse_a_field_twice_and_name_a_missing_one() {
        let mut s = Slots::default();
        s.set(Field::T, 0, "t").unwrap();
        assert!(
            s.set(Field::T, 1, "timestamp")
                .unwrap_err()
                .contains("`timestamp`")
        );
        s.set(Field::X, 1, "x").unwrap();
        s.set(Field::Y, 2, "y").unwrap();
        assert!(s.complete().unwrap_err().contains("field `p`"));
        s.set(Field::P, 3, "on").unwrap();
        assert_eq!(s.complete().unwrap(), [0, 1, 2, 3]);
    }
}
