//! An NPZ archive of one array per field (`np.savez(f, t=t, x=x, y=y, p=p)`), read a chunk at
//! a time: each chunk takes the next values of all four members into buffers of their own type
//! and builds the events field by field from them.
//!
//! Why field by field: one loop per field and value type (eight of them, chosen once per chunk)
//! loads fixed-width values with no per-value dispatch, where a loop over events would ask each
//! value's type four times an event. The loops only note whether a value is out of range; the
//! first bad value is then looked for in the chunk, event by event in the order `t, x, y, p`, so
//! the error names the member and element a whole-column read named.

use std::io::{Read, Seek};

use super::NpzError;
use super::member::Member;
use crate::check::EventCheck;
use crate::npy::{NpyError, Scalar, coordinates, polarity, read_full, read_header};
use crate::{Event, Resolution};

/// Events per chunk: four buffers of a chunk's values and its events stay in the cache.
const CHUNK: usize = 1 << 15;

/// One member: its stream, value type and the chunk of its bytes read last.
struct Column<R> {
    member: Member<R>,
    scalar: Scalar,
    /// Offset of the first value in the member (after the NPY header).
    data_start: u64,
    buf: Vec<u8>,
}

/// The four members of a per-field archive, read together.
pub(super) struct Fields<R> {
    /// Member names, `t, x, y, p` order.
    names: [String; 4],
    columns: [Column<R>; 4],
    /// Values per member (the headers' length).
    declared: u64,
    /// Events built so far.
    done: u64,
    events: Vec<Event>,
    check: EventCheck,
}

impl<R> std::fmt::Debug for Fields<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fields")
            .field("names", &self.names)
            .field("declared", &self.declared)
            .field("done", &self.done)
            .finish_non_exhaustive()
    }
}

impl<R: Read + Seek> Fields<R> {
    /// Reads the four members' NPY headers and checks that they are integer or bool arrays of
    /// one length whose data fill their members exactly.
    pub(super) fn new(names: [String; 4], members: [Member<R>; 4]) -> Result<Self, NpzError> {
        let mut columns = Vec::with_capacity(4);
        let mut counts = Vec::with_capacity(4);
        for (name, mut member) in names.iter().zip(members) {
            let at = |error| NpzError::Member {
                member: name.clone(),
                error,
            };
            let (header, data_start) = read_header(&mut member).map_err(at)?;
            let scalar = header.scalar().map_err(at)?;
            let declared = header.count;
            // The member's size is known: a short or long array is named now, as a read of the
            // whole member would name it, rather than after the events before it.
            let width = scalar.width as u64;
            let present = member.size().saturating_sub(data_start);
            let wanted = declared.saturating_mul(width);
            if present < wanted {
                return Err(at(NpyError::Truncated {
                    declared,
                    complete: present / width,
                    offset: data_start + present,
                }));
            }
            if present > wanted {
                return Err(at(NpyError::TrailingData {
                    declared,
                    offset: data_start + wanted,
                }));
            }
            counts.push(declared);
            columns.push(Column {
                member,
                scalar,
                data_start,
                buf: Vec::new(),
            });
        }
        if counts.iter().any(|&c| c != counts[0]) {
            let lengths = names
                .iter()
                .zip(&counts)
                .map(|(m, c)| format!("{m} {c}"))
                .collect::<Vec<_>>()
                .join(", ");
            return Err(NpzError::Lengths { lengths });
        }
        let Ok(columns) = <[Column<R>; 4]>::try_from(columns) else {
            unreachable!("one column per member");
        };
        Ok(Self {
            names,
            columns,
            declared: counts[0],
            done: 0,
            events: Vec::new(),
            check: EventCheck::new(None),
        })
    }

    /// The member names, `t, x, y, p` order.
    pub(super) fn names(&self) -> &[String; 4] {
        &self.names
    }

    /// Events built so far, and the number declared.
    pub(super) fn progress(&self) -> (u64, u64) {
        (self.done, self.declared)
    }

    pub(super) fn check(&mut self) -> &mut EventCheck {
        &mut self.check
    }

    pub(super) fn resolution(&self) -> Option<Resolution> {
        self.check.resolution()
    }

    /// The next chunk of events; `Ok(None)` once every member has been read to its end (and
    /// its size and checksum checked).
    pub(super) fn next_chunk(&mut self) -> Result<Option<&[Event]>, NpzError> {
        let remaining = self.declared - self.done;
        if remaining == 0 {
            self.events.clear();
            for (name, c) in self.names.iter().zip(&mut self.columns) {
                let at = |error| NpzError::Member {
                    member: name.clone(),
                    error,
                };
                // The end of the member: data after the values, a short member or a bad
                // checksum (see `member`) are errors here.
                if read_full(&mut c.member, &mut [0u8; 1]).map_err(|e| at(NpyError::Io(e)))? > 0 {
                    return Err(at(NpyError::TrailingData {
                        declared: self.declared,
                        offset: c.data_start + self.declared * c.scalar.width as u64,
                    }));
                }
            }
            return Ok(None);
        }
        let n = remaining.min(CHUNK as u64) as usize;
        for (name, c) in self.names.iter().zip(&mut self.columns) {
            let width = c.scalar.width;
            c.buf.resize(n * width, 0);
            let got = read_full(&mut c.member, &mut c.buf).map_err(|e| NpzError::Member {
                member: name.clone(),
                error: NpyError::Io(e),
            })?;
            if got < c.buf.len() {
                return Err(NpzError::Member {
                    member: name.clone(),
                    error: NpyError::Truncated {
                        declared: self.declared,
                        complete: self.done + (got / width) as u64,
                        offset: c.data_start + self.done * width as u64 + got as u64,
                    },
                });
            }
        }
        // Every field of every event is written below: only a change of length is filled in.
        self.events.resize(n, Event::default());
        let [t, x, y, p] = &self.columns;
        let events = &mut self.events[..];
        let mut ok = fill(&t.buf, t.scalar, events, |e, v| {
            e.t = v;
            true
        });
        ok &= fill(&x.buf, x.scalar, events, |e, v| {
            e.x = v as u16;
            (0..=i64::from(u16::MAX)).contains(&v)
        });
        ok &= fill(&y.buf, y.scalar, events, |e, v| {
            e.y = v as u16;
            (0..=i64::from(u16::MAX)).contains(&v)
        });
        ok &= fill(&p.buf, p.scalar, events, |e, v| {
            e.polarity = v == 1;
            matches!(v, -1..=1)
        });
        if !ok {
            return Err(self.locate(n));
        }
        self.done += n as u64;
        self.check.check(&self.events).map_err(NpzError::Event)?;
        Ok(Some(&self.events))
    }

    /// The error for the first bad value of the chunk of `n` events just read, in the order a
    /// whole-column read met them: element by element, `t, x, y, p`.
    fn locate(&self, n: usize) -> NpzError {
        for i in 0..n {
            let index = self.done + i as u64;
            let mut values = [None; 4];
            for (k, c) in self.columns.iter().enumerate() {
                let width = c.scalar.width;
                values[k] = c.scalar.load(&c.buf[i * width..]);
                if values[k].is_none() {
                    return NpzError::Member {
                        member: self.names[k].clone(),
                        error: NpyError::BadRecord {
                            index,
                            offset: c.data_start + index * width as u64,
                            reason: "the value is larger than 2^63 - 1".into(),
                        },
                    };
                }
            }
            let bad = |k: usize, reason| NpzError::BadValue {
                member: self.names[k].clone(),
                index: index as usize,
                reason,
            };
            if let Err(reason) = coordinates(values[1], values[2]) {
                return bad(1, reason);
            }
            if let Err(reason) = polarity(values[3]) {
                return bad(3, reason);
            }
        }
        // Only called when a value failed, so the loop returned; a truthful answer all the same.
        NpzError::BadValue {
            member: self.names[0].clone(),
            index: self.done as usize,
            reason: "a value of this chunk is out of range".into(),
        }
    }
}

/// Loads the values of `bytes` (of type `scalar`) into `events` through `set`, which stores
/// one and says whether it is in range; whether every value was (an unsigned 8-byte value
/// above `i64::MAX` is not).
fn fill(
    bytes: &[u8],
    scalar: Scalar,
    events: &mut [Event],
    set: impl Fn(&mut Event, i64) -> bool,
) -> bool {
    match (scalar.width, scalar.signed) {
        (1, false) => fill_as::<1, false>(bytes, events, set),
        (1, true) => fill_as::<1, true>(bytes, events, set),
        (2, false) => fill_as::<2, false>(bytes, events, set),
        (2, true) => fill_as::<2, true>(bytes, events, set),
        (4, false) => fill_as::<4, false>(bytes, events, set),
        (4, true) => fill_as::<4, true>(bytes, events, set),
        (8, false) => fill_as::<8, false>(bytes, events, set),
        _ => fill_as::<8, true>(bytes, events, set),
    }
}

/// [`fill`] for values of `W` bytes, signed or not: one fixed-width load per value.
#[inline(always)]
fn fill_as<const W: usize, const SIGNED: bool>(
    bytes: &[u8],
    events: &mut [Event],
    set: impl Fn(&mut Event, i64) -> bool,
) -> bool {
    let mut ok = true;
    for (e, b) in events.iter_mut().zip(bytes.chunks_exact(W)) {
        let mut raw = [0u8; 8];
        raw[..W].copy_from_slice(b);
        let raw = u64::from_le_bytes(raw);
        let v = if SIGNED {
            let shift = 64 - 8 * W as u32;
            ((raw << shift) as i64) >> shift
        } else {
            ok &= raw <= i64::MAX as u64;
            raw as i64
        };
        ok &= set(e, v);
    }
    ok
}
