//! AEDAT 3.1 event packets (cAER, libcaer).
//!
//! After the header come packets, little-endian: a 28-byte header (`eventType` i16,
//! `eventSource` i16, `eventSize` i32, `eventTSOffset` i32, `eventTSOverflow` i32,
//! `eventCapacity` i32, `eventNumber` i32, `eventValid` i32) and `eventCapacity * eventSize`
//! bytes of events of that one type (iniVation's AEDAT 3.1 format description; libcaer
//! `events/common.h`). Every event's first 32-bit word has a validity mark in bit 0; only valid
//! events count. A timestamp is the event's 31-bit `timestamp` plus `eventTSOverflow << 31`.
//!
//! - type 1, polarity (8 bytes): `data` u32 (polarity bit 1, `y` bits 2..16, `x` bits 17..31,
//!   libcaer's top-left origin), `timestamp` i32.
//! - type 3, IMU6 (36 bytes, libcaer `caer_imu6_event`): `info` u32, `timestamp` i32, then f32
//!   acceleration x, y, z in g, rotation x, y, z in deg/s, temperature in deg C.
//! - type 0, special (8 bytes): `data` u32 with the special type in bits 1..7, `timestamp` i32.
//!   External input rising / falling edges and pulses (types 2, 3, 4) become triggers with the
//!   AEDAT4 codes 1, 2, 3. A timestamp reset (type 1) restarts the camera clock at zero: it is
//!   kept as a trigger of code 0 at the last time read before it, and every later timestamp is
//!   shifted by that time, so that time keeps going forwards.
//! - every other type (frames, IMU9, spikes, ...) is skipped without being buffered.
//!
//! A file may hold packets from several cameras (`eventSource`); evtac reads those of the first
//! packet's source and skips the rest.

use super::{LegacyError, Out};
use crate::{Event, ImuSample, Trigger};

/// Size of a packet header.
const PACKET_HEADER: usize = 28;

/// The event types decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Special,
    Polarity,
    Imu6,
}

impl Kind {
    fn of(event_type: i16) -> Option<Self> {
        match event_type {
            0 => Some(Self::Special),
            1 => Some(Self::Polarity),
            3 => Some(Self::Imu6),
            _ => None,
        }
    }

    /// The event size the format fixes for the type.
    fn size(self) -> usize {
        match self {
            Self::Special | Self::Polarity => 8,
            Self::Imu6 => 36,
        }
    }
}

/// Where the decoder is in the packet stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Expecting a packet header.
    Header,
    /// Inside the events of a decoded packet: `left` events to decode, then `tail` bytes of
    /// unused capacity to skip.
    Events {
        kind: Kind,
        left: u64,
        tail: u64,
        overflow: i64,
    },
    /// Skipping `left` more bytes of a packet evtac does not decode.
    Skip { left: u64 },
}

/// Decoder state carried across reads.
#[derive(Debug, Clone)]
pub(crate) struct Decoder {
    state: State,
    /// Offset and size of the packet being read (for truncation errors).
    packet: (u64, u64),
    /// The source whose packets are read (the first packet's).
    source: Option<i16>,
    /// Added to every timestamp: the time of the last timestamp reset.
    shift: i64,
    /// The latest time read so far.
    latest: i64,
}

impl Default for Decoder {
    fn default() -> Self {
        Self {
            state: State::Header,
            packet: (0, 0),
            source: None,
            shift: 0,
            latest: 0,
        }
    }
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn i32_at(b: &[u8], at: usize) -> i32 {
    u32_at(b, at) as i32
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_bits(u32_at(b, at))
}

impl Decoder {
    /// Decodes as much of `bytes` (found at file offset `offset`) as is whole into `out`;
    /// returns the bytes used.
    pub(crate) fn decode(
        &mut self,
        bytes: &[u8],
        offset: u64,
        out: &mut Out,
    ) -> Result<usize, LegacyError> {
        let mut pos = 0;
        loop {
            let rest = &bytes[pos..];
            match self.state {
                State::Header => {
                    if rest.len() < PACKET_HEADER {
                        return Ok(pos);
                    }
                    self.packet_header(&rest[..PACKET_HEADER], offset + pos as u64)?;
                    pos += PACKET_HEADER;
                }
                State::Skip { left } => {
                    let n = (rest.len() as u64).min(left);
                    if left == 0 {
                        self.state = State::Header;
                        continue;
                    }
                    if n == 0 {
                        return Ok(pos);
                    }
                    pos += n as usize;
                    self.state = State::Skip { left: left - n };
                }
                State::Events {
                    kind,
                    left,
                    tail,
                    overflow,
                } => {
                    if left == 0 {
                        self.state = State::Skip { left: tail };
                        continue;
                    }
                    let size = kind.size();
                    let n = (rest.len() / size).min(usize::try_from(left).unwrap_or(usize::MAX));
                    if n == 0 {
                        return Ok(pos);
                    }
                    for e in rest[..n * size].chunks_exact(size) {
                        self.event(kind, e, overflow, out);
                    }
                    pos += n * size;
                    self.state = State::Events {
                        kind,
                        left: left - n as u64,
                        tail,
                        overflow,
                    };
                }
            }
        }
    }

    /// Reads a packet header at file offset `offset` and sets the state for its events.
    fn packet_header(&mut self, h: &[u8], offset: u64) -> Result<(), LegacyError> {
        let event_type = i16::from_le_bytes([h[0], h[1]]);
        let source = i16::from_le_bytes([h[2], h[3]]);
        let size = i32_at(h, 4);
        let ts_offset = i32_at(h, 8);
        let overflow = i32_at(h, 12);
        let capacity = i32_at(h, 16);
        let number = i32_at(h, 20);
        let bad = |field, value: i32, reason| LegacyError::BadPacket {
            offset,
            field,
            value: i64::from(value),
            reason,
        };
        if size < 1 {
            return Err(bad("eventSize", size, "must be at least 1"));
        }
        if capacity < 0 {
            return Err(bad("eventCapacity", capacity, "must not be negative"));
        }
        if !(0..=capacity).contains(&number) {
            return Err(bad(
                "eventNumber",
                number,
                "must be from 0 to eventCapacity",
            ));
        }
        if overflow < 0 {
            return Err(bad("eventTSOverflow", overflow, "must not be negative"));
        }
        // Both fit in 31 bits: the product fits in u64.
        let data = u64::from(size.unsigned_abs()) * u64::from(capacity.unsigned_abs());
        self.packet = (offset, PACKET_HEADER as u64 + data);
        let source = *self.source.get_or_insert(source) == source;
        let kind = Kind::of(event_type).filter(|_| source);
        self.state = match kind {
            None => State::Skip { left: data },
            Some(kind) => {
                if size as usize != kind.size() {
                    return Err(bad("eventSize", size, "does not match the event type"));
                }
                if ts_offset != 4 {
                    return Err(bad("eventTSOffset", ts_offset, "must be 4"));
                }
                State::Events {
                    kind,
                    left: u64::from(number.unsigned_abs()),
                    tail: u64::from((capacity - number).unsigned_abs()) * kind.size() as u64,
                    overflow: i64::from(overflow) << 31,
                }
            }
        };
        Ok(())
    }

    /// Decodes one event of `kind`.
    fn event(&mut self, kind: Kind, e: &[u8], overflow: i64, out: &mut Out) {
        let data = u32_at(e, 0);
        if data & 1 == 0 {
            return;
        }
        // Saturating: repeated resets after huge overflows must not overflow i64 (time then
        // stops, and the time-order check names the event).
        let t = self
            .shift
            .saturating_add(overflow + i64::from(i32_at(e, 4)));
        match kind {
            Kind::Polarity => out.events.push(Event {
                t,
                // 15 bits each.
                x: (data >> 17) as u16,
                y: ((data >> 2) & 0x7FFF) as u16,
                polarity: data & 2 != 0,
            }),
            Kind::Imu6 => out.imu.push(ImuSample {
                t,
                accelerometer: [f32_at(e, 8), f32_at(e, 12), f32_at(e, 16)],
                gyroscope: [f32_at(e, 20), f32_at(e, 24), f32_at(e, 28)],
                temperature: f32_at(e, 32),
            }),
            Kind::Special => {
                let (t, kind) = match (data >> 1) & 0x7F {
                    1 => {
                        // The reset's own timestamp is not on either clock.
                        self.shift = self.latest;
                        (self.latest, 0)
                    }
                    2 => (t, 1),
                    3 => (t, 2),
                    4 => (t, 3),
                    _ => return,
                };
                out.triggers.push(Trigger { t, kind });
                self.latest = self.latest.max(t);
                return;
            }
        }
        self.latest = self.latest.max(t);
    }

    /// Checks the end of the file: `left` unused bytes remain at `offset`.
    pub(crate) fn finish(&self, left: usize, offset: u64, len: u64) -> Result<(), LegacyError> {
        let (what, start, needed) = match self.state {
            State::Header if left == 0 => return Ok(()),
            State::Header => ("packet header", offset, PACKET_HEADER as u64),
            State::Events {
                left: 0, tail: 0, ..
            }
            | State::Skip { left: 0 } => return Ok(()),
            _ => ("packet", self.packet.0, self.packet.1),
        };
        Err(LegacyError::Truncated {
            what,
            offset: start,
            needed,
            len,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn packet(kind: i16, size: i32, overflow: i32, events: &[Vec<u8>]) -> Vec<u8> {
        let n = events.len() as i32;
        let mut p = Vec::new();
        for v in [kind.to_le_bytes().to_vec(), 1i16.to_le_bytes().to_vec()] {
            p.extend(v);
        }
        for v in [size, 4, overflow, n, n, n] {
            p.extend(v.to_le_bytes());
        }
        events.iter().for_each(|e| p.extend(e));
        p
    }

    fn word_ts(data: u32, ts: i32) -> Vec<u8> {
        [data.to_le_bytes(), ts.to_le_bytes()].concat()
    }

    #[test]
    fn polarity_special_reset_and_skipped_packets() {
        let bytes = [
            packet(2, 5, 0, &[vec![9; 5]]), // a frame-like packet: skipped
            packet(
                1,
                8,
                1,
                &[
                    word_ts(7 << 17 | 3 << 2 | 2 | 1, 5),
                    word_ts(8 << 17, 6), // invalid: skipped
                ],
            ),
            packet(
                0,
                8,
                0,
                &[word_ts(2 << 1 | 1, 9), word_ts(1 << 1 | 1, i32::MAX)],
            ),
            packet(1, 8, 0, &[word_ts(1 << 17 | 1, 2)]),
        ]
        .concat();
        let mut out = Out::default();
        let mut d = Decoder::default();
        assert_eq!(d.decode(&bytes, 0, &mut out).unwrap(), bytes.len());
        d.finish(0, bytes.len() as u64, bytes.len() as u64).unwrap();
        let first = (1 << 31) + 5;
        assert_eq!(
            out.events,
            vec![
                Event {
                    t: first,
                    x: 7,
                    y: 3,
                    polarity: true
                },
                Event {
                    t: first + 2,
                    x: 1,
                    y: 0,
                    polarity: false
                },
            ]
        );
        assert_eq!(
            out.triggers,
            vec![Trigger { t: 9, kind: 1 }, Trigger { t: first, kind: 0 }]
        );
    }

    #[test]
    fn resets_after_the_largest_overflow_do_not_overflow() {
        let reset = || packet(0, 8, 0, &[word_ts(1 << 1 | 1, 0)]);
        let late = || packet(1, 8, i32::MAX, &[word_ts(1, i32::MAX)]);
        let bytes = [late(), reset(), late(), reset(), late(), reset(), late()].concat();
        let mut out = Out::default();
        Decoder::default().decode(&bytes, 0, &mut out).unwrap();
        assert_eq!(out.events.last().map(|e| e.t), Some(i64::MAX));
    }

    #[test]
    fn bad_headers_and_truncation_are_errors() {
        let mut d = Decoder::default();
        let bad = packet(1, 36, 0, &[]);
        let err = d.decode(&bad, 40, &mut Out::default()).unwrap_err();
        assert!(matches!(
            err,
            LegacyError::BadPacket {
                offset: 40,
                field: "eventSize",
                ..
            }
        ));
        let mut d = Decoder::default();
        let p = packet(1, 8, 0, &[word_ts(1, 1), word_ts(1, 2)]);
        let used = d.decode(&p[..40], 100, &mut Out::default()).unwrap();
        assert_eq!(used, 36);
        let err = d.finish(4, 136, 140).unwrap_err();
        assert!(
            matches!(
                err,
                LegacyError::Truncated {
                    what: "packet",
                    offset: 100,
                    needed: 44,
                    len: 140
                }
            ),
            "{err}"
        );
    }
}
