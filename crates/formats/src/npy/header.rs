//! The NPY header dictionary: a Python literal such as
//! `{'descr': [('t', '<i8'), ...], 'fortran_order': False, 'shape': (12,), }`.
//!
//! A small recursive-descent parser for the literal subset numpy writes (strings, integers,
//! `True`/`False`, tuples, lists, dicts) turns it into a [`Value`] tree, from which the record
//! [`Layout`] is taken.

use super::NpyError;
use crate::Event;
use crate::columns::{Field, Slots};

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

/// The largest record accepted, padding included: numpy pads the 13-byte event record to 16
/// when aligned; anything near this size is not an event record, and a padding field declaring
/// gigabytes must not decide how much the reader allocates.
const MAX_RECORD: usize = 1 << 12;

/// A numpy scalar type that can hold an event field: a little-endian integer of 1, 2, 4 or 8
/// bytes, or a bool (numpy's `?`, one byte that is 0 or 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scalar {
    /// Bytes per value.
    pub width: usize,
    /// Whether values are two's-complement signed.
    pub signed: bool,
}

impl Scalar {
    /// Parses a numpy type string (`<i8`, `|u1`, `?`, `b1`); `None` for what is not a
    /// little-endian integer or bool (floats, big-endian, strings), which the caller names.
    pub fn parse(typestr: &str) -> Option<Self> {
        let (order, code) = match typestr.as_bytes().first()? {
            o @ (b'<' | b'>' | b'|' | b'=') => (*o, &typestr[1..]),
            _ => (b'|', typestr),
        };
        let (signed, width) = match code {
            "?" | "b1" => {
                return Some(Self {
                    width: 1,
                    signed: false,
                });
            }
            c if c.len() == 2 => match (c.as_bytes()[0], c.as_bytes()[1]) {
                (b'i', w @ (b'1' | b'2' | b'4' | b'8')) => (true, usize::from(w - b'0')),
                (b'u', w @ (b'1' | b'2' | b'4' | b'8')) => (false, usize::from(w - b'0')),
                _ => return None,
            },
            _ => return None,
        };
        // `|` (not applicable) and `=` (native, little-endian on every machine evtac builds
        // for) are only right for one byte and for native order; `>` never.
        match order {
            b'>' if width > 1 => None,
            b'|' if width > 1 => None,
            _ => Some(Self { width, signed }),
        }
    }

    /// The value at the start of `bytes` as an `i64`; `None` for an unsigned 8-byte value above
    /// `i64::MAX`. `bytes` holds at least `width` bytes (the layout checked it).
    #[inline(always)]
    pub fn load(self, bytes: &[u8]) -> Option<i64> {
        // Fixed-size loads per width: a copy of `width` bytes would be a `memcpy` call per field,
        // which cost NPY decoding most of its speed.
        let raw = match self.width {
            1 => u64::from(bytes[0]),
            2 => u64::from(u16::from_le_bytes([bytes[0], bytes[1]])),
            4 => u64::from(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])),
            _ => u64::from_le_bytes([
                bytes[0], bytes[1], bytes[2], bytes[3], bytes[4], bytes[5], bytes[6], bytes[7],
            ]),
        };
        if self.signed {
            let shift = 64 - 8 * self.width as u32;
            Some(((raw << shift) as i64) >> shift)
        } else {
            i64::try_from(raw).ok()
        }
    }
}

/// Where the four event fields sit in one record, and their types.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Bytes per record (padding included).
    pub itemsize: usize,
    /// Offset and type of `t`, `x`, `y`, `p` (evtac's order, whatever the file's).
    fields: [(usize, Scalar); 4],
}

impl Layout {
    /// Decodes one record of `itemsize` bytes.
    #[inline]
    pub(super) fn decode(&self, r: &[u8]) -> Result<Event, String> {
        let [t, x, y, p] = self
            .fields
            .map(|(offset, scalar)| scalar.load(&r[offset..]));
        let t = t.ok_or_else(|| "t is larger than 2^63 - 1 microseconds".to_string())?;
        let (x, y) = coordinates(x, y)?;
        Ok(Event {
            t,
            x,
            y,
            polarity: polarity(p)?,
        })
    }
}

/// A pixel's column and row from two loaded values: 0 to 65535 each.
#[inline]
pub(crate) fn coordinates(x: Option<i64>, y: Option<i64>) -> Result<(u16, u16), String> {
    match (x.map(u16::try_from), y.map(u16::try_from)) {
        (Some(Ok(x)), Some(Ok(y))) => Ok((x, y)),
        _ if x.is_some_and(|v| v < 0) || y.is_some_and(|v| v < 0) => Err(format!(
            "negative coordinate (x={}, y={})",
            x.unwrap_or_default(),
            y.unwrap_or_default()
        )),
        _ => Err(format!(
            "coordinate beyond 65535 (x={:?}, y={:?})",
            x.unwrap_or(i64::MAX),
            y.unwrap_or(i64::MAX)
        )),
    }
}

/// A polarity from a loaded value: 1 is ON, 0 OFF, and -1 OFF too (tools that store the sign
/// of the brightness change write -1; it cannot mean ON).
#[inline]
pub(crate) fn polarity(p: Option<i64>) -> Result<bool, String> {
    match p {
        Some(1) => Ok(true),
        Some(0 | -1) => Ok(false),
        p => Err(format!(
            "p = {} is not 1 (ON), 0 or -1 (OFF)",
            p.unwrap_or(i64::MAX)
        )),
    }
}

/// An NPY header: the array's element type and its length.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Header {
    /// The `descr` value: a type string for a plain array, a list of fields for a record array.
    descr: Value,
    /// The `descr` as written, for error messages.
    descr_text: String,
    /// Number of elements.
    pub count: u64,
}

impl Header {
    /// The element type of a plain (not record) array, or an error naming what it is.
    pub fn scalar(&self) -> Result<Scalar, NpyError> {
        match &self.descr {
            Value::Str(typestr) => Scalar::parse(typestr).ok_or_else(|| {
                self.unsupported(format!(
                    "`{typestr}` is not a little-endian integer or bool (event fields are \
                     integer microseconds, pixels and 0/1 polarities)"
                ))
            }),
            _ => Err(self.unsupported("a record (structured) dtype, not a plain array".into())),
        }
    }

    fn unsupported(&self, reason: String) -> NpyError {
        NpyError::UnsupportedDtype {
            descr: self.descr_text.clone(),
            reason,
        }
    }

    /// The record layout of a record array of events.
    pub fn layout(&self) -> Result<Layout, NpyError> {
        let Value::Seq(fields) = &self.descr else {
            return Err(self.unsupported("not a record (structured) dtype".into()));
        };
        let unsupported = |reason: String| self.unsupported(reason);
        let mut offset = 0usize;
        let mut slots = Slots::default();
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
            let size = if name.is_empty() && kind.trim_start_matches('|').starts_with('V') {
                kind.trim_start_matches('|')[1..]
                    .parse::<usize>()
                    .ok()
                    .filter(|&n| n <= MAX_RECORD)
                    .ok_or_else(|| {
                        unsupported(format!(
                            "padding field of type `{kind}` is not a size of at most \
                             {MAX_RECORD} bytes"
                        ))
                    })?
            } else {
                let Some(field) = Field::of(name) else {
                    return Err(unsupported(format!(
                        "unexpected field `{name}` (event fields are named {})",
                        Field::accepted()
                    )));
                };
                let scalar = Scalar::parse(kind)
                    .ok_or_else(|| unsupported(format!("field `{name}` has type `{kind}`")))?;
                slots
                    .set(field, (offset, scalar), name)
                    .map_err(&unsupported)?;
                scalar.width
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
        let fields = slots.complete().map_err(&unsupported)?;
        Ok(Layout {
            itemsize: offset,
            fields,
        })
    }
}

/// Parses the header text: the element type and the length of a one-dimensional C-order array.
pub(super) fn parse(text: &str) -> Result<Header, NpyError> {
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
    Ok(Header {
        descr: get("descr")?.clone(),
        descr_text,
        count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The layout and length of a record array's header, or the error.
    fn parse_layout(text: &str) -> Result<(Layout, u64), NpyError> {
        let header = parse(text)?;
        Ok((header.layout()?, header.count))
    }

    fn offsets(l: &Layout) -> [usize; 4] {
        l.fields.map(|(offset, _)| offset)
    }

    #[test]
    fn packed_and_padded_records() {
        let (l, n) = parse_layout(
            "{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')], \
             'fortran_order': False, 'shape': (7,), }",
        )
        .unwrap();
        assert_eq!((l.itemsize, offsets(&l), n), (13, [0, 8, 10, 12], 7));
        let (l, n) = parse_layout(
            "{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1'), ('', '|V3')], \
             'fortran_order': False, 'shape': (219596,), }",
        )
        .unwrap();
        assert_eq!((l.itemsize, n), (16, 219596));
    }

    #[test]
    fn other_orders_names_and_types() {
        let (l, _) = parse_layout(
            "{'descr': [('p', '|b1'), ('x', '<u2'), ('y', '<u2'), ('t', '<i8')], \
             'fortran_order': False, 'shape': (0,)}",
        )
        .unwrap();
        assert_eq!((offsets(&l), l.itemsize), ([5, 1, 3, 0], 13));
        // dv-processing's EventStore.numpy() and the `aedat` package's event arrays.
        let (l, _) = parse_layout(
            "{'descr': [('timestamp', '<i8'), ('x', '<i2'), ('y', '<i2'), ('polarity', '|i1'), \
             ('', '|V3')], 'fortran_order': False, 'shape': (1,)}",
        )
        .unwrap();
        assert_eq!((offsets(&l), l.itemsize), ([0, 8, 10, 12], 16));
        let (l, _) = parse_layout(
            "{'descr': [('t', '<u8'), ('x', '<u2'), ('y', '<u2'), ('on', '|b1')], \
             'fortran_order': False, 'shape': (1,)}",
        )
        .unwrap();
        assert_eq!(
            l.fields[0].1,
            Scalar {
                width: 8,
                signed: false
            }
        );
    }

    #[test]
    fn scalars_load_sign_and_range() {
        let s = |t: &str| Scalar::parse(t).unwrap();
        assert_eq!(s("|i1").load(&[0xff]), Some(-1));
        assert_eq!(s("<i2").load(&[0xfe, 0xff]), Some(-2));
        assert_eq!(s("<u2").load(&[0xfe, 0xff]), Some(65534));
        assert_eq!(s("<i4").load(&(-7i32).to_le_bytes()), Some(-7));
        assert_eq!(s("<u8").load(&u64::MAX.to_le_bytes()), None);
        assert_eq!(s("<u8").load(&5u64.to_le_bytes()), Some(5));
        for bad in [">i8", "<f8", "|i2", "<i3", "S4", ""] {
            assert_eq!(Scalar::parse(bad), None, "{bad}");
        }
        assert_eq!(polarity(Some(-1)), Ok(false));
        assert!(polarity(Some(2)).unwrap_err().contains("p = 2"));
        assert!(
            coordinates(Some(-1), Some(0))
                .unwrap_err()
                .contains("negative")
        );
        assert!(
            coordinates(Some(70_000), Some(0))
                .unwrap_err()
                .contains("65535")
        );
    }

    #[test]
    fn plain_arrays_give_their_scalar() {
        let h = parse("{'descr': '<u4', 'fortran_order': False, 'shape': (3,)}").unwrap();
        assert_eq!(
            (h.scalar().unwrap(), h.count),
            (
                Scalar {
                    width: 4,
                    signed: false
                },
                3
            )
        );
        let h = parse("{'descr': '<f8', 'fortran_order': False, 'shape': (3,)}").unwrap();
        assert!(h.scalar().unwrap_err().to_string().contains("`<f8` is not"));
    }

    #[test]
    fn rejections_name_the_problem() {
        let err = |h: &str| parse_layout(h).unwrap_err().to_string();
        assert!(
            err("{'descr': '<f8', 'fortran_order': False, 'shape': (3,)}").contains("not a record")
        );
        assert!(
            err("{'descr': [('t', '<f8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')], 'fortran_order': False, 'shape': (3,)}")
                .contains("field `t` has type `<f8`")
        );
        assert!(
            err("{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2')], 'fortran_order': False, 'shape': (3,)}")
                .contains("field `p`")
        );
        assert!(
            err("{'descr': [('t', '<i8'), ('timestamp', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')], 'fortran_order': False, 'shape': (3,)}")
                .contains("two columns")
        );
        assert!(
            err("{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')], 'fortran_order': False, 'shape': (3, 2)}")
                .contains("2 dimensions")
        );
        assert!(err("{'descr': [], 'shape': (3,)}").contains("`fortran_order`"));
        assert!(err("{'descr': [('t'").contains("character"));
    }
}
