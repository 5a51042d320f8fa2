//! The NPY header dictionary: a Python literal such as
//! `{'descr': [('t', '<i8'), ...], 'fortran_order': False, 'shape': (12,), }`.
//!
//! A small recursive-descent parser for the literal subset numpy writes (strings, integers,
//! `True`/`False`, tuples, lists, dicts) turns it into a [`Value`] tree, from which the record
//! [`Layout`] is taken.

use super::NpyError;
use crate::Event;

/// A parsed Python literal.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Str(String),
    Int(i128),
    Bool(bool),
    /// Tuples and lists alike.
    Seq(Vec<Value>),
    Dict(Vec<(String, Value)>),
}

struct Parser<'a> {
    text: &'a [u8],
    pos: usize,
}

impl Parser<'_> {
    fn skip_space(&mut self) {
        while self
            .text
            .get(self.pos)
            .is_some_and(|b| b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
    }

    fn err(&self, what: &str) -> NpyError {
        NpyError::BadHeader(format!("{what} at character {} of the header", self.pos))
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_space();
        self.text.get(self.pos).copied()
    }

    fn expect(&mut self, c: u8) -> Result<(), NpyError> {
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.err(&format!("expected `{}`", c as char)))
        }
    }

    fn value(&mut self, depth: usize) -> Result<Value, NpyError> {
        if depth > 8 {
            return Err(self.err("nesting too deep"));
        }
        match self.peek() {
            Some(q @ (b'\'' | b'"')) => {
                self.pos += 1;
                let start = self.pos;
                while self.text.get(self.pos).is_some_and(|&b| b != q) {
                    self.pos += 1;
                }
                if self.pos >= self.text.len() {
                    return Err(self.err("unterminated string"));
                }
                let s = String::from_utf8_lossy(&self.text[start..self.pos]).into_owned();
                self.pos += 1;
                Ok(Value::Str(s))
            }
            Some(open @ (b'(' | b'[')) => {
                self.pos += 1;
                let close = if open == b'(' { b')' } else { b']' };
                let mut items = Vec::new();
                loop {
                    if self.peek() == Some(close) {
                        self.pos += 1;
                        return Ok(Value::Seq(items));
                    }
                    items.push(self.value(depth + 1)?);
                    match self.peek() {
                        Some(b',') => self.pos += 1,
                        Some(c) if c == close => {}
                        _ => return Err(self.err("expected `,` or a closing bracket")),
                    }
                }
            }
            Some(b'{') => {
                self.pos += 1;
                let mut entries = Vec::new();
                loop {
                    if self.peek() == Some(b'}') {
                        self.pos += 1;
                        return Ok(Value::Dict(entries));
                    }
                    let Value::Str(key) = self.value(depth + 1)? else {
                        return Err(self.err("dictionary keys must be strings"));
                    };
                    self.expect(b':')?;
                    entries.push((key, self.value(depth + 1)?));
                    match self.peek() {
                        Some(b',') => self.pos += 1,
                        Some(b'}') => {}
                        _ => return Err(self.err("expected `,` or `}`")),
                    }
                }
            }
            Some(c) if c == b'-' || c.is_ascii_digit() => {
                let start = self.pos;
                self.pos += 1;
                while self
                    .text
                    .get(self.pos)
                    .is_some_and(|b| b.is_ascii_digit() || *b == b'L')
                {
                    self.pos += 1;
                }
                let digits = String::from_utf8_lossy(&self.text[start..self.pos]).replace('L', "");
                digits
                    .parse()
                    .map(Value::Int)
                    .map_err(|_| self.err("bad integer"))
            }
            Some(_) if self.text[self.pos..].starts_with(b"True") => {
                self.pos += 4;
                Ok(Value::Bool(true))
            }
            Some(_) if self.text[self.pos..].starts_with(b"False") => {
                self.pos += 5;
                Ok(Value::Bool(false))
            }
            _ => Err(self.err("unexpected text")),
        }
    }
}

/// How a record's coordinate field is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Coordinate {
    /// `<i2`: negative values are rejected.
    I16,
    /// `<u2`.
    U16,
}

/// The largest record accepted, padding included: numpy pads the 13-byte event record to 16
/// when aligned; anything near this size is not an event record, and a padding field declaring
/// gigabytes must not decide how much the reader allocates.
const MAX_RECORD: usize = 1 << 12;

/// Where the four event fields sit in one record.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Bytes per record (padding included).
    pub itemsize: usize,
    t: usize,
    x: usize,
    y: usize,
    p: usize,
    coordinate: Coordinate,
}

impl Layout {
    /// Decodes one record of `itemsize` bytes.
    #[inline]
    pub(super) fn decode(&self, r: &[u8]) -> Result<Event, String> {
        let t = i64::from_le_bytes([
            r[self.t],
            r[self.t + 1],
            r[self.t + 2],
            r[self.t + 3],
            r[self.t + 4],
            r[self.t + 5],
            r[self.t + 6],
            r[self.t + 7],
        ]);
        let x = u16::from_le_bytes([r[self.x], r[self.x + 1]]);
        let y = u16::from_le_bytes([r[self.y], r[self.y + 1]]);
        if self.coordinate == Coordinate::I16 && (x > i16::MAX as u16 || y > i16::MAX as u16) {
            return Err(format!(
                "negative coordinate (x={}, y={})",
                x as i16, y as i16
            ));
        }
        let polarity = match r[self.p] {
            0 => false,
            1 => true,
            p => return Err(format!("p = {p} is neither 0 nor 1")),
        };
        Ok(Event { t, x, y, polarity })
    }
}

/// Parses the header text into the record layout and the record count.
pub(super) fn parse(text: &str) -> Result<(Layout, u64), NpyError> {
    let mut parser = Parser {
        text: text.as_bytes(),
        pos: 0,
    };
    let Value::Dict(entries) = parser.value(0)? else {
        return Err(NpyError::BadHeader("the header is not a dictionary".into()));
    };
    let get = |key: &str| {
        entries
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v)
            .ok_or_else(|| NpyError::BadHeader(format!("the header has no `{key}` key")))
    };
    match get("fortran_order")? {
        Value::Bool(false) => {}
        Value::Bool(true) => {
            return Err(NpyError::BadShape {
                field: "fortran_order",
                reason: "Fortran order is not supported for a record array".into(),
            });
        }
        _ => {
            return Err(NpyError::BadShape {
                field: "fortran_order",
                reason: "not True or False".into(),
            });
        }
    }
    let count = match get("shape")? {
        Value::Seq(dims) => match dims.as_slice() {
            [Value::Int(n)] => u64::try_from(*n).map_err(|_| NpyError::BadShape {
                field: "shape",
                reason: format!("negative length {n}"),
            })?,
            _ => {
                return Err(NpyError::BadShape {
                    field: "shape",
                    reason: format!("{} dimensions; event arrays have one", dims.len()),
                });
            }
        },
        _ => {
            return Err(NpyError::BadShape {
                field: "shape",
                reason: "not a tuple".into(),
            });
        }
    };
    let descr_text = text
        .find("'descr'")
        .and_then(|i| text.get(i + "'descr'".len()..))
        .map(|rest| rest.trim_start().strip_prefix(':').unwrap_or(rest))
        .and_then(|rest| rest.split("'fortran_order'").next())
        .unwrap_or("")
        .trim()
        .trim_end_matches(',')
        .trim()
        .to_string();
    let unsupported = |reason: String| NpyError::UnsupportedDtype {
        descr: descr_text.clone(),
        reason,
    };
    let Value::Seq(fields) = get("descr")? else {
        return Err(unsupported("not a record (structured) dtype".into()));
    };
    let mut offset = 0usize;
    let (mut t, mut x, mut y, mut p) = (None, None, None, None);
    let mut coordinate = None;
    for field in fields {
        let (name, kind) = match field {
            Value::Seq(parts) => match parts.as_slice() {
                [Value::Str(n), Value::Str(k)] => (n.as_str(), k.as_str()),
                [Value::Str(n), _, _] => {
                    return Err(unsupported(format!("field `{n}` is a sub-array")));
                }
                _ => return Err(unsupported("a field is not a (name, type) pair".into())),
            },
            _ => return Err(unsupported("a field is not a (name, type) pair".into())),
        };
        let size = match (name, kind) {
            ("", k) if k.starts_with("|V") || k.starts_with("V") => k.trim_start_matches('|')[1..]
                .parse::<usize>()
                .ok()
                .filter(|&n| n <= MAX_RECORD)
                .ok_or_else(|| {
                    unsupported(format!(
                        "padding field of type `{k}` is not a size of at most {MAX_RECORD} bytes"
                    ))
                })?,
            ("t", "<i8") => set(&mut t, offset, name, &unsupported)? + 8,
            ("x" | "y", "<i2" | "<u2") => {
                let c = if kind == "<i2" {
                    Coordinate::I16
                } else {
                    Coordinate::U16
                };
                if coordinate.is_some_and(|old| old != c) {
                    return Err(unsupported("x and y have different types".into()));
                }
                coordinate = Some(c);
                let slot = if name == "x" { &mut x } else { &mut y };
                set(slot, offset, name, &unsupported)? + 2
            }
            ("p", "|u1" | "u1" | "|b1" | "b1" | "?") => {
                set(&mut p, offset, name, &unsupported)? + 1
            }
            ("t" | "x" | "y" | "p", k) => {
                return Err(unsupported(format!("field `{name}` has type `{k}`")));
            }
            (n, _) => return Err(unsupported(format!("unexpected field `{n}`"))),
        };
        offset += size;
        // Each field adds at most MAX_RECORD bytes, so the sum cannot overflow before this.
        if offset > MAX_RECORD {
            return Err(unsupported(format!(
                "the fields make records of more than {MAX_RECORD} bytes (the event record \
                 takes 13)"
            )));
        }
    }
    let missing = |name: &str| unsupported(format!("field `{name}` is missing"));
    let layout = Layout {
        itemsize: offset,
        t: t.ok_or_else(|| missing("t"))?,
        x: x.ok_or_else(|| missing("x"))?,
        y: y.ok_or_else(|| missing("y"))?,
        p: p.ok_or_else(|| missing("p"))?,
        coordinate: coordinate.unwrap_or(Coordinate::I16),
    };
    Ok((layout, count))
}

/// Records a field's offset, rejecting a second field of the same name; returns 0 so the caller
/// adds the field size.
fn set(
    slot: &mut Option<usize>,
    offset: usize,
    name: &str,
    unsupported: &impl Fn(String) -> NpyError,
) -> Result<usize, NpyError> {
    if slot.is_some() {
        return Err(unsupported(format!("field `{name}` appears twice")));
    }
    *slot = Some(offset);
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_and_padded_records() {
        let (l, n) = parse(
            "{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')], \
             'fortran_order': False, 'shape': (7,), }",
        )
        .unwrap();
        assert_eq!((l.itemsize, l.t, l.x, l.y, l.p, n), (13, 0, 8, 10, 12, 7));
        let (l, n) = parse(
            "{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1'), ('', '|V3')], \
             'fortran_order': False, 'shape': (219596,), }",
        )
        .unwrap();
        assert_eq!((l.itemsize, n), (16, 219596));
    }

    #[test]
    fn other_orders_and_types() {
        let (l, _) = parse(
            "{'descr': [('p', '|b1'), ('x', '<u2'), ('y', '<u2'), ('t', '<i8')], \
             'fortran_order': False, 'shape': (0,)}",
        )
        .unwrap();
        assert_eq!((l.p, l.x, l.y, l.t, l.itemsize), (0, 1, 3, 5, 13));
    }

    #[test]
    fn rejections_name_the_problem() {
        let err = |h: &str| parse(h).unwrap_err().to_string();
        assert!(
            err("{'descr': '<f8', 'fortran_order': False, 'shape': (3,)}").contains("not a record")
        );
        assert!(
            err("{'descr': [('t', '<f8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')], 'fortran_order': False, 'shape': (3,)}")
                .contains("field `t` has type `<f8`")
        );
        assert!(
            err("{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2')], 'fortran_order': False, 'shape': (3,)}")
                .contains("field `p` is missing")
        );
        assert!(
            err("{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')], 'fortran_order': False, 'shape': (3, 2)}")
                .contains("2 dimensions")
        );
        assert!(err("{'descr': [], 'shape': (3,)}").contains("`fortran_order`"));
        assert!(err("{'descr': [('t'").contains("character"));
    }
}
