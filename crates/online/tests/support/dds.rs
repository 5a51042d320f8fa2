//! DDS on loopback for the ROS 2 tests: Cyclone's configuration, RustDDS's options, and a domain
//! id per test and run.

use evtac_online::ros2::Ros2Options;
use std::net::{IpAddr, Ipv4Addr};
use std::time::{SystemTime, UNIX_EPOCH};

/// Cyclone DDS on loopback only, discovering peers by unicast to 127.0.0.1 (participant indices
/// up to 20 on this host).
pub const CYCLONE_LOOPBACK: &str = "<CycloneDDS><Domain id=\"any\"><General><Interfaces>\
     <NetworkInterface name=\"lo\"/></Interfaces><AllowMulticast>false</AllowMulticast>\
     </General><Discovery><ParticipantIndex>auto</ParticipantIndex>\
     <MaxAutoParticipantIndex>20</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/>\
     </Peers></Discovery></Domain></CycloneDDS>";

/// A domain id for this test in this run: random per run (so that runs at the same time, or
/// another engineer's, do not cross-talk), and different for each `test` of a run (the tests
/// run in parallel). 1..=230: never ROS's default 0, and 231 is left to the CLI's test of a
/// domain without subscribers.
pub fn random_domain(test: u32) -> u16 {
    static RUN: std::sync::OnceLock<u32> = std::sync::OnceLock::new();
    let run = *RUN.get_or_init(|| {
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .unwrap()
            .subsec_nanos();
        (nanos ^ std::process::id().rotate_left(16)) % 230
    });
    // 61 is prime to 230: distinct tests get distinct domains.
    1 + ((run + test * 61) % 230) as u16
}

pub fn loopback_options(domain: u16, frame_id: &str) -> Ros2Options {
    Ros2Options {
        topic: "/contact_angle".into(),
        frame_id: frame_id.into(),
        domain,
        interfaces: vec![IpAddr::V4(Ipv4Addr::LOCALHOST)],
    }
}
