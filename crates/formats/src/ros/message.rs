//! One event topic's messages decoded one at a time: what the bag readers do with each message
//! they take from a bag, and what a live ROS 2 subscriber (`evtac online --input ros2://TOPIC`)
//! does with each sample it receives, so that a bag of the published messages and the live
//! stream give the same events, bit for bit.
//!
//! ```
//! use evtac_formats::ros::{EventMessage, MessageDecoder};
//!
//! // A `dvs_msgs/msg/EventArray` as ROS 2 serializes it (CDR, little-endian), holding no event.
//! let mut message = vec![0, 1, 0, 0]; // encapsulation header: plain CDR, little-endian
//! message.extend([0u8; 8]); // header.stamp
//! message.extend(1u32.to_le_bytes()); // header.frame_id: "" and its NUL
//! message.extend([0, 0, 0, 0]); // the NUL, padded to 4
//! message.extend(480u32.to_le_bytes()); // height
//! message.extend(640u32.to_le_bytes()); // width
//! message.extend(0u32.to_le_bytes()); // no events
//! let kind = EventMessage::of("dvs_msgs::msg::dds_::EventArray_").unwrap();
//! let mut decoder = MessageDecoder::cdr(kind);
//! let (mut events, mut triggers) = (Vec::new(), Vec::new());
//! let size = decoder.decode(&message, &mut events, &mut triggers)?;
//! assert_eq!((size.width, size.height, events.len()), (640, 480, 0));
//! # Ok::<(), evtac_formats::ros::MessageError>(())
//! ```

use super::msg;
use crate::evt::Evt3Decoder;
use crate::{Event, Resolution, Trigger};

/// The event message types evtac decodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum EventMessage {
    /// `dvs_msgs/msg/EventArray` (rpg_dvs_ros and its ROS 2 ports): one record per event.
    EventArray,
    /// `event_camera_msgs/msg/EventPacket` (ros-event-camera's drivers): the camera's own
    /// encoding (`evt3`, `mono`) in a byte array.
    EventPacket,
}

impl EventMessage {
    /// Both types.
    pub const ALL: [Self; 2] = [Self::EventPacket, Self::EventArray];

    /// The type `name` spells, in any of its spellings: ROS 1 (`dvs_msgs/EventArray`), ROS 2
    /// (`dvs_msgs/msg/EventArray`) or DDS (`dvs_msgs::msg::dds_::EventArray_`); `None` for
    /// any other type.
    pub fn of(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| {
            name == m.ros2_name()
                || name == m.dds_type_name()
                || name == m.ros2_name().replacen("/msg/", "/", 1)
        })
    }

    /// The ROS 2 name, `dvs_msgs/msg/EventArray` or `event_camera_msgs/msg/EventPacket`.
    pub fn ros2_name(self) -> &'static str {
        match self {
            Self::EventArray => "dvs_msgs/msg/EventArray",
            Self::EventPacket => "event_camera_msgs/msg/EventPacket",
        }
    }

    /// The DDS type name ROS 2 gives the type (`dvs_msgs::msg::dds_::EventArray_`), which a
    /// DDS reader must name to match ROS 2 publishers.
    pub fn dds_type_name(self) -> &'static str {
        match self {
            Self::EventArray => "dvs_msgs::msg::dds_::EventArray_",
            Self::EventPacket => "event_camera_msgs::msg::dds_::EventPacket_",
        }
    }
}

impl std::fmt::Display for EventMessage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.ros2_name())
    }
}

/// Why a message did not decode.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum MessageError {
    /// The bytes are not a message of the type: what is wrong, naming the field and its byte
    /// offset in the message.
    #[error("{0}")]
    Malformed(String),
    /// An `EventPacket` in an encoding evtac does not decode.
    #[error("unknown EventPacket encoding `{encoding}` (evtac decodes `evt3` and `mono`)")]
    Encoding {
        /// The packet's `encoding` field.
        encoding: String,
    },
}

/// Decodes one topic's event messages in the order they come, keeping what carries from one
/// message to the next: the EVT 3.0 decoder's state (time high and low, row, vector base), as
/// ros-event-camera's `event_camera_codecs` do, since the drivers cut the camera's word stream
/// into packets anywhere.
///
/// An event's time is the bag readers' (see [`crate::ros`]): for `dvs_msgs/EventArray` its
/// `ts` as `sec * 1_000_000 + nanosec / 1000` microseconds; for `evt3` packets the camera's
/// counter; for `mono` packets `time_base + dt` nanoseconds, truncated to microseconds.
#[derive(Debug, Clone)]
pub struct MessageDecoder {
    message: EventMessage,
    encoding: msg::Encoding,
    evt3: Evt3Decoder,
}

impl MessageDecoder {
    /// A decoder of ROS 2 messages of type `message` (CDR, each starting with its 4-byte
    /// encapsulation header, as DDS delivers them and rosbag2 stores them).
    pub fn cdr(message: EventMessage) -> Self {
        Self::new(message, msg::Encoding::Cdr)
    }

    pub(super) fn new(message: EventMessage, encoding: msg::Encoding) -> Self {
        Self {
            message,
            encoding,
            evt3: Evt3Decoder::default(),
        }
    }

    /// The message type decoded.
    pub fn message(&self) -> EventMessage {
        self.message
    }

    /// The sensor size `bytes` states (`width` x `height`), its events not decoded.
    pub fn size(&self, bytes: &[u8]) -> Result<Resolution, MessageError> {
        let malformed = |e: msg::MsgError| MessageError::Malformed(e.to_string());
        match self.message {
            EventMessage::EventArray => msg::event_array_size(bytes, self.encoding),
            EventMessage::EventPacket => msg::event_packet(bytes, self.encoding).map(|p| p.size),
        }
        .map_err(malformed)
    }

    /// Decodes the message `bytes`, appending its events to `events` (and an `evt3` packet's
    /// external triggers to `triggers`); returns the sensor size the message states. On an
    /// error nothing is appended, and the EVT 3.0 state is as before the message.
    pub fn decode(
        &mut self,
        bytes: &[u8],
        events: &mut Vec<Event>,
        triggers: &mut Vec<Trigger>,
    ) -> Result<Resolution, MessageError> {
        let malformed = |e: msg::MsgError| MessageError::Malformed(e.to_string());
        let (start, trigger_start) = (events.len(), triggers.len());
        let decoded = match self.message {
            EventMessage::EventArray => {
                msg::event_array(bytes, self.encoding, events).map_err(malformed)
            }
            EventMessage::EventPacket => {
                let packet = msg::event_packet(bytes, self.encoding).map_err(malformed)?;
                decode_packet(&packet, &mut self.evt3, events, triggers).map(|()| packet.size)
            }
        };
        if decoded.is_err() {
            events.truncate(start);
            triggers.truncate(trigger_start);
        }
        decoded
    }
}

/// Decodes one `EventPacket`'s events into `events` (and the EVT3 triggers into `triggers`).
/// The EVT 3.0 state changes only once the packet is known to be whole words.
fn decode_packet(
    p: &msg::EventPacket<'_>,
    evt3: &mut Evt3Decoder,
    events: &mut Vec<Event>,
    triggers: &mut Vec<Trigger>,
) -> Result<(), MessageError> {
    if p.is_bigendian && matches!(p.encoding, "evt3" | "mono") {
        return Err(MessageError::Malformed(format!(
            "field `is_bigendian` is true; the drivers write `{}` words little-endian and evtac \
             reads no other",
            p.encoding
        )));
    }
    let whole = |word: usize| {
        if p.events.len().is_multiple_of(word) {
            Ok(())
        } else {
            Err(MessageError::Malformed(format!(
                "field `events` at byte {} of the message holds {} bytes, not whole {word}-byte \
                 `{}` words",
                p.events_offset,
                p.events.len(),
                p.encoding
            )))
        }
    };
    match p.encoding {
        "evt3" => {
            whole(2)?;
            evt3.decode(p.events, events, triggers);
        }
        "mono" => {
            whole(8)?;
            events.reserve(p.events.len() / 8);
            for (i, w) in p.events.chunks_exact(8).enumerate() {
                let word = u64::from_le_bytes(w.try_into().expect("8 bytes"));
                let ns = u128::from(p.time_base) + u128::from(word & 0xFFFF_FFFF);
                let t = i64::try_from(ns / 1000).map_err(|_| {
                    MessageError::Malformed(format!(
                        "event {i}: time_base {} + dt overflows the microsecond clock",
                        p.time_base
                    ))
                })?;
                events.push(Event {
                    t,
                    x: (word >> 32) as u16,
                    y: ((word >> 48) & 0x7FFF) as u16,
                    polarity: word >> 63 == 1,
                });
            }
        }
        other => {
            return Err(MessageError::Encoding {
                encoding: other.to_string(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_spelling_of_the_types_is_known() {
        for (name, want) in [
            ("dvs_msgs/EventArray", EventMessage::EventArray),
            ("dvs_msgs/msg/EventArray", EventMessage::EventArray),
            ("dvs_msgs::msg::dds_::EventArray_", EventMessage::EventArray),
            ("event_camera_msgs/EventPacket", EventMessage::EventPacket),
            (
                "event_camera_msgs::msg::dds_::EventPacket_",
                EventMessage::EventPacket,
            ),
        ] {
            assert_eq!(EventMessage::of(name), Some(want), "{name}");
        }
        assert_eq!(EventMessage::of("sensor_msgs/msg/Imu"), None);
        assert_eq!(EventMessage::of("dvs_msgs::msg::EventArray"), None);
    }

    /// An `evt3` packet (CDR) of `words`, 1280x720.
    fn packet(words: &[u16], encoding: &str) -> Vec<u8> {
        let mut m = vec![0, 1, 0, 0];
        m.extend([0u8; 8]); // stamp
        m.extend(1u32.to_le_bytes());
        m.extend([0, 0, 0, 0]); // "" + NUL, padded
        m.extend(720u32.to_le_bytes());
        m.extend(1280u32.to_le_bytes());
        m.extend(0u64.to_le_bytes()); // seq
        m.extend(0u64.to_le_bytes()); // time_base
        m.extend((encoding.len() as u32 + 1).to_le_bytes());
        m.extend(encoding.as_bytes());
        m.push(0);
        m.push(0); // is_bigendian
        while (m.len() - 4) % 4 != 0 {
            m.push(0);
        }
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        m.extend((bytes.len() as u32).to_le_bytes());
        m.extend(bytes);
        m
    }

    #[test]
    fn evt3_state_carries_across_messages_and_a_bad_message_leaves_it_alone() {
        let mut d = MessageDecoder::cdr(EventMessage::EventPacket);
        let (mut events, mut triggers) = (Vec::new(), Vec::new());
        // Time and row in the first packet, the event in the second.
        d.decode(
            &packet(&[0x8001, 0x6010, 0x0007], "evt3"),
            &mut events,
            &mut triggers,
        )
        .unwrap();
        assert!(events.is_empty());
        // A cut word: refused whole, the state untouched.
        let mut cut = packet(&[0x8002, 0x6011], "evt3");
        cut.pop();
        let len_at = cut.len() - 3 - 4;
        cut[len_at..len_at + 4].copy_from_slice(&3u32.to_le_bytes());
        let e = d.decode(&cut, &mut events, &mut triggers).unwrap_err();
        assert!(e.to_string().contains("not whole 2-byte"), "{e}");
        d.decode(&packet(&[0x2805], "evt3"), &mut events, &mut triggers)
            .unwrap();
        assert_eq!(
            events,
            vec![Event {
                t: 4096 + 16,
                x: 5,
                y: 7,
                polarity: true
            }]
        );
        let e = d
            .decode(&packet(&[0x2805], "evt4"), &mut events, &mut triggers)
            .unwrap_err();
        assert_eq!(
            e,
            MessageError::Encoding {
                encoding: "evt4".into()
            }
        );
        assert_eq!(events.len(), 1);
    }
}
