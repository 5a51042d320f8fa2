//! EVT 2.0 word decoder, with the time-high loop handling of Prophesee's `EVT2Decoder`
//! (openeb `hal/cpp/include/metavision/hal/decoders/evt2/evt2_decoder.h`), without time shifting.
//!
//! Each little-endian 32-bit word has its type in bits 28..31:
//! `0x0`/`0x1` CD OFF/ON (`ts` 6 bits at 22, `x` 11 bits at 11, `y` 11 bits at 0),
//! `0x8` TIME_HIGH (the upper 28 bits of the timestamp), `0xA` EXT_TRIGGER (`value` bit 0,
//! `id` bits 8..12, `ts` at 22). Other types carry nothing evtac uses.

use crate::check::ChunkSummary;
use crate::{Event, Resolution, Trigger};

/// Bits of the timestamp carried by CD and trigger words.
const LSB_BITS: u32 = 6;
/// Largest time-high value, in us.
const MAX_TIMESTAMP: i64 = ((1 << 28) - 1) << LSB_BITS;
/// How far back a time high must jump to count as the 34-bit counter wrapping around.
const LOOP_THRESHOLD: i64 = 10_000;
/// Duration of one wrap of the 34-bit counter, in us.
const TIME_LOOP: i64 = MAX_TIMESTAMP + (1 << LSB_BITS);

/// AEDAT4 trigger codes used for Prophesee external triggers (dv `TriggerType`).
pub(crate) const TRIGGER_RISING: i8 = 1;
/// See [`TRIGGER_RISING`].
pub(crate) const TRIGGER_FALLING: i8 = 2;

/// An external trigger at `t`: a rising edge when `value` is 1, else a falling one.
#[inline]
pub(crate) fn trigger(t: i64, value: u64) -> Trigger {
    Trigger {
        t,
        kind: if value & 1 == 1 {
            TRIGGER_RISING
        } else {
            TRIGGER_FALLING
        },
    }
}

/// The EVT 2.x clock: the time high of the last TIME_HIGH word, with the wraps of the 34-bit
/// counter added (shared by EVT 2.0 and EVT 2.1, which encode time alike).
#[derive(Debug, Clone, Default)]
pub(crate) struct TimeHigh {
    /// Whether a TIME_HIGH has been seen; words before the first one are skipped, as Prophesee
    /// does, because their time is unknown.
    pub(crate) set: bool,
    /// Current time high in us, wraps included.
    pub(crate) base: i64,
    /// Accumulated wraps of the counter, in us.
    loop_shift: i64,
}

impl TimeHigh {
    /// Takes the 28-bit payload of a TIME_HIGH word.
    #[inline]
    pub(crate) fn advance(&mut self, payload: u32) {
        let mut high = (i64::from(payload & 0x0FFF_FFFF) << LSB_BITS) + self.loop_shift;
        if !self.set {
            self.set = true;
        } else if high < self.base && self.base - high >= MAX_TIMESTAMP - LOOP_THRESHOLD {
            self.loop_shift += TIME_LOOP;
            high += TIME_LOOP;
        }
        self.base = high;
    }
}

/// Decoder state carried from word to word (and across reads).
#[derive(Debug, Clone, Default)]
pub(crate) struct Evt2Decoder {
    /// Whether a TIME_HIGH has been seen; words before the first one are skipped, as Prophesee
    /// does, because their time is unknown.
    base_time_set: bool,
    /// Current time high in us, wraps included.
    base_time: i64,
    /// Accumulated wraps of the counter, in us.
    loop_shift: i64,
}

impl Evt2Decoder {
    /// Decodes whole words from `bytes` (a multiple of 4 bytes long), appending to the outputs;
    /// returns what [`EventCheck`](crate::check::EventCheck) needs to validate the events
    /// appended against `resolution`, gathered on the way so that they need no second pass.
    ///
    /// Nearly every word of a recording is a CD event, so the loop writes an event for every
    /// word into the spare capacity and keeps it (advances the count) only for CD words; the
    /// other types go through a separate, rarely taken branch. That avoids `push`'s capacity
    /// check and length update per event, and with the fused check halves the decoding time.
    pub(crate) fn decode(
        &mut self,
        bytes: &[u8],
        events: &mut Vec<Event>,
        triggers: &mut Vec<Trigger>,
        resolution: Option<Resolution>,
    ) -> ChunkSummary {
        let (mut words, _) = bytes.as_chunks::<4>();
        if !self.base_time_set {
            let Some(i) = words
                .iter()
                .position(|w| u32::from_le_bytes(*w) >> 28 == 0x8)
            else {
                return ChunkSummary::EMPTY;
            };
            self.base_time = i64::from(u32::from_le_bytes(words[i]) & 0x0FFF_FFFF) << LSB_BITS;
            self.base_time_set = true;
            words = &words[i + 1..];
        }
        let start = events.len();
        events.reserve(words.len());
        let spare = &mut events.spare_capacity_mut()[..words.len()];
        let mut kept = 0;
        // The time high and the summary live in registers for the loop. An event is inside
        // when `x - width` and `y - height` are both negative: their sign bits, and-ed over the
        // chunk, are one register (a running maximum of x and y took two, and spilled).
        let (width, height) = resolution.map_or((1 << 16, 1 << 16), |r| {
            (i32::from(r.width), i32::from(r.height))
        });
        let mut base = self.base_time;
        let mut inside = -1i32;
        let mut ordered = true;
        let mut last = i64::MIN;
        for w in words {
            let word = u32::from_le_bytes(*w);
            let kind = word >> 28;
            let t = base + i64::from((word >> 22) & 0x3F);
            let x = ((word >> 11) & 0x7FF) as u16;
            let y = (word & 0x7FF) as u16;
            // `kept` <= the words seen so far < `words.len()`: always inside `spare`.
            spare[kept].write(Event {
                t,
                x,
                y,
                polarity: kind == 1,
            });
            if kind < 2 {
                ordered &= t >= last;
                last = t;
                inside &= (i32::from(x) - width) & (i32::from(y) - height);
                kept += 1;
            } else if kind == 0x8 {
                base = self.time_high(word, base);
            } else if kind == 0xA {
                triggers.push(trigger(t, u64::from(word)));
            }
        }
        self.base_time = base;
        // SAFETY: `spare[..kept]` was initialised above (each `kept += 1` follows the write of
        // `spare[kept]`), and `reserve` made room for `words.len() >= kept` events after `start`.
        unsafe { events.set_len(start + kept) };
        ChunkSummary {
            in_bounds: inside < 0,
            ordered,
        }
    }

    /// The new time high (us, wraps included) after a TIME_HIGH word, `base` being the current
    /// one: a jump far back is the 34-bit counter wrapping around.
    #[inline(always)]
    fn time_high(&mut self, word: u32, base: i64) -> i64 {
        let high = (i64::from(word & 0x0FFF_FFFF) << LSB_BITS) + self.loop_shift;
        if high < base && base - high >= MAX_TIMESTAMP - LOOP_THRESHOLD {
            self.loop_shift += TIME_LOOP;
            return high + TIME_LOOP;
        }
        high
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(ws: &[u32]) -> Vec<u8> {
        ws.iter().flat_map(|w| w.to_le_bytes()).collect()
    }

    #[test]
    fn decodes_cd_after_time_high_and_skips_before() {
        let cd = |kind: u32, ts: u32, x: u32, y: u32| kind << 28 | ts << 22 | x << 11 | y;
        let bytes = words(&[
            cd(1, 0, 1, 1), // before any time high: skipped
            0x8000_0002,    // time high 2 -> 128 us
            cd(1, 5, 639, 479),
            cd(0, 63, 0, 0),
            0xA000_0001 | 3 << 22,
        ]);
        let (mut events, mut triggers) = (Vec::new(), Vec::new());
        Evt2Decoder::default().decode(&bytes, &mut events, &mut triggers, None);
        assert_eq!(
            events,
            vec![
                Event {
                    t: 133,
                    x: 639,
                    y: 479,
                    polarity: true
                },
                Event {
                    t: 191,
                    x: 0,
                    y: 0,
                    polarity: false
                },
            ]
        );
        assert_eq!(
            triggers,
            vec![Trigger {
                t: 131,
                kind: TRIGGER_RISING
            }]
        );
    }

    #[test]
    fn the_summary_sees_the_last_pixel_inside_and_the_first_outside() {
        let cd = |ts: u32, x: u32, y: u32| ts << 22 | x << 11 | y;
        let summary = |ws: &[u32], resolution| {
            let (mut events, mut triggers) = (Vec::new(), Vec::new());
            Evt2Decoder::default().decode(&words(ws), &mut events, &mut triggers, resolution)
        };
        let r = Some(Resolution::new(640, 480));
        let inside = summary(&[0x8000_0001, cd(0, 639, 479), cd(1, 0, 0)], r);
        assert_eq!(inside, ChunkSummary::EMPTY);
        for (x, y) in [(640, 0), (0, 480), (2047, 2047)] {
            let outside = summary(&[0x8000_0001, cd(0, 1, 1), cd(1, x, y)], r);
            assert!(!outside.in_bounds && outside.ordered, "({x}, {y})");
            assert!(summary(&[0x8000_0001, cd(1, x, y)], None).in_bounds);
        }
        let back = summary(&[0x8000_0001, cd(5, 1, 1), cd(4, 1, 1)], r);
        assert!(back.in_bounds && !back.ordered);
        // A time high going back, not far enough to be a wrap.
        let back = summary(&[0x8000_0002, cd(0, 1, 1), 0x8000_0001, cd(63, 1, 1)], r);
        assert!(!back.ordered);
    }

    #[test]
    fn time_high_wrap_continues_the_clock() {
        let bytes = words(&[0x8FFF_FFFF, 1 << 22, 0x8000_0000, 1 << 22]);
        let (mut events, mut triggers) = (Vec::new(), Vec::new());
        Evt2Decoder::default().decode(&bytes, &mut events, &mut triggers, None);
        assert_eq!(events[0].t, MAX_TIMESTAMP + 1);
        assert_eq!(events[1].t, TIME_LOOP + 1);
    }
}
