//! EVT 2.1 word decoder, following Prophesee's EVT 2.1 format description (Metavision docs,
//! "EVT 2.1 Format") and the time-high handling of its EVT 2.0 decoder, without time shifting.
//!
//! Each little-endian 64-bit word has its type in bits 60..63:
//! `0x0`/`0x1` CD OFF/ON, vectorised: `ts` 6 bits at 54, `x` 11 bits at 43 (the base of 32
//! aligned columns), `y` 11 bits at 32, and a 32-bit validity mask in bits 0..31 whose bit `i`
//! means an event at column `x + i`; `0x8` EVT_TIME_HIGH (the upper 28 bits of the timestamp, at
//! 32); `0xA` EXT_TRIGGER (`value` bit 32, `id` bits 40..44, `ts` at 54); `0xE` OTHERS and `0xF`
//! CONTINUED carry nothing evtac uses. The 34-bit clock wraps like EVT 2.0's, and is unwrapped
//! the same way.

use super::evt2::{TimeHigh, trigger};
use crate::{Event, Trigger};

/// Decoder state carried from word to word (and across reads).
#[derive(Debug, Clone, Default)]
pub(crate) struct Evt21Decoder {
    clock: TimeHigh,
}

impl Evt21Decoder {
    /// Decodes whole words from `bytes` (a multiple of 8 bytes long), appending to the outputs.
    pub(crate) fn decode(
        &mut self,
        bytes: &[u8],
        events: &mut Vec<Event>,
        triggers: &mut Vec<Trigger>,
    ) {
        let mut words = bytes
            .chunks_exact(8)
            .map(|w| u64::from_le_bytes([w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7]]));
        if !self.clock.set {
            for word in words.by_ref() {
                if word >> 60 == 0x8 {
                    self.clock.advance((word >> 32) as u32);
                    break;
                }
            }
        }
        for word in words {
            let ts = ((word >> 54) & 0x3F) as i64;
            match word >> 60 {
                kind @ (0x0 | 0x1) => {
                    let t = self.clock.base + ts;
                    // 11 bits each: fit in u16, and x + 31 too.
                    let x = ((word >> 43) & 0x7FF) as u16;
                    let y = ((word >> 32) & 0x7FF) as u16;
                    let mut mask = word as u32;
                    while mask != 0 {
                        let bit = mask.trailing_zeros() as u16;
                        mask &= mask - 1;
                        events.push(Event {
                            t,
                            x: x + bit,
                            y,
                            polarity: kind == 1,
                        });
                    }
                }
                0x8 => self.clock.advance((word >> 32) as u32),
                0xA => triggers.push(trigger(self.clock.base + ts, word >> 32)),
                _ => {}
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evt::evt2::TRIGGER_RISING;

    fn words(ws: &[u64]) -> Vec<u8> {
        ws.iter().flat_map(|w| w.to_le_bytes()).collect()
    }

    fn cd(kind: u64, ts: u64, x: u64, y: u64, mask: u32) -> u64 {
        kind << 60 | ts << 54 | x << 43 | y << 32 | u64::from(mask)
    }

    #[test]
    fn decodes_vectors_after_time_high_and_skips_before() {
        let bytes = words(&[
            cd(1, 0, 0, 0, 1),   // before any time high: skipped
            0x8 << 60 | 2 << 32, // time high 2 -> 128 us
            cd(1, 5, 32, 7, 0b1001),
            cd(0, 63, 2016, 479, 1 << 31),
            0xA << 60 | 3 << 54 | 1 << 32,
        ]);
        let (mut events, mut triggers) = (Vec::new(), Vec::new());
        Evt21Decoder::default().decode(&bytes, &mut events, &mut triggers);
        let e = |t, x, y, polarity| Event { t, x, y, polarity };
        assert_eq!(
            events,
            vec![
                e(133, 32, 7, true),
                e(133, 35, 7, true),
                e(191, 2047, 479, false)
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
}
