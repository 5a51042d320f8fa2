//! The MCAP container (rosbag2's default storage since ROS 2 Iron), read with Foxglove's `mcap`
//! crate: the format's reference Rust reader, kept in step with the specification, with zstd
//! and lz4 chunks. Its streaming reader checks each record's length against the file's
//! (records are never longer than the file), decompresses a chunk as its records are read
//! rather than reserving the declared size, and reports a file cut short after its last whole
//! message (the end magic is missing), which is an error here as for any truncated file.
//!
//! The file is read in order, not through its summary: the summary is optional (a recording
//! that crashed has none), and every message is needed anyway. A channel's schema name is the
//! message type (`dvs_msgs/msg/EventArray`) and its message encoding says how to decode
//! (`cdr` from rosbag2, `ros1` from a converted ROS 1 bag).

use std::collections::HashMap;

use mcap::read::RawMessageStream;

use super::{Collector, Place, RosError};

/// Scans the MCAP file `bytes` into `c`.
pub(crate) fn scan(bytes: &[u8], c: &mut Collector) -> Result<(), RosError> {
    if !bytes.starts_with(super::MCAP_MAGIC) {
        return Err(RosError::Container {
            offset: 0,
            what: "not an MCAP file: it does not start with the magic `\\x89MCAP0\\r\\n`".into(),
        });
    }
    let broken = |e: mcap::McapError| RosError::Mcap {
        what: e.to_string(),
    };
    let mut stream = RawMessageStream::new(bytes).map_err(broken)?;
    // Channel id -> topic index in the collector.
    let mut channels: HashMap<u16, usize> = HashMap::new();
    while let Some(message) = stream.next() {
        let message = message.map_err(broken)?;
        let id = message.header.channel_id;
        let topic = match channels.get(&id) {
            Some(&topic) => topic,
            None => {
                let channel = stream.get_channel(id).ok_or_else(|| RosError::Mcap {
                    what: format!(
                        "message {} refers to channel {id}, which the file has not defined",
                        message.header.sequence
                    ),
                })?;
                let message_type = channel
                    .schema
                    .as_ref()
                    .map_or("(no schema)", |s| s.name.as_str());
                let topic = c.topic(&channel.topic, message_type, &channel.message_encoding);
                channels.insert(id, topic);
                topic
            }
        };
        c.message(
            topic,
            message.header.log_time,
            &message.data,
            Place::Unknown,
        )?;
    }
    Ok(())
}
