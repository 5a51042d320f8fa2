//! EVT 3.0 word decoder, following Prophesee's `EVT3Decoder` (openeb
//! `hal/cpp/include/metavision/hal/decoders/evt3/evt3_decoder.h`) without time shifting.
//!
//! Each little-endian 16-bit word has its type in bits 12..15 and updates a small state:
//! `0x0` EVT_ADDR_Y (row, CD), `0x1` EM ADDR_Y (row of a non-CD event: following X words emit
//! nothing), `0x2` EVT_ADDR_X (emits one event: x in bits 0..10, polarity bit 11),
//! `0x3` VECT_BASE_X (x and polarity for the next vectors), `0x4` VECT_12 / `0x5` VECT_8 (a
//! bitmask of 12 / 8 consecutive pixels from the base x, which then advances by 12 / 8),
//! `0x6` EVT_TIME_LOW (bits 0..11 of time), `0x8` EVT_TIME_HIGH (bits 12..23 of time),
//! `0xA` EXT_TRIGGER. The 24-bit time wraps every 16.78 s: a time high more than 2048 steps
//! below the previous one counts as a wrap, exactly as Prophesee's decoder does.

use super::evt2::{TRIGGER_FALLING, TRIGGER_RISING};
use crate::{Event, Trigger};

/// Polarity bit of EVT_ADDR_X and VECT_BASE_X.
const POLARITY: u32 = 1 << 11;
/// Prophesee keeps the vector base in a wider register and masks only the polarity bit out.
const NOT_POLARITY: u32 = 0xF7FF;
/// A time high this far below the previous one means the 24-bit counter wrapped.
const WRAP_THRESHOLD: u32 = 1 << 11;

/// Decoder state carried from word to word (and across reads).
#[derive(Debug, Clone, Default)]
pub(crate) struct Evt3Decoder {
    /// Whether a TIME_HIGH has been seen; words before the first one are skipped, as Prophesee
    /// does, because their time is unknown.
    base_time_set: bool,
    /// Current row (the 12-bit EVT_ADDR_Y content).
    y: u16,
    /// Whether the current row belongs to CD events.
    is_cd: bool,
    /// VECT_BASE_X register: x in bits 0..10, polarity in bit 11, advanced by each vector.
    base_x: u32,
    /// Time low (bits 0..11).
    low: u32,
    /// Time high (bits 12..23).
    high: u32,
    /// Wraps of the 24-bit counter.
    loops: i64,
    /// The assembled timestamp in us.
    t: i64,
}

impl Evt3Decoder {
    fn update_time(&mut self) {
        self.t = (self.loops << 24) | i64::from(self.high << 12) | i64::from(self.low);
    }

    /// Appends one event per set bit of `mask` (`width` bits) from the vector base.
    #[inline]
    fn vector(&mut self, mut mask: u32, width: u32, events: &mut Vec<Event>) {
        if self.is_cd {
            let base = self.base_x & NOT_POLARITY;
            let polarity = self.base_x & POLARITY != 0;
            while mask != 0 {
                let bit = mask.trailing_zeros();
                mask &= mask - 1;
                events.push(Event {
                    t: self.t,
                    // At most 0xF7FF + 11: fits in u16.
                    x: (base + bit) as u16,
                    y: self.y,
                    polarity,
                });
            }
        }
        self.base_x = self.base_x.wrapping_add(width);
    }

    /// Decodes whole words from `bytes` (an even number of bytes), appending to the outputs.
    pub(crate) fn decode(
        &mut self,
        bytes: &[u8],
        events: &mut Vec<Event>,
        triggers: &mut Vec<Trigger>,
    ) {
        let mut words = bytes.chunks_exact(2);
        if !self.base_time_set {
            for w in words.by_ref() {
                let word = u16::from_le_bytes([w[0], w[1]]);
                if word >> 12 == 0x8 {
                    // Prophesee starts one step below the first time high, so that the time high
                    // itself counts as a change (and resets the time low).
                    self.high = u32::from(word & 0xFFF).saturating_sub(1);
                    self.base_time_set = true;
                    self.apply(word, events, triggers);
                    break;
                }
            }
        }
        for w in words {
            self.apply(u16::from_le_bytes([w[0], w[1]]), events, triggers);
        }
    }

    #[inline(always)]
    fn apply(&mut self, word: u16, events: &mut Vec<Event>, triggers: &mut Vec<Trigger>) {
        let content = u32::from(word & 0xFFF);
        match word >> 12 {
            0x0 => {
                self.y = content as u16;
                self.is_cd = true;
            }
            0x1 => self.is_cd = false,
            0x2 if self.is_cd => events.push(Event {
                t: self.t,
                x: (content & 0x7FF) as u16,
                y: self.y,
                polarity: content & POLARITY != 0,
            }),
            0x3 => self.base_x = content,
            0x4 => self.vector(content, 12, events),
            0x5 => self.vector(content & 0xFF, 8, events),
            0x6 => {
                self.low = content;
                self.update_time();
            }
            0x8 => {
                if self.high >= WRAP_THRESHOLD + content {
                    self.loops += 1;
                }
                if self.high != content {
                    self.low = 0;
                }
                self.high = content;
                self.update_time();
            }
            0xA => triggers.push(Trigger {
                t: self.t,
                kind: if content & 1 == 1 {
                    TRIGGER_RISING
                } else {
                    TRIGGER_FALLING
                },
            }),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(ws: &[u16]) -> (Vec<Event>, Vec<Trigger>) {
        let bytes: Vec<u8> = ws.iter().flat_map(|w| w.to_le_bytes()).collect();
        let (mut events, mut triggers) = (Vec::new(), Vec::new());
        Evt3Decoder::default().decode(&bytes, &mut events, &mut triggers);
        (events, triggers)
    }

    #[test]
    fn addr_and_vectors() {
        let (events, _) = decode(&[
            0x2005,       // x before any time high: skipped
            0x8001,       // time high 1
            0x6010,       // time low 16 -> t = 4096 + 16
            0x0007,       // y = 7
            0x2805,       // ON at x=5
            0x3000 | 100, // base x 100, OFF
            0x4000 | 0b1000_0000_0001,
            0x5000 | 0b10,
            0x1003, // EM row: the next x emits nothing
            0x2001,
        ]);
        let at = |x, polarity| Event {
            t: 4112,
            x,
            y: 7,
            polarity,
        };
        assert_eq!(
            events,
            vec![at(5, true), at(100, false), at(111, false), at(113, false)]
        );
    }

    #[test]
    fn time_high_wraps_and_resets_time_low() {
        let (events, triggers) = decode(&[
            0x8FFF, 0x6005, 0x0000, 0x2000, // t = 0xFFF005
            0x8000, 0x2001, // wrap: t = 1 << 24
            0xA001,
        ]);
        assert_eq!(events[0].t, 0xFF_F005);
        assert_eq!(events[1].t, 1 << 24);
        assert_eq!(
            triggers,
            vec![Trigger {
                t: 1 << 24,
                kind: TRIGGER_RISING
            }]
        );
    }
}
