//! The three message types evtac reads from bags, decoded from their serialized bytes: ROS 1's
//! serialization (little-endian, packed, `u32` length prefixes) and ROS 2's CDR (a 4-byte
//! encapsulation header, then fields aligned to their own size from the end of that header).
//!
//! Why by hand rather than with a serialization crate: the messages are three fixed layouts
//! (`dvs_msgs/EventArray`, `event_camera_msgs/EventPacket`, `sensor_msgs/Imu`), each in two
//! encodings, and a generic deserializer (`cdr` or `cdr-encoding` through serde, a ROS 1 crate
//! through its own traits) would need the same structs spelled out, copy the packets'
//! `uint8[] events` element by element into a `Vec` (megabytes per message) where a slice of the
//! message suffices, and report a short message as "unexpected EOF" without the field or the
//! byte. Here every read is bounds-checked, a length prefix is checked against the bytes left
//! before anything is reserved for it, and an error names the field (`events[12].ts`) and its
//! byte offset in the message.

use crate::{Event, ImuSample, Resolution};

/// How a message's bytes are serialized.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Encoding {
    /// ROS 1: little-endian, no alignment, `time` as `u32` secs + `u32` nsecs.
    Ros1,
    /// ROS 2: CDR with its encapsulation header, `builtin_interfaces/Time` as `i32` sec +
    /// `u32` nanosec.
    Cdr,
}

/// Why a message did not decode: the field and where it starts in the message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct MsgError {
    /// The field, as a path (`header.frame_id`, `events[3].x`).
    pub field: String,
    /// Byte offset of the field in the message.
    pub offset: usize,
    /// What is wrong.
    pub what: String,
}

impl std::fmt::Display for MsgError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "field `{}` at byte {} of the message: {}",
            self.field, self.offset, self.what
        )
    }
}

/// A read past the end (or a bad value) before the field is known; the caller names it.
#[derive(Debug, Clone, Copy)]
struct Short {
    offset: usize,
    need: usize,
    left: usize,
}

impl Short {
    fn named(self, field: impl Into<String>) -> MsgError {
        MsgError {
            field: field.into(),
            offset: self.offset,
            what: format!(
                "needs {} byte(s) but the message has {} left (truncated, or not this message type)",
                self.need, self.left
            ),
        }
    }
}

/// A cursor over one message.
pub(crate) struct Reader<'a> {
    /// The message body (for CDR, after the encapsulation header).
    bytes: &'a [u8],
    pos: usize,
    /// Bytes before `bytes` in the message (the CDR header), for offsets in errors.
    base: usize,
    encoding: Encoding,
    big_endian: bool,
}

impl<'a> Reader<'a> {
    /// A reader of `message` in `encoding`; for CDR, checks the encapsulation header.
    pub(crate) fn new(message: &'a [u8], encoding: Encoding) -> Result<Self, MsgError> {
        match encoding {
            Encoding::Ros1 => Ok(Self {
                bytes: message,
                pos: 0,
                base: 0,
                encoding,
                big_endian: false,
            }),
            Encoding::Cdr => {
                let header = message.get(..4).ok_or_else(|| MsgError {
                    field: "CDR encapsulation header".into(),
                    offset: 0,
                    what: format!("the message holds {} byte(s), not 4", message.len()),
                })?;
                // 0x0000 CDR_BE, 0x0001 CDR_LE: what rmw implementations write for ROS 2
                // messages (the parameter-list and XCDR2 kinds are not used for them).
                let big_endian = match (header[0], header[1]) {
                    (0, 0) => true,
                    (0, 1) => false,
                    (a, b) => {
                        return Err(MsgError {
                            field: "CDR encapsulation header".into(),
                            offset: 0,
                            what: format!(
                                "kind 0x{a:02x}{b:02x} is not plain CDR (0x0000 big-endian or \
                                 0x0001 little-endian)"
                            ),
                        });
                    }
                };
                Ok(Self {
                    bytes: &message[4..],
                    pos: 0,
                    base: 4,
                    encoding,
                    big_endian,
                })
            }
        }
    }

    /// Bytes not read yet.
    pub(crate) fn left(&self) -> usize {
        self.bytes.len() - self.pos
    }

    /// The offset in the message of the next read.
    fn offset(&self) -> usize {
        self.base + self.pos
    }

    /// Skips CDR padding up to a multiple of `n` (from the end of the encapsulation header).
    fn align(&mut self, n: usize) -> Result<(), Short> {
        if self.encoding == Encoding::Cdr {
            let pad = (n - self.pos % n) % n;
            self.take(pad)?;
        }
        Ok(())
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], Short> {
        let short = Short {
            offset: self.offset(),
            need: n,
            left: self.left(),
        };
        let end = self.pos.checked_add(n).ok_or(short)?;
        let out = self.bytes.get(self.pos..end).ok_or(short)?;
        self.pos = end;
        Ok(out)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], Short> {
        self.align(N)?;
        let mut a: [u8; N] = self.take(N)?.try_into().expect("took N bytes");
        if self.big_endian {
            a.reverse();
        }
        Ok(a)
    }

    fn u8(&mut self) -> Result<u8, Short> {
        Ok(self.take(1)?[0])
    }

    fn u16(&mut self) -> Result<u16, Short> {
        self.array().map(u16::from_le_bytes)
    }

    fn u32(&mut self) -> Result<u32, Short> {
        self.array().map(u32::from_le_bytes)
    }

    fn u64(&mut self) -> Result<u64, Short> {
        self.array().map(u64::from_le_bytes)
    }

    fn f64(&mut self) -> Result<f64, Short> {
        self.array().map(f64::from_le_bytes)
    }

    fn bool(&mut self, field: impl Fn() -> String) -> Result<bool, MsgError> {
        let offset = self.offset();
        match self.u8().map_err(|s| s.named(field()))? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err(MsgError {
                field: field(),
                offset,
                what: format!("{v} is not a bool (0 or 1)"),
            }),
        }
    }

    /// A sequence's or string's length prefix, checked against the bytes left: each element
    /// takes at least `min_size` bytes.
    fn length(&mut self, field: &str, min_size: usize) -> Result<usize, MsgError> {
        let offset = self.offset();
        let n = self.u32().map_err(|s| s.named(format!("{field} length")))?;
        let n = usize::try_from(n).unwrap_or(usize::MAX);
        if n.saturating_mul(min_size) > self.left() {
            return Err(MsgError {
                field: format!("{field} length"),
                offset,
                what: format!(
                    "{n} element(s) of at least {min_size} byte(s) do not fit in the {} byte(s) \
                     left",
                    self.left()
                ),
            });
        }
        Ok(n)
    }

    /// A string (ROS 1: length and bytes; CDR: length with the NUL, bytes, NUL).
    fn string(&mut self, field: &str) -> Result<&'a str, MsgError> {
        let n = self.length(field, 1)?;
        let offset = self.offset();
        let bytes = self.take(n).map_err(|s| s.named(field))?;
        let text = match self.encoding {
            Encoding::Ros1 => bytes,
            Encoding::Cdr => match bytes.split_last() {
                Some((0, text)) => text,
                _ => {
                    return Err(MsgError {
                        field: field.into(),
                        offset,
                        what: "a CDR string must end in a NUL byte".into(),
                    });
                }
            },
        };
        std::str::from_utf8(text).map_err(|e| MsgError {
            field: field.into(),
            offset,
            what: format!("not UTF-8 ({e})"),
        })
    }

    /// A `time` (ROS 1) or `builtin_interfaces/Time` (ROS 2) in microseconds:
    /// `sec * 1_000_000 + nanosec / 1000`, truncating the nanoseconds.
    fn time_us(&mut self, field: impl Fn() -> String) -> Result<i64, MsgError> {
        let sec = self
            .u32()
            .map_err(|s| s.named(format!("{}.sec", field())))?;
        let nsec = self
            .u32()
            .map_err(|s| s.named(format!("{}.nanosec", field())))?;
        let sec = match self.encoding {
            // ROS 1 `time` is unsigned, ROS 2 `Time.sec` signed.
            Encoding::Ros1 => i64::from(sec),
            Encoding::Cdr => i64::from(sec as i32),
        };
        Ok(sec * 1_000_000 + i64::from(nsec / 1000))
    }

    /// `std_msgs/Header`: its stamp in microseconds (ROS 1's `seq` and the `frame_id` read past).
    fn header(&mut self) -> Result<i64, MsgError> {
        if self.encoding == Encoding::Ros1 {
            self.u32().map_err(|s| s.named("header.seq"))?;
        }
        let stamp = self.time_us(|| "header.stamp".into())?;
        self.string("header.frame_id")?;
        Ok(stamp)
    }

    /// The `uint32 height; uint32 width` pair of both event messages, as a sensor size.
    fn size(&mut self) -> Result<Resolution, MsgError> {
        let offset = self.offset();
        let height = self.u32().map_err(|s| s.named("height"))?;
        let width = self.u32().map_err(|s| s.named("width"))?;
        match (u16::try_from(width), u16::try_from(height)) {
            (Ok(w), Ok(h)) => Ok(Resolution::new(w, h)),
            _ => Err(MsgError {
                field: "width".into(),
                offset,
                what: format!("a {width}x{height} sensor is larger than 65535 pixels a side"),
            }),
        }
    }

    /// Decodes `n` `dvs_msgs/Event`s (little-endian) into `out` with no per-field error path,
    /// the way nearly every message is; `false`, with `out` and the cursor untouched, when a
    /// field is cut off or a polarity is not 0 or 1 (or the message is big-endian CDR): the
    /// careful field-by-field loop then finds and names the problem.
    fn events_fast(&mut self, n: usize, out: &mut Vec<Event>) -> bool {
        if self.big_endian {
            return false;
        }
        let start = out.len();
        let end = match self.encoding {
            Encoding::Ros1 => self.events_packed(n, out),
            Encoding::Cdr => self.events_aligned(n, out),
        };
        match end {
            Some(end) => {
                self.pos = end;
                true
            }
            None => {
                out.truncate(start);
                false
            }
        }
    }

    /// ROS 1 events: packed 13-byte records (`u16 x, u16 y, u32 sec, u32 nsec, u8 polarity`).
    fn events_packed(&self, n: usize, out: &mut Vec<Event>) -> Option<usize> {
        let end = self.pos.checked_add(n.checked_mul(13)?)?;
        let records = self.bytes.get(self.pos..end)?;
        let mut ok = true;
        out.extend(records.chunks_exact(13).map(|r| {
            let word = |i: usize| u32::from_le_bytes([r[i], r[i + 1], r[i + 2], r[i + 3]]);
            ok &= r[12] <= 1;
            Event {
                t: i64::from(word(4)) * 1_000_000 + i64::from(word(8) / 1000),
                x: u16::from_le_bytes([r[0], r[1]]),
                y: u16::from_le_bytes([r[2], r[3]]),
                polarity: r[12] == 1,
            }
        }));
        ok.then_some(end)
    }

    /// CDR events: each field aligned to its size from the end of the encapsulation header
    /// (`x` and `y` to 2, `sec` and `nanosec` to 4), so the first event's layout depends on
    /// where it starts and the later ones are 16 bytes apart.
    fn events_aligned(&self, n: usize, out: &mut Vec<Event>) -> Option<usize> {
        let b = self.bytes;
        let mut p = self.pos;
        let mut ok = true;
        // An event whose `x` starts at `x_at`: `sec` at the next multiple of 4 after `y`.
        let mut event = |x_at: usize, r: &[u8]| {
            let s = ((x_at + 4 + 3) & !3) - x_at;
            let word = |i: usize| u32::from_le_bytes([r[i], r[i + 1], r[i + 2], r[i + 3]]);
            let polarity = r[s + 8];
            ok &= polarity <= 1;
            out.push(Event {
                // ROS 2's `Time.sec` is signed.
                t: i64::from(word(s) as i32) * 1_000_000 + i64::from(word(s + 4) / 1000),
                x: u16::from_le_bytes([r[0], r[1]]),
                y: u16::from_le_bytes([r[2], r[3]]),
                polarity: polarity == 1,
            });
            x_at + s + 9
        };
        if n == 0 {
            return Some(p);
        }
        // The first event, wherever it starts.
        let x_at = p.checked_add(1)? & !1;
        let end = ((x_at + 4 + 3) & !3) + 9;
        p = event(x_at, b.get(x_at..end)?);
        // It ends one past a multiple of 4, so every later one starts 2 past a multiple of 4:
        // `x` at 0, `y` at 2, `sec` at 6, `nanosec` at 10, `polarity` at 14 of a 16-byte
        // stride (the last one without its byte of padding).
        let rest = n - 1;
        if rest > 0 {
            let x_at = p + 1;
            let end = x_at.checked_add(rest.checked_mul(16)? - 1)?;
            let region = b.get(x_at..end)?;
            for (i, r) in region.chunks(16).enumerate() {
                event(x_at + 16 * i, r);
            }
            p = end;
        }
        ok.then_some(p)
    }

    /// Checks that the message ends here. CDR messages may end in up to 7 bytes of padding
    /// (serializers pad to 4 or 8); ROS 1 messages have none.
    pub(crate) fn finish(&self) -> Result<(), MsgError> {
        let left = self.left();
        let padding = match self.encoding {
            Encoding::Ros1 => 0,
            Encoding::Cdr => 7,
        };
        if left > padding {
            return Err(MsgError {
                field: "(end of message)".into(),
                offset: self.offset(),
                what: format!(
                    "{left} byte(s) left after the last field: the message is not of this type"
                ),
            });
        }
        Ok(())
    }
}

/// The sensor size a `dvs_msgs/EventArray` states, its events not decoded.
pub(crate) fn event_array_size(message: &[u8], encoding: Encoding) -> Result<Resolution, MsgError> {
    let mut r = Reader::new(message, encoding)?;
    r.header()?;
    r.size()
}

/// `dvs_msgs/EventArray` (rpg_dvs_ros; ROS 2 `dvs_msgs/msg/EventArray`): appends its events to
/// `out` and returns the sensor size the message states.
pub(crate) fn event_array(
    message: &[u8],
    encoding: Encoding,
    out: &mut Vec<Event>,
) -> Result<Resolution, MsgError> {
    let mut r = Reader::new(message, encoding)?;
    r.header()?;
    let size = r.size()?;
    // x, y, ts (8 bytes), polarity: at least 13 bytes each.
    let n = r.length("events", 13)?;
    out.reserve(n);
    if r.events_fast(n, out) {
        r.finish()?;
        return Ok(size);
    }
    for i in 0..n {
        let x = r.u16().map_err(|s| s.named(format!("events[{i}].x")))?;
        let y = r.u16().map_err(|s| s.named(format!("events[{i}].y")))?;
        let t = r.time_us(|| format!("events[{i}].ts"))?;
        let polarity = r.bool(|| format!("events[{i}].polarity"))?;
        out.push(Event { t, x, y, polarity });
    }
    r.finish()?;
    Ok(size)
}

/// `event_camera_msgs/EventPacket` (ros-event-camera), its events still encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct EventPacket<'a> {
    /// The sensor size the message states.
    pub size: Resolution,
    /// Sensor time of the packet's first event, nanoseconds (the `mono` encoding's base; for
    /// `evt3` its content is undefined).
    pub time_base: u64,
    /// `evt3`, `mono`, ...
    pub encoding: &'a str,
    /// Whether `events` holds big-endian words.
    pub is_bigendian: bool,
    /// The encoded events.
    pub events: &'a [u8],
    /// Byte offset of `events` in the message, for errors.
    pub events_offset: usize,
}

/// Decodes an `event_camera_msgs/EventPacket` (ROS 1 or ROS 2 layout).
pub(crate) fn event_packet(
    message: &[u8],
    encoding: Encoding,
) -> Result<EventPacket<'_>, MsgError> {
    let mut r = Reader::new(message, encoding)?;
    r.header()?;
    let size = r.size()?;
    r.u64().map_err(|s| s.named("seq"))?;
    let time_base = r.u64().map_err(|s| s.named("time_base"))?;
    let encoding_name = r.string("encoding")?;
    let is_bigendian = r.bool(|| "is_bigendian".into())?;
    let n = r.length("events", 1)?;
    let events_offset = r.offset();
    let events = r.take(n).map_err(|s| s.named("events"))?;
    r.finish()?;
    Ok(EventPacket {
        size,
        time_base,
        encoding: encoding_name,
        is_bigendian,
        events,
        events_offset,
    })
}

/// Standard gravity (m/s^2 per g), as `sensor_msgs/Imu`'s m/s^2 become the g of [`ImuSample`].
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// `sensor_msgs/Imu` as an [`ImuSample`]: the header stamp in microseconds, the linear
/// acceleration from m/s^2 to g, the angular velocity from rad/s to deg/s; the message has no
/// temperature, so it is NaN. Orientation and covariances are read past.
pub(crate) fn imu(message: &[u8], encoding: Encoding) -> Result<ImuSample, MsgError> {
    let mut r = Reader::new(message, encoding)?;
    let t = r.header()?;
    let mut vector = |field: &str, n: usize| -> Result<[f64; 9], MsgError> {
        let mut v = [0.0; 9];
        for (i, slot) in v.iter_mut().take(n).enumerate() {
            *slot = r.f64().map_err(|s| s.named(format!("{field}[{i}]")))?;
        }
        Ok(v)
    };
    vector("orientation", 4)?;
    vector("orientation_covariance", 9)?;
    let gyro = vector("angular_velocity", 3)?;
    vector("angular_velocity_covariance", 9)?;
    let accel = vector("linear_acceleration", 3)?;
    vector("linear_acceleration_covariance", 9)?;
    r.finish()?;
    Ok(ImuSample {
        t,
        accelerometer: [0, 1, 2].map(|i| (accel[i] / STANDARD_GRAVITY) as f32),
        gyroscope: [0, 1, 2].map(|i| gyro[i].to_degrees() as f32),
        temperature: f32::NAN,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ROS 1 `dvs_msgs/EventArray` with `events` as (x, y, secs, nsecs, polarity).
    fn ros1_array(events: &[(u16, u16, u32, u32, u8)]) -> Vec<u8> {
        let mut m = Vec::new();
        m.extend(7u32.to_le_bytes()); // seq
        m.extend([0u8; 8]); // stamp
        m.extend(3u32.to_le_bytes());
        m.extend(b"cam");
        m.extend(480u32.to_le_bytes());
        m.extend(640u32.to_le_bytes());
        m.extend((events.len() as u32).to_le_bytes());
        for &(x, y, s, ns, p) in events {
            m.extend(x.to_le_bytes());
            m.extend(y.to_le_bytes());
            m.extend(s.to_le_bytes());
            m.extend(ns.to_le_bytes());
            m.push(p);
        }
        m
    }

    /// A CDR `dvs_msgs/msg/EventArray` with `frame_id` and `events` as (x, y, sec, nanosec,
    /// polarity), each field aligned to its size from the end of the encapsulation header.
    fn cdr_array(frame_id: &str, events: &[(u16, u16, i32, u32, u8)]) -> Vec<u8> {
        let mut b = Vec::new();
        let align = |b: &mut Vec<u8>, n: usize| b.resize(b.len().div_ceil(n) * n, 0);
        b.extend([0u8; 8]); // stamp
        b.extend((frame_id.len() as u32 + 1).to_le_bytes());
        b.extend(frame_id.as_bytes());
        b.push(0);
        for v in [480u32, 640, events.len() as u32] {
            align(&mut b, 4);
            b.extend(v.to_le_bytes());
        }
        for &(x, y, sec, ns, p) in events {
            align(&mut b, 2);
            b.extend(x.to_le_bytes());
            b.extend(y.to_le_bytes());
            align(&mut b, 4);
            b.extend(sec.to_le_bytes());
            b.extend(ns.to_le_bytes());
            b.push(p);
        }
        [vec![0, 1, 0, 0], b].concat()
    }

    /// The fast paths (packed ROS 1 records; CDR's first event, then a 16-byte stride) against
    /// the events written, for every alignment the frame id's length gives the first event,
    /// and a bad polarity still named by the careful loop.
    #[test]
    fn event_arrays_decode_alike_at_every_alignment() {
        let all = [
            (1u16, 2u16, 3i32, 999_999_999u32, 1u8),
            (639, 479, -1, 1999, 0),
            (7, 8, 1_600_000_000, 5_000, 1),
            (0, 0, 0, 0, 0),
        ];
        // Each (x, y, seconds, nanoseconds, polarity) as the event it stands for.
        let event = |(x, y, s, ns, p): (u16, u16, i64, u32, u8)| Event {
            t: s * 1_000_000 + i64::from(ns / 1000),
            x,
            y,
            polarity: p == 1,
        };
        let want = |events: &[(u16, u16, i32, u32, u8)]| -> Vec<Event> {
            let wide = |&(x, y, s, ns, p): &(u16, u16, i32, u32, u8)| (x, y, i64::from(s), ns, p);
            events.iter().map(wide).map(event).collect()
        };
        for n in 0..=all.len() {
            let events = &all[..n];
            for frame in ["", "a", "ab", "abc", "abcd", "cam_0"] {
                let mut out = Vec::new();
                event_array(&cdr_array(frame, events), Encoding::Cdr, &mut out).unwrap();
                assert_eq!(out, want(events), "CDR, frame {frame:?}, {n} events");
            }
            // ROS 1's `time.sec` is unsigned: -1 reads as 4294967295 s.
            let ros1: Vec<_> = events
                .iter()
                .map(|&(x, y, s, ns, p)| (x, y, s as u32, ns, p))
                .collect();
            let mut out = Vec::new();
            event_array(&ros1_array(&ros1), Encoding::Ros1, &mut out).unwrap();
            let unsigned: Vec<Event> = ros1
                .iter()
                .map(|&(x, y, s, ns, p)| event((x, y, i64::from(s), ns, p)))
                .collect();
            assert_eq!(out, unsigned, "ROS 1, {n} events");
        }
        let mut bad = all;
        bad[2].4 = 2;
        for (m, encoding) in [
            (cdr_array("ab", &bad), Encoding::Cdr),
            (
                ros1_array(&bad.map(|(x, y, s, ns, p)| (x, y, s as u32, ns, p))),
                Encoding::Ros1,
            ),
        ] {
            let mut out = Vec::new();
            let err = event_array(&m, encoding, &mut out).unwrap_err();
            assert_eq!(err.field, "events[2].polarity", "{encoding:?}: {err}");
        }
    }

    #[test]
    fn ros1_event_array_times_truncate_to_microseconds() {
        let m = ros1_array(&[(1, 2, 3, 999_999_999, 1), (4, 5, 4, 1999, 0)]);
        let mut out = Vec::new();
        let size = event_array(&m, Encoding::Ros1, &mut out).unwrap();
        assert_eq!(size, Resolution::new(640, 480));
        assert_eq!(
            out,
            vec![
                Event {
                    t: 3_999_999,
                    x: 1,
                    y: 2,
                    polarity: true
                },
                Event {
                    t: 4_000_001,
                    x: 4,
                    y: 5,
                    polarity: false
                }
            ]
        );
    }

    #[test]
    fn a_cut_or_overlong_message_names_the_field() {
        let m = ros1_array(&[(1, 2, 3, 4, 1), (4, 5, 6, 7, 0)]);
        let mut out = Vec::new();
        let err = event_array(&m[..m.len() - 3], Encoding::Ros1, &mut out).unwrap_err();
        assert_eq!(err.field, "events length", "{err}");
        let err = event_array(&m[..m.len() - 14], Encoding::Ros1, &mut out).unwrap_err();
        assert_eq!(err.field, "events length", "{err}");
        let mut long = m.clone();
        long.push(0);
        let err = event_array(&long, Encoding::Ros1, &mut out).unwrap_err();
        assert!(err.what.contains("1 byte(s) left"), "{err}");
        let mut bad = m.clone();
        let last = bad.len() - 1;
        bad[last] = 2;
        let err = event_array(&bad, Encoding::Ros1, &mut out).unwrap_err();
        assert_eq!(err.field, "events[1].polarity", "{err}");
        // A huge count is refused before anything is reserved for it.
        let mut huge = m.clone();
        let at = 4 + 8 + 4 + 3 + 8;
        huge[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        let err = event_array(&huge, Encoding::Ros1, &mut out).unwrap_err();
        assert!(err.what.contains("do not fit"), "{err}");
    }

    #[test]
    fn cdr_aligns_fields_from_the_encapsulation_header() {
        // EventPacket, CDR little-endian: stamp, frame_id "a" (padded to 4), height, width, seq
        // (at 24: aligned), time_base, encoding "evt3", is_bigendian, events [1, 2, 3] (their
        // length padded to 4).
        let mut m = vec![0, 1, 0, 0];
        m.extend(5i32.to_le_bytes());
        m.extend(6u32.to_le_bytes());
        m.extend(2u32.to_le_bytes());
        m.extend(b"a\0");
        m.extend([0, 0]); // pad to 4
        m.extend(720u32.to_le_bytes());
        m.extend(1280u32.to_le_bytes());
        m.extend(9u64.to_le_bytes());
        m.extend(77u64.to_le_bytes());
        m.extend(5u32.to_le_bytes());
        m.extend(b"evt3\0");
        m.push(0);
        m.extend([0, 0]); // pad to 4
        m.extend(3u32.to_le_bytes());
        m.extend([1, 2, 3]);
        let p = event_packet(&m, Encoding::Cdr).unwrap();
        assert_eq!(p.size, Resolution::new(1280, 720));
        assert_eq!(
            (p.time_base, p.encoding, p.is_bigendian),
            (77, "evt3", false)
        );
        assert_eq!(p.events, &[1, 2, 3]);
        assert_eq!(p.events_offset, m.len() - 3);
        let err = event_packet(&m[..20], Encoding::Cdr).unwrap_err();
        assert_eq!((err.field.as_str(), err.offset), ("height", 20), "{err}");
    }
}
