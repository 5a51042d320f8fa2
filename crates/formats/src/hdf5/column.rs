//! One event field's HDF5 dataset: its element type checked once, then windows of its raw bytes
//! read into a reused buffer and decoded into the events' fields.
//!
//! A contiguous dataset's window is read at its address (`stored.rs`); a chunked one's comes
//! from `hdf5-pure`'s row-window read, so only the chunks a window overlaps are read and
//! inflated. The decoding is ours because the crate's typed reads allocate a vector per window
//! and per type; the common layouts are decoded by `fused.rs` in one pass over all four
//! columns, and this file's checked path decodes the rest and names a bad value.
//! Before any read, the dataset must be one-dimensional with an element of at most 8 bytes,
//! claim no more data than the file can hold, and store every chunk inside the file:
//! `hdf5-pure` 0.47 sizes a read buffer from a chunk's stored size before it checks that against
//! the file (a damaged size asked for 4 GiB in our mutation tests), and sizes a whole read, and
//! the fill values of storage never written, from the dataspace and the element (up to 910 GB).

use hdf5_pure::{Dataset, Datatype, DatatypeByteOrder};

use hdf5_pure::Layout;

use super::fused::microseconds;
use super::stored::FileBytes;
use super::{Hdf5Error, library};
use crate::columns::Field;

/// Runs `$body` for each element `$v` of `$raw` stored as `$t` (`$n` bytes, in `$column`'s byte
/// order), with `$item` the matching element of `$out` and `$i` its index.
macro_rules! each_value {
    ($column:expr, $raw:expr, $out:expr, $t:ty, $n:literal, |$i:ident, $item:ident, $v:ident| $body:block) => {
        for ($i, ($item, bytes)) in $out.iter_mut().zip($raw.chunks_exact($n)).enumerate() {
            let bytes: [u8; $n] = bytes.try_into().unwrap_or_default();
            let $v = if $column.big_endian {
                <$t>::from_be_bytes(bytes)
            } else {
                <$t>::from_le_bytes(bytes)
            };
            $body
        }
    };
}

/// How a dataset's elements are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// Integers of 1, 2, 4 or 8 bytes (an enumeration, as h5py writes numpy's bool, reads as its
    /// integer base).
    Int { width: usize, signed: bool },
    /// IEEE floats of 4 or 8 bytes, seconds (times only).
    Seconds { width: usize },
}

/// One event field's dataset.
#[derive(Debug)]
pub(super) struct Column {
    pub(super) path: String,
    dataset: Dataset,
    pub(super) kind: Kind,
    big_endian: bool,
    /// Where a contiguous dataset's bytes start in the file; `None` for storage `hdf5-pure`
    /// reads (chunked, compact, or never written).
    address: Option<u64>,
    /// Elements (the dataset's one dimension; 1 for a scalar).
    pub(super) len: usize,
    /// Whether the dataset is a scalar (DSEC's `t_offset`) rather than one-dimensional.
    pub(super) scalar: bool,
}

impl Column {
    /// Checks `dataset`'s type, shape and chunks for `field` (see the module docs).
    pub(super) fn new(
        path: String,
        dataset: Dataset,
        field: Field,
        file_len: u64,
    ) -> Result<Self, Hdf5Error> {
        let datatype = dataset.datatype().map_err(library(&path))?;
        let (kind, big_endian) = kind(&datatype).ok_or_else(|| Hdf5Error::Type {
            dataset: path.clone(),
            found: describe(&datatype),
            expected: if field == Field::T {
                "times are integer microseconds or float seconds"
            } else {
                "pixels and polarities are integers (or bool)"
            },
        })?;
        if matches!(kind, Kind::Seconds { .. }) && field != Field::T {
            return Err(Hdf5Error::Type {
                dataset: path,
                found: describe(&datatype),
                expected: "pixels and polarities are integers (or bool)",
            });
        }
        let shape = dataset.shape().map_err(library(&path))?;
        let scalar = shape.is_empty();
        let len = match shape.as_slice() {
            [] => 1,
            [n] => usize::try_from(*n).map_err(|_| Hdf5Error::Metadata {
                object: path.clone(),
                reason: format!("claims {n} elements"),
            })?,
            other => {
                return Err(Hdf5Error::Shapes {
                    shapes: format!("{path} {other:?}"),
                });
            }
        };
        // What the file can back: stored bytes, or what a filter (gzip at most ~1,000 to 1) can
        // have made of them. A dataset whose storage was never written, or a damaged size,
        // would otherwise stream fill values for as long as it claims.
        let width = match kind {
            Kind::Int { width, .. } | Kind::Seconds { width } => width as u64,
        };
        let ratio = if dataset.filters().is_empty() {
            1
        } else {
            4096
        };
        let claimed = (len as u64).saturating_mul(width);
        if claimed > file_len.saturating_mul(ratio) {
            return Err(Hdf5Error::Metadata {
                object: path,
                reason: format!(
                    "claims {len} elements ({claimed} bytes), more than the {file_len}-byte file \
                     holds (a damaged or cut file, or a dataset never written?)"
                ),
            });
        }
        let address = match dataset.layout().map_err(library(&path))? {
            Layout::Contiguous {
                address: Some(address),
                size,
            } => {
                if size != claimed {
                    return Err(Hdf5Error::Metadata {
                        object: path,
                        reason: format!(
                            "stores {size} bytes for {len} elements of {width} bytes (a damaged \
                             file?)"
                        ),
                    });
                }
                if address
                    .checked_add(claimed)
                    .is_none_or(|end| end > file_len)
                {
                    return Err(Hdf5Error::Metadata {
                        object: path,
                        reason: format!(
                            "its {claimed} bytes at byte {address} run past the end of the \
                             {file_len}-byte file (a damaged or cut file?)"
                        ),
                    });
                }
                Some(address)
            }
            _ => None,
        };
        if dataset.is_chunked() {
            // `chunks` walks the chunk index: its entries come from the file, so a damaged one
            // is bounded by the file's size.
            for chunk in dataset.chunks().map_err(library(&path))? {
                if chunk
                    .address
                    .checked_add(chunk.storage_size)
                    .is_none_or(|end| end > file_len)
                {
                    return Err(Hdf5Error::Metadata {
                        object: path,
                        reason: format!(
                            "a chunk claims {} bytes at byte {}, past the end of the \
                             {file_len}-byte file (a damaged or cut file?)",
                            chunk.storage_size, chunk.address
                        ),
                    });
                }
            }
        }
        Ok(Self {
            path,
            dataset,
            kind,
            big_endian,
            address,
            len,
            scalar,
        })
    }

    /// How the elements are stored, when [`super::fused`] may decode them (little-endian).
    pub(super) fn fused_kind(&self) -> Option<Kind> {
        (!self.big_endian).then_some(self.kind)
    }

    /// Whether the elements are float seconds.
    pub(super) fn seconds(&self) -> bool {
        matches!(self.kind, Kind::Seconds { .. })
    }

    /// The path and shape, for an error message.
    pub(super) fn shape(&self) -> String {
        if self.scalar {
            format!("{} []", self.path)
        } else {
            format!("{} [{}]", self.path, self.len)
        }
    }

    /// The stored bytes of the elements `start..start + count` (`count` at most a slice of
    /// events, so at most 8 bytes each) in `buf`, read from `file` at the dataset's address when
    /// it is contiguous, else by `hdf5-pure`.
    pub(super) fn raw_into<'b>(
        &self,
        file: &mut FileBytes,
        start: usize,
        count: usize,
        buf: &'b mut Vec<u8>,
    ) -> Result<&'b [u8], Hdf5Error> {
        let Some(address) = self.address else {
            *buf = self.library_raw(start, count)?;
            return Ok(buf);
        };
        let width = self.width();
        let n = count * width;
        // Grown once to a slice's size, then reused: no clearing of fresh pages per slice.
        if buf.len() < n {
            buf.resize(n, 0);
        }
        let window = &mut buf[..n];
        // `new` checked the whole dataset against the file's length, so this cannot overflow.
        let offset = address + (start * width) as u64;
        file.read_at(offset, window)
            .map_err(|e| Hdf5Error::Library {
                object: self.path.clone(),
                message: format!("reading {n} bytes at byte {offset}: {e}"),
            })?;
        Ok(window)
    }

    /// Bytes per element.
    fn width(&self) -> usize {
        match self.kind {
            Kind::Int { width, .. } | Kind::Seconds { width } => width,
        }
    }

    /// The stored bytes of the elements `start..start + count`, read by `hdf5-pure`.
    fn library_raw(&self, start: usize, count: usize) -> Result<Vec<u8>, Hdf5Error> {
        let raw = self
            .dataset
            .read_raw_rows(start as u64, count as u64)
            .map_err(library(&self.path))?;
        let width = self.width();
        if raw.len() != count * width {
            return Err(Hdf5Error::Metadata {
                object: self.path.clone(),
                reason: format!(
                    "{} bytes read for elements {start}..{}",
                    raw.len(),
                    start + count
                ),
            });
        }
        Ok(raw)
    }

    /// The error refusing element `index`, for `reason`.
    fn value_error(&self, index: usize, reason: String) -> Hdf5Error {
        Hdf5Error::Value {
            dataset: self.path.clone(),
            index,
            reason,
        }
    }

    /// Decodes the integers stored in `raw`, elements `start..start + out.len()`, into `out`,
    /// through `set(item, value)`, whose error is the reason element `start + i` is refused.
    pub(super) fn ints<T>(
        &self,
        raw: &[u8],
        start: usize,
        out: &mut [T],
        mut set: impl FnMut(&mut T, i64) -> Result<(), String>,
    ) -> Result<(), Hdf5Error> {
        let Kind::Int { width, signed } = self.kind else {
            return Err(Hdf5Error::Metadata {
                object: self.path.clone(),
                reason: "float seconds read as integers".into(),
            });
        };
        let fail = |i: usize, reason: String| self.value_error(start + i, reason);
        // One loop per stored type, so each is a plain widening loop.
        macro_rules! each {
            ($t:ty, $n:literal) => {
                each_value!(self, raw, out, $t, $n, |i, item, v| {
                    // u64 above i64::MAX is no event field: refused by name.
                    let v =
                        i64::try_from(v).map_err(|_| fail(i, format!("{v} is above 2^63 - 1")))?;
                    set(item, v).map_err(|reason| fail(i, reason))?;
                })
            };
        }
        match (width, signed) {
            (1, true) => each!(i8, 1),
            (1, false) => each!(u8, 1),
            (2, true) => each!(i16, 2),
            (2, false) => each!(u16, 2),
            (4, true) => each!(i32, 4),
            (4, false) => each!(u32, 4),
            (8, true) => each!(i64, 8),
            _ => each!(u64, 8),
        }
        Ok(())
    }

    /// Decodes the times stored in `raw`, elements `start..start + out.len()`, into `out` in
    /// microseconds (float seconds rounded to the nearest microsecond), through `set(item, t)`.
    pub(super) fn times<T>(
        &self,
        raw: &[u8],
        start: usize,
        out: &mut [T],
        mut set: impl FnMut(&mut T, i64) -> Result<(), String>,
    ) -> Result<(), Hdf5Error> {
        let Kind::Seconds { width } = self.kind else {
            return self.ints(raw, start, out, set);
        };
        let fail = |i: usize, reason: String| self.value_error(start + i, reason);
        let mut each = |i: usize, item: &mut T, s: f64| {
            let (us, fits) = microseconds(s);
            if !fits {
                return Err(fail(i, format!("{s} s is not a time in microseconds")));
            }
            set(item, us).map_err(|reason| fail(i, reason))
        };
        macro_rules! each {
            ($t:ty, $n:literal) => {
                each_value!(self, raw, out, $t, $n, |i, item, s| {
                    each(i, item, f64::from(s))?;
                })
            };
        }
        if width == 4 {
            each!(f32, 4);
        } else {
            each!(f64, 8);
        }
        Ok(())
    }

    /// Element `i` as an integer (an index entry, a time at a range's edge, `t_offset`).
    pub(super) fn get(&self, i: usize) -> Result<i64, Hdf5Error> {
        let mut v = [0i64];
        let raw = self.library_raw(i, 1)?;
        self.times(&raw, i, &mut v, |slot, t| {
            *slot = t;
            Ok(())
        })?;
        Ok(v[0])
    }
}

/// How elements of `datatype` are read, and whether they are big-endian; `None` for types that
/// hold no event field.
fn kind(datatype: &Datatype) -> Option<(Kind, bool)> {
    match datatype {
        Datatype::FixedPoint {
            size,
            byte_order,
            layout,
        } if matches!(size, 1 | 2 | 4 | 8)
            && layout.bit_offset == 0
            && u32::from(layout.bit_precision) == size * 8 =>
        {
            Some((
                Kind::Int {
                    width: *size as usize,
                    signed: layout.signed,
                },
                big_endian(*byte_order)?,
            ))
        }
        Datatype::FloatingPoint {
            size, byte_order, ..
        } if matches!(size, 4 | 8) => Some((
            Kind::Seconds {
                width: *size as usize,
            },
            big_endian(*byte_order)?,
        )),
        // h5py's bool: an enumeration FALSE = 0, TRUE = 1 over int8; its values are the base's.
        Datatype::Enumeration {
            size, base_type, ..
        } => match kind(base_type)? {
            (Kind::Int { width, signed }, be) if width == *size as usize => {
                Some((Kind::Int { width, signed }, be))
            }
            _ => None,
        },
        _ => None,
    }
}

fn big_endian(order: DatatypeByteOrder) -> Option<bool> {
    match order {
        DatatypeByteOrder::LittleEndian => Some(false),
        DatatypeByteOrder::BigEndian => Some(true),
        _ => None,
    }
}

/// A type for an error message: its class and size, not the whole structure.
fn describe(datatype: &Datatype) -> String {
    match datatype {
        Datatype::FixedPoint { size, layout, .. } => {
            let bits = u64::from(*size) * 8;
            format!("{}int{bits}", if layout.signed { "" } else { "u" })
        }
        Datatype::FloatingPoint { size, .. } => format!("float{}", u64::from(*size) * 8),
        Datatype::String { size, .. } => format!("string ({size} bytes)"),
        Datatype::Enumeration { base_type, .. } => format!("enum of {}", describe(base_type)),
        other => format!("{other:?}").chars().take(80).collect(),
    }
}
