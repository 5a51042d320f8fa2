//! Fuzzes the ROS 1 bag reader: the record and header-field parser, bz2 and lz4 chunks, the
//! connections, and the `dvs_msgs/EventArray`, `event_camera_msgs/EventPacket` and
//! `sensor_msgs/Imu` decoders behind them. Any outcome but a panic, a hang or a huge allocation
//! is fine.

#![no_main]

use evtac_formats::ros::fuzz_decode_rosbag;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    fuzz_decode_rosbag(data);
});
