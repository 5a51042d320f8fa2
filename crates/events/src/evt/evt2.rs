//! EVT 2.0 word decoder, with the time-high loop handling of Prophesee's `EVT2Decoder`
//! (openeb `hal/cpp/include/metavision/hal/decoders/evt2/evt2_decoder.h`), without time shifting.
//!
//! Each little-endian 32-bit word has its type in bits 28..31:
//! `0x0`/`0x1` CD OFF/ON (`ts` 6 bits at 22, `x` 11 bits at 11, `y` 11 bits at 0),
//! `0x8` TIME_HIGH (the upper 28 bits of the timestamp), `0xA` EXT_TRIGGER (`value` bit 0,
//! `id` bits 8..12, `ts` at 22). Other types carry nothing evtac uses.

use crate::{Event, Trigger};

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
    clock: TimeHigh,
}

impl Evt2Decoder {
    /// Decodes whole words from `bytes` (a multiple of 4 bytes long), appending to the outputs.
    pub(crate) fn decode(
        &mut self,
        bytes: &[u8],
        events: &mut Vec<Event>,
        triggers: &mut Vec<Trigger>,
    ) {
        let mut words = bytes.chunks_exact(4);
        if !self.clock.set {
            for w in words.by_ref() {
                let word = u32::from_le_bytes([w[0], w[1], w[2], w[3]]);
                if word >> 28 == 0x8 {
                    self.clock.advance(word);
                    break;
                }
            }
        }
        events.reserve(bytes.len() / 4);
        for w in words {
            let word = u32::from_le_bytes([w[0], w[1], w[2], w[3]]);
            let ts = i64::from((word >> 22) & 0x3F);
            match word >> 28 {
                kind @ (0x0 | 0x1) => events.push(Event {
                    t: self.clock.base + ts,
                    x: ((word >> 11) & 0x7FF) as u16,
                    y: (word & 0x7FF) as u16,
                    polarity: kind == 1,
                }),
                0x8 => self.clock.advance(word),
                0xA => triggers.push(trigger(self.clock.base + ts, u64::from(word))),
                _ => {}
            }
        }
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
        Evt2Decoder::default().decode(&bytes, &mut events, &mut triggers);
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
    fn time_high_wrap_continues_the_clock() {
        let bytes = words(&[0x8FFF_FFFF, 1 << 22, 0x8000_0000, 1 << 22]);
        let (mut events, mut triggers) = (Vec::new(), Vec::new());
        Evt2Decoder::default().decode(&bytes, &mut events, &mut triggers);
        assert_eq!(events[0].t, MAX_TIMESTAMP + 1);
        assert_eq!(events[1].t, TIME_LOOP + 1);
    }
}
