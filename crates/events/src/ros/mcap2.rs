//! The MCAP container (rosbag2's default storage since ROS 2 Iron), read with Foxglove's `mcap`
//! crate: the format's reference Rust reader, kept in step with the specification, with zstd
//! and lz4 chunks. Its sans-io linear reader is driven here with a record length limit (see
//! `record_limit`), which bounds every record, inside a chunk too, before any buffer is sized
//! by it: the crate's `RawMessageStream` (0.26) sets no limit for the records of a chunk and
//! reserved a damaged length (5 PB, found by fuzzing), which aborted the process. A file cut
//! short after its last whole message (the end magic missing) is an error, as for any
//! truncated file.
//!
//! The file is read in order, not through its summary: the summary is optional (a recording
//! that crashed has none), and every message is needed anyway. A channel's schema name is the
//! message type (`dvs_msgs/msg/EventArray`) and its message encoding says how to decode
//! (`cdr` from rosbag2, `ros1` from a converted ROS 1 bag).

use std::collections::HashMap;

use mcap::records::Record;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use super::{Collector, Place, RosError};

/// Scans the MCAP file `bytes` into `c`.
pub(crate) fn scan(bytes: &[u8], c: &mut Collector) -> Result<(), RosError> {
    if !bytes.starts_with(super::MCAP_MAGIC) {
        return Err(RosError::Container {
            offset: 0,
            what: "not an MCAP file: it does not start with the magic `\\x89MCAP0\\r\\n`".into(),
        });
    }
    // What the reader had read when a problem is found: `bytes.len() - rest.len()`.
    let broken = |rest: &[u8]| {
        let read_to = (bytes.len() - rest.len()) as u64;
        move |what: String| RosError::Mcap { read_to, what }
    };
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default().with_record_length_limit(record_limit(bytes.len())),
    );
    let mut rest = bytes;
    // Schema id -> name; channel id -> topic index in the collector (or the channel, until its
    // first message).
    let mut schemas: HashMap<u16, String> = HashMap::new();
    let mut channels: HashMap<u16, mcap::records::Channel> = HashMap::new();
    let mut topics: HashMap<u16, usize> = HashMap::new();
    let mut past_data_end = false;
    let mut ended = false;
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| broken(rest)(e.to_string()))? {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
            }
            LinearReadEvent::Record { opcode, data } => {
                // The summary repeats schemas and channels: read on to the end magic only.
                if past_data_end {
                    ended |= opcode == mcap::records::op::FOOTER;
                    continue;
                }
                match mcap::parse_record(opcode, data).map_err(|e| broken(rest)(e.to_string()))? {
                    Record::Schema { header, .. } => {
                        schemas.insert(header.id, header.name);
                    }
                    Record::Channel(channel) => {
                        channels.insert(channel.id, channel);
                    }
                    Record::Message { header, data } => {
                        let id = header.channel_id;
                        let topic = match topics.get(&id) {
                            Some(&topic) => topic,
                            None => {
                                let channel = channels.get(&id).ok_or_else(|| {
                                    broken(rest)(format!(
                                        "message {} refers to channel {id}, which the file has \
                                         not defined",
                                        header.sequence
                                    ))
                                })?;
                                let message_type = match channel.schema_id {
                                    0 => "(no schema)",
                                    sid => {
                                        schemas.get(&sid).map(String::as_str).ok_or_else(|| {
                                            broken(rest)(format!(
                                                "channel {id} ({}) refers to schema {sid}, which \
                                                 the file has not defined",
                                                channel.topic
                                            ))
                                        })?
                                    }
                                };
                                let topic = c.topic(
                                    &channel.topic,
                                    message_type,
                                    &channel.message_encoding,
                                );
                                topics.insert(id, topic);
                                topic
                            }
                        };
                        c.message(topic, header.log_time, &data, Place::Unknown)?;
                    }
                    Record::DataEnd(_) => past_data_end = true,
                    Record::Footer(_) => ended = true,
                    _ => {}
                }
            }
        }
    }
    if !ended {
        return Err(broken(rest)(
            "the file ends before its footer and end magic (cut short?)".into(),
        ));
    }
    Ok(())
}

/// The longest record accepted, in a chunk or not: sixteen times the file, at least 64 MiB, at
/// most 2 GiB (rosbag2 writes chunks of about a megabyte; a record is never longer than its
/// decompressed chunk, and a chunk this far beyond its file is a damaged size field).
fn record_limit(file_len: usize) -> usize {
    file_len.saturating_mul(16).clamp(64 << 20, 2 << 30)
}
