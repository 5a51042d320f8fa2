//! One pass over the four columns' stored bytes for the layouts labs have: each event built and
//! written whole, its values checked and the event check's summary gathered in the same loop.
//!
//! Decoding one column at a time wrote each 16-byte event four times, in four passes over the
//! slice, and the event check read it a fifth time; a profile of the DSEC layout put those
//! passes at half the read. Here a kernel is compiled for each combination of the stored types
//! that the two layouts and their variants use (times as `u32`, `i32`, `i64`, `u64`
//! microseconds or `f32`/`f64` seconds; coordinates both `u16` or both `i16`; polarity `u8` or
//! `i8`, h5py's bool), little-endian. Any other combination (big-endian files, 32-bit
//! coordinates) goes through the column-at-a-time path in `column.rs`, which is also the one
//! that names a bad value: a kernel only says whether every value was valid.

use super::column::Kind;
use crate::check::ChunkSummary;
use crate::{Event, Resolution};

/// A stored type: its width and how an element becomes an `i64` (and whether it can).
trait Lane {
    /// Bytes per element.
    const WIDTH: usize;
    /// The element stored in `bytes` (exactly `WIDTH` of them), and whether it is a value of
    /// the field at all.
    fn get(bytes: &[u8]) -> (i64, bool);
}

/// A lane for elements stored as `$t` (`$n` bytes): `|$v| $body` turns the element into the
/// field's value and whether it is one.
macro_rules! lane {
    ($lane:ident, $t:ty, $n:literal, |$v:ident| $body:expr) => {
        struct $lane;
        impl Lane for $lane {
            const WIDTH: usize = $n;
            #[inline(always)]
            fn get(bytes: &[u8]) -> (i64, bool) {
                let $v = <$t>::from_le_bytes(bytes.try_into().unwrap_or_default());
                $body
            }
        }
    };
}
lane!(I8, i8, 1, |v| (i64::from(v), true));
lane!(U8, u8, 1, |v| (i64::from(v), true));
lane!(I16, i16, 2, |v| (i64::from(v), true));
lane!(U16, u16, 2, |v| (i64::from(v), true));
lane!(I32, i32, 4, |v| (i64::from(v), true));
lane!(U32, u32, 4, |v| (i64::from(v), true));
lane!(I64, i64, 8, |v| (v, true));
// Above `i64::MAX` is no time.
lane!(U64, u64, 8, |v| (v as i64, v <= i64::MAX as u64));
lane!(F32, f32, 4, |v| microseconds(f64::from(v)));
lane!(F64, f64, 8, |v| microseconds(v));

/// Float seconds to microseconds, rounded half away from zero, and whether they fit an `i64`:
/// the one conversion of float times, for the kernels and for `Column::times`.
#[inline(always)]
pub(super) fn microseconds(s: f64) -> (i64, bool) {
    let us = s * 1e6;
    // i64::MAX as f64 rounds up to 2^63, so `<` (less one) keeps the cast in range.
    let fits = us.is_finite() & (us > i64::MIN as f64) & (us < i64::MAX as f64 - 1.0);
    // Rounded by a truncating cast of the value moved half a unit away from zero:
    // `f64::round` is a library call here, a fifth of the read's time.
    ((us + 0.5f64.copysign(us)) as i64, fits)
}

/// What a kernel found: whether every value was a valid field value, and, when so, the summary
/// the event check needs.
#[derive(Debug, Clone, Copy)]
pub(super) struct Decoded {
    /// Whether every value was valid; when not, the events are to be decoded again by the
    /// checked path, which names the first bad one.
    pub(super) valid: bool,
    /// The event check's summary of the events (meaningful when `valid`).
    pub(super) summary: ChunkSummary,
}

/// Decodes the events whose fields' stored bytes are `raw` (`[t, x, y, p]`, the same number of
/// elements each) into `out` (its length set to theirs), adding `t_offset` to every time; `None` when no
/// kernel is compiled for `kinds` (little-endian `[t, x, y, p]`).
pub(super) fn decode(
    kinds: [Kind; 4],
    raw: [&[u8]; 4],
    t_offset: i64,
    resolution: Option<Resolution>,
    out: &mut Vec<Event>,
) -> Option<Decoded> {
    use Kind::{Int, Seconds};
    let [t, x, y, p] = kinds;
    if x != y {
        return None;
    }
    macro_rules! with_xy_p {
        ($t:ty) => {
            match (x, p) {
                (
                    Int {
                        width: 2,
                        signed: false,
                    },
                    Int {
                        width: 1,
                        signed: false,
                    },
                ) => kernel::<$t, U16, U8>(raw, t_offset, resolution, out),
                (
                    Int {
                        width: 2,
                        signed: false,
                    },
                    Int {
                        width: 1,
                        signed: true,
                    },
                ) => kernel::<$t, U16, I8>(raw, t_offset, resolution, out),
                (
                    Int {
                        width: 2,
                        signed: true,
                    },
                    Int {
                        width: 1,
                        signed: false,
                    },
                ) => kernel::<$t, I16, U8>(raw, t_offset, resolution, out),
                (
                    Int {
                        width: 2,
                        signed: true,
                    },
                    Int {
                        width: 1,
                        signed: true,
                    },
                ) => kernel::<$t, I16, I8>(raw, t_offset, resolution, out),
                _ => return None,
            }
        };
    }
    Some(match t {
        Int {
            width: 4,
            signed: false,
        } => with_xy_p!(U32),
        Int {
            width: 4,
            signed: true,
        } => with_xy_p!(I32),
        Int {
            width: 8,
            signed: true,
        } => with_xy_p!(I64),
        Int {
            width: 8,
            signed: false,
        } => with_xy_p!(U64),
        Seconds { width: 8 } => with_xy_p!(F64),
        Seconds { width: 4 } => with_xy_p!(F32),
        _ => return None,
    })
}

/// The kernel for times stored as `T`, both coordinates as `XY` and polarities as `P`.
fn kernel<T: Lane, XY: Lane, P: Lane>(
    [t, x, y, p]: [&[u8]; 4],
    t_offset: i64,
    resolution: Option<Resolution>,
    out: &mut Vec<Event>,
) -> Decoded {
    let n = t.len() / T::WIDTH;
    // Every event is overwritten below: only a change of length touches the buffer here
    // (`resize` both grows and shortens).
    out.resize(n, Event::default());
    // Locals rather than state captured by a closure, so they live in registers; no early exit
    // and no branch on the values (flags are and-ed), so the loop is a straight run of loads,
    // conversions and one 16-byte store per event.
    let mut valid = true;
    let (mut max_x, mut max_y) = (0i64, 0i64);
    let mut ordered = true;
    let mut previous = i64::MIN;
    let rows = out
        .iter_mut()
        .zip(t.chunks_exact(T::WIDTH))
        .zip(x.chunks_exact(XY::WIDTH))
        .zip(y.chunks_exact(XY::WIDTH))
        .zip(p.chunks_exact(P::WIDTH));
    for ((((e, t), x), y), p) in rows {
        let (t, t_ok) = T::get(t);
        let (t, overflow) = t.overflowing_add(t_offset);
        let (x, _) = XY::get(x);
        let (y, _) = XY::get(y);
        let (p, _) = P::get(p);
        valid &= t_ok & !overflow & (0..=0xFFFF).contains(&x) & (0..=0xFFFF).contains(&y);
        valid &= (-1..=1).contains(&p);
        max_x = max_x.max(x);
        max_y = max_y.max(y);
        ordered &= t >= previous;
        previous = t;
        *e = Event {
            t,
            x: x as u16,
            y: y as u16,
            polarity: p == 1,
        };
    }
    Decoded {
        valid,
        summary: ChunkSummary {
            in_bounds: resolution
                .is_none_or(|r| max_x < i64::from(r.width) && max_y < i64::from(r.height)),
            ordered,
        },
    }
}

#[cfg(test)]
mod tests {
    //! The kernels against a decoding written element by element from the stored bytes, for
    //! every compiled combination of types, on values inside and outside each field's range.
    use super::*;
    use proptest::prelude::*;

    /// The stored types of the kernels: `(kind, element width)`.
    const TIMES: [Kind; 6] = [
        Kind::Int {
            width: 4,
            signed: false,
        },
        Kind::Int {
            width: 4,
            signed: true,
        },
        Kind::Int {
            width: 8,
            signed: true,
        },
        Kind::Int {
            width: 8,
            signed: false,
        },
        Kind::Seconds { width: 8 },
        Kind::Seconds { width: 4 },
    ];
    const COORDS: [Kind; 2] = [
        Kind::Int {
            width: 2,
            signed: false,
        },
        Kind::Int {
            width: 2,
            signed: true,
        },
    ];
    const POLARITIES: [Kind; 2] = [
        Kind::Int {
            width: 1,
            signed: false,
        },
        Kind::Int {
            width: 1,
            signed: true,
        },
    ];

    fn width(kind: Kind) -> usize {
        match kind {
            Kind::Int { width, .. } | Kind::Seconds { width } => width,
        }
    }

    /// Element `bytes` of `kind`, the plain way: `None` when it is no value of an event field.
    fn value(kind: Kind, bytes: &[u8]) -> Option<i64> {
        let b = |n: usize| -> [u8; 8] {
            let mut a = [0; 8];
            a[..n].copy_from_slice(bytes);
            a
        };
        match kind {
            Kind::Int {
                width: 1,
                signed: true,
            } => Some(i64::from(bytes[0] as i8)),
            Kind::Int { width: 1, .. } => Some(i64::from(bytes[0])),
            Kind::Int {
                width: 2,
                signed: true,
            } => Some(i64::from(i16::from_le_bytes([bytes[0], bytes[1]]))),
            Kind::Int { width: 2, .. } => Some(i64::from(u16::from_le_bytes([bytes[0], bytes[1]]))),
            Kind::Int {
                width: 4,
                signed: true,
            } => Some(i64::from(i32::from_le_bytes(bytes.try_into().ok()?))),
            Kind::Int { width: 4, .. } => {
                Some(i64::from(u32::from_le_bytes(bytes.try_into().ok()?)))
            }
            Kind::Int {
                width: 8,
                signed: true,
            } => Some(i64::from_le_bytes(b(8))),
            Kind::Int { .. } => i64::try_from(u64::from_le_bytes(b(8))).ok(),
            Kind::Seconds { width } => {
                let s = if width == 4 {
                    f64::from(f32::from_le_bytes(bytes.try_into().ok()?))
                } else {
                    f64::from_le_bytes(b(8))
                };
                // The checked path's rounding (`Column::times`: half away from zero by a
                // truncating cast) and range (inside (-2^63, 2^63)).
                let us = s * 1e6;
                let fits = us.is_finite() && us > -(2f64.powi(63)) && us < 2f64.powi(63);
                fits.then(|| (us + 0.5f64.copysign(us)) as i64)
            }
        }
    }

    /// Raw bytes for `n` elements of `kind`: mostly plausible values, sometimes anything.
    fn column(kind: Kind, n: usize, field: usize) -> impl Strategy<Value = Vec<u8>> {
        let w = width(kind);
        proptest::collection::vec(
            prop_oneof![
                4 => (0u64..2000).prop_map(move |v| {
                    let v = match (field, kind) {
                        (0, Kind::Seconds { width: 8 }) => (v as f64 * 1e-6).to_bits(),
                        (0, Kind::Seconds { .. }) => u64::from((v as f32 * 1e-6).to_bits()),
                        (3, _) => v % 2,
                        _ => v,
                    };
                    v.to_le_bytes()[..w].to_vec()
                }),
                1 => proptest::collection::vec(any::<u8>(), w),
            ],
            n,
        )
        .prop_map(|elements| elements.concat())
    }

    /// The stored types, their bytes, `t_offset` and a sensor size.
    type Case = ([Kind; 4], [Vec<u8>; 4], i64, Option<(u16, u16)>);

    fn case() -> impl Strategy<Value = Case> {
        (
            0..TIMES.len(),
            0..COORDS.len(),
            0..POLARITIES.len(),
            0usize..200,
        )
            .prop_flat_map(|(t, xy, p, n)| {
                let kinds = [TIMES[t], COORDS[xy], COORDS[xy], POLARITIES[p]];
                (
                    Just(kinds),
                    [
                        column(kinds[0], n, 0),
                        column(kinds[1], n, 1),
                        column(kinds[2], n, 2),
                        column(kinds[3], n, 3),
                    ],
                    prop_oneof![Just(0i64), any::<i64>(), -5_000i64..5_000],
                    proptest::option::of((1u16..2100, 1u16..2100)),
                )
            })
    }

    proptest! {
        #[test]
        fn kernels_decode_as_element_by_element(
            (kinds, raw, t_offset, size) in case()
        ) {
            let resolution = size.map(|(w, h)| Resolution::new(w, h));
            let mut out = vec![Event::default(); 7];
            let got = decode(kinds, raw.each_ref().map(Vec::as_slice), t_offset, resolution, &mut out)
                .expect("a kernel for every combination listed");
            let n = raw[0].len() / width(kinds[0]);
            let mut want = Vec::new();
            let mut valid = true;
            for i in 0..n {
                let at = |c: usize| value(kinds[c], &raw[c][i * width(kinds[c])..][..width(kinds[c])]);
                let t = at(0).and_then(|t| t.checked_add(t_offset));
                let (x, y, p) = (at(1), at(2), at(3));
                let pixel = |v: Option<i64>| v.and_then(|v| u16::try_from(v).ok());
                match (t, pixel(x), pixel(y), p) {
                    (Some(t), Some(x), Some(y), Some(p @ -1..=1)) => {
                        want.push(Event { t, x, y, polarity: p == 1 });
                    }
                    _ => valid = false,
                }
            }
            prop_assert_eq!(got.valid, valid);
            if valid {
                prop_assert_eq!(&out, &want);
                let in_bounds = resolution
                    .is_none_or(|r| want.iter().all(|e| e.x < r.width && e.y < r.height));
                let ordered = want.windows(2).all(|w| w[1].t >= w[0].t);
                prop_assert_eq!(got.summary.in_bounds, in_bounds);
                prop_assert_eq!(got.summary.ordered, ordered);
            }
        }
    }

    #[test]
    fn other_combinations_have_no_kernel() {
        let int = |width, signed| Kind::Int { width, signed };
        let (i32k, u16k, i16k, u8k) = (int(4, true), int(2, false), int(2, true), int(1, false));
        let mut out = Vec::new();
        let none = |kinds| decode(kinds, [&[][..]; 4], 0, None, &mut Vec::new()).is_none();
        // 32-bit coordinates, mixed coordinate types, a 16-bit polarity, 16-bit times.
        assert!(none([i32k, i32k, i32k, u8k]));
        assert!(none([i32k, u16k, i16k, u8k]));
        assert!(none([i32k, u16k, u16k, u16k]));
        assert!(none([u16k, u16k, u16k, u8k]));
        assert!(decode([i32k, u16k, u16k, u8k], [&[][..]; 4], 0, None, &mut out).is_some());
    }
}
