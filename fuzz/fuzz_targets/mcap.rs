//! Fuzzes the ROS 2 MCAP reader: the `mcap` crate's container reader (records, zstd and lz4
//! chunks) as evtac drives it, and the CDR decoders of `dvs_msgs/msg/EventArray`,
//! `event_camera_msgs/msg/EventPacket` (`evt3`, `mono`) and `sensor_msgs/msg/Imu`. Any outcome
//! but a panic, a hang or a huge allocation is fine.

#![no_main]

use evtac_formats::ros::fuzz_decode_mcap;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    fuzz_decode_mcap(data);
});
