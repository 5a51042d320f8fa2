//! The bad-input matrix (`bad_input.rs`) over the container formats other tools write: NPZ
//! (a zip of NPY members), ROS 1 bags and ROS 2 MCAP. Each gets the generic cases (empty, cut
//! at every byte, every byte of its magic and index fields flipped) and the cases of its own:
//! a member or topic missing, a wrong dtype, a member claiming 4 GiB, an unknown packet
//! encoding. Every cut of these is an error: a zip's directory, a bag's index and an MCAP's
//! footer are at the end, so a cut file is never read as a shorter one.
//!
//! The NPZ files are built here with the `zip` crate around evtac's own NPY (numpy's reading of
//! both is tested in `npy.rs` and `other_tools.rs`); the bags are written by the `rosbags`
//! package (skipped without Python outside CI, as `ros.rs`).

use std::io::{Cursor, Write};

use evtac_events::{Event, Resolution};
use evtac_formats::npy::NpyWriter;
use evtac_testkit::run_python;
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

use crate::bad_input::{Expect, Field, SENSOR, Sample, events, find_once, with_matrix};

/// A zip archive of `members` (name, bytes), each stored or deflated as `np.savez` and
/// `np.savez_compressed` write them.
fn zip_bytes(members: &[(&str, Vec<u8>)], method: CompressionMethod) -> Vec<u8> {
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default().compression_method(method);
    for (name, bytes) in members {
        zip.start_file(*name, options).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// `events` as one NPY record array.
fn record_npy(events: &[Event]) -> Vec<u8> {
    let mut writer = NpyWriter::new(Cursor::new(Vec::new())).unwrap();
    writer.write_events(events).unwrap();
    writer.finish().unwrap().into_inner()
}

/// A 1-D NPY array of `descr` (`<i8`, `<u2`, `|b1`, ...) holding `values`, each already in
/// that type's little-endian bytes.
fn column_npy(descr: &str, values: &[Vec<u8>]) -> Vec<u8> {
    let dict = format!(
        "{{'descr': '{descr}', 'fortran_order': False, 'shape': ({},), }}",
        values.len()
    );
    let mut header = dict.into_bytes();
    // The header is padded with spaces to a multiple of 64 bytes, ending in a newline.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(b' ');
    }
    header.push(b'\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&u16::try_from(header.len()).unwrap().to_le_bytes());
    bytes.extend_from_slice(&header);
    values.iter().for_each(|v| bytes.extend_from_slice(v));
    bytes
}

/// `np.savez(f, t=t, x=x, y=y, p=p)` of `events`: `t` int64, `x`/`y` uint16, `p` bool.
fn per_field_members(events: &[Event]) -> Vec<(&'static str, Vec<u8>)> {
    let column = |descr, f: &dyn Fn(&Event) -> Vec<u8>| {
        column_npy(descr, &events.iter().map(f).collect::<Vec<_>>())
    };
    vec![
        ("t.npy", column("<i8", &|e| e.t.to_le_bytes().to_vec())),
        ("x.npy", column("<u2", &|e| e.x.to_le_bytes().to_vec())),
        ("y.npy", column("<u2", &|e| e.y.to_le_bytes().to_vec())),
        ("p.npy", column("|b1", &|e| vec![u8::from(e.polarity)])),
    ]
}

/// The zip fields that locate every member: the signatures of each local header, of each
/// central directory entry and of the end record, and the end record's directory offset. A
/// changed byte in any of them must make the archive unreadable.
fn zip_fields(bytes: &[u8]) -> Vec<Field> {
    let mut fields = Vec::new();
    let signatures: [(&str, &[u8]); 3] = [
        ("local header signature", b"PK\x03\x04"),
        ("central directory signature", b"PK\x01\x02"),
        ("end record signature", b"PK\x05\x06"),
    ];
    for (name, signature) in signatures {
        for (i, w) in bytes.windows(4).enumerate() {
            if w == signature {
                fields.push(Field {
                    name: format!("{name} at byte {i}"),
                    range: i..i + 4,
                    must_fail: true,
                });
            }
        }
    }
    let end = find_once(bytes, b"PK\x05\x06");
    fields.push(Field {
        name: "end record's directory offset".into(),
        range: end + 16..end + 20,
        must_fail: true,
    });
    fields
}

#[test]
fn npz_bad_input_matrix() {
    let good = events();
    let samples = [
        (
            "NPZ, one record array",
            zip_bytes(
                &[("events.npy", record_npy(&good))],
                CompressionMethod::Stored,
            ),
        ),
        (
            "NPZ, one array per field",
            zip_bytes(&per_field_members(&good), CompressionMethod::Stored),
        ),
        (
            "NPZ, one array per field, deflated",
            zip_bytes(&per_field_members(&good), CompressionMethod::Deflated),
        ),
    ];
    with_matrix(|m| {
        for (label, bytes) in samples {
            let sample = Sample {
                label,
                file: "case.npz",
                header: zip_fields(&bytes),
                valid_cuts: vec![],
                bytes,
                declare: Some(SENSOR),
            };
            m.generic(&sample, &good);
        }
        let sample = Sample {
            label: "NPZ",
            file: "case.npz",
            header: vec![],
            valid_cuts: vec![],
            bytes: vec![],
            declare: Some(SENSOR),
        };
        let stored = |members: &[(&str, Vec<u8>)]| zip_bytes(members, CompressionMethod::Stored);
        let mut fields = per_field_members(&good);
        fields.retain(|(name, _)| *name != "p.npy");
        m.case(&sample, "member p missing", &stored(&fields), Expect::Error);
        let mut fields = per_field_members(&good);
        fields[1].1 = column_npy(
            "<f4",
            &good
                .iter()
                .map(|e| f32::from(e.x).to_le_bytes().to_vec())
                .collect::<Vec<_>>(),
        );
        m.case(&sample, "x as float32", &stored(&fields), Expect::Error);
        let mut fields = per_field_members(&good);
        fields[2].1 = column_npy("<u2", &vec![vec![0, 0]; 9]);
        m.case(
            &sample,
            "y one value short",
            &stored(&fields),
            Expect::Error,
        );
        // A member whose NPY header claims 4 Gi records (its data is 10).
        let mut fields = per_field_members(&good);
        let t = &fields[0].1;
        let data = t[10 + usize::from(u16::from_le_bytes([t[8], t[9]]))..].to_vec();
        let mut claimed = column_npy("<i8", &[]);
        let dict = "{'descr': '<i8', 'fortran_order': False, 'shape': (4294967296,), }";
        claimed = crate::common::with_dict(&claimed, dict);
        claimed.extend_from_slice(&data);
        fields[0].1 = claimed;
        m.case(
            &sample,
            "t claiming 4 Gi values",
            &stored(&fields),
            Expect::Error,
        );
        let mut outside = good.clone();
        outside[3].x = 64;
        m.case(
            &sample,
            "x outside the sensor",
            &stored(&per_field_members(&outside)),
            Expect::Error,
        );
        let mut back = good.clone();
        back[6].t = back[5].t - 1;
        m.case(
            &sample,
            "timestamps going back",
            &stored(&per_field_members(&back)),
            Expect::Error,
        );
        m.case(
            &sample,
            "a zip of no NPY",
            &stored(&[("notes.txt", b"hello".to_vec())]),
            Expect::Error,
        );
    });
}

// ---------------------------------------------------------------------------------------------
// ROS bags
// ---------------------------------------------------------------------------------------------

/// Writes the matrix's bags into `argv[1]` with `rosbags`: `ok.bag` and `ok.mcap` (one
/// `dvs_msgs/EventArray` message of the matrix's 10 events on the 64 x 32 sensor, and two
/// `sensor_msgs/Imu`), `evt4.mcap` (an `EventPacket` of an unknown encoding) and
/// `no_events.bag` (IMU only).
const WRITE_BAGS: &str = r#"
import sys, os
import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Writer as Writer2
from rosbags.rosbag2.enums import StoragePlugin
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

d = sys.argv[1]
events = [tuple(int(v) for v in e.split(':')) for e in sys.argv[2].split(',')]
ARRAY = "std_msgs/Header header\nuint32 height\nuint32 width\ndvs_msgs/Event[] events\n"
PACKET = ("std_msgs/Header header\nuint32 height\nuint32 width\nuint64 seq\nuint64 time_base\n"
          "string encoding\nbool is_bigendian\nuint8[] events\n")

def store(ros1):
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    event = "uint16 x\nuint16 y\n" + ("time" if ros1 else "builtin_interfaces/Time") + " ts\nbool polarity\n"
    types = {}
    types.update(get_types_from_msg(event, 'dvs_msgs/msg/Event'))
    types.update(get_types_from_msg(ARRAY, 'dvs_msgs/msg/EventArray'))
    types.update(get_types_from_msg(PACKET, 'event_camera_msgs/msg/EventPacket'))
    ts.register(types)
    return ts

def messages(ts, ros1):
    T = ts.types['builtin_interfaces/msg/Time']
    H = ts.types['std_msgs/msg/Header']
    def header(ns):
        s, n = divmod(ns, 10**9)
        return H(seq=0, stamp=T(sec=s, nanosec=n), frame_id='cam') if ros1 else H(stamp=T(sec=s, nanosec=n), frame_id='cam')
    Ev = ts.types['dvs_msgs/msg/Event']
    evs = [Ev(x=x, y=y, ts=T(sec=t // 10**6, nanosec=t % 10**6 * 1000), polarity=bool(p)) for t, x, y, p in events]
    last = events[-1][0] * 1000
    arr = ts.types['dvs_msgs/msg/EventArray'](header=header(last), height=32, width=64, events=evs)
    V = ts.types['geometry_msgs/msg/Vector3']; Q = ts.types['geometry_msgs/msg/Quaternion']
    imu = []
    for k in range(2):
        ns = events[0][0] * 1000 + k * 1_250_000
        imu.append((ns, ts.types['sensor_msgs/msg/Imu'](
            header=header(ns), orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=np.zeros(9), angular_velocity=V(x=0.0, y=0.0, z=0.0),
            angular_velocity_covariance=np.zeros(9), linear_acceleration=V(x=0.0, y=0.0, z=9.8),
            linear_acceleration_covariance=np.zeros(9))))
    return (last, arr), imu

ts1, ts2 = store(True), store(False)
for name, with_events in [('ok.bag', True), ('no_events.bag', False)]:
    ev, imu = messages(ts1, True)
    with Writer1(os.path.join(d, name)) as w:
        ci = w.add_connection('/dvs/imu', 'sensor_msgs/msg/Imu', typestore=ts1)
        ce = w.add_connection('/dvs/events', 'dvs_msgs/msg/EventArray', typestore=ts1) if with_events else None
        for t, m in imu:
            w.write(ci, t, ts1.serialize_ros1(m, 'sensor_msgs/msg/Imu'))
        if with_events:
            w.write(ce, ev[0], ts1.serialize_ros1(ev[1], 'dvs_msgs/msg/EventArray'))
for name, packet in [('ok', False), ('evt4', True)]:
    ev, imu = messages(ts2, False)
    w = Writer2(os.path.join(d, name), version=9, storage_plugin=StoragePlugin.MCAP)
    with w:
        ci = w.add_connection('/dvs/imu', 'sensor_msgs/msg/Imu', typestore=ts2)
        kind = 'event_camera_msgs/msg/EventPacket' if packet else 'dvs_msgs/msg/EventArray'
        ce = w.add_connection('/dvs/events', kind, typestore=ts2)
        for t, m in imu:
            w.write(ci, t, ts2.serialize_cdr(m, 'sensor_msgs/msg/Imu'))
        if packet:
            Pkt = ts2.types[kind]
            m = Pkt(header=ev[1].header, height=32, width=64, seq=0, time_base=0, encoding='evt4',
                    is_bigendian=False, events=np.zeros(8, dtype=np.uint8))
            w.write(ce, ev[0], ts2.serialize_cdr(m, kind))
        else:
            w.write(ce, ev[0], ts2.serialize_cdr(ev[1], kind))
    os.rename(os.path.join(d, name, name + '.mcap'), os.path.join(d, name + '.mcap'))
"#;

/// The matrix's bags, written into a temporary folder (`None`: no Python outside CI).
fn bags() -> Option<tempfile::TempDir> {
    let dir = tempfile::tempdir().unwrap();
    let list: Vec<String> = events()
        .iter()
        .map(|e| format!("{}:{}:{}:{}", e.t, e.x, e.y, u8::from(e.polarity)))
        .collect();
    run_python(WRITE_BAGS, &[dir.path().to_str().unwrap(), &list.join(",")])?;
    Some(dir)
}

/// A field of `len` bytes after the only occurrence of `key` in `bytes` (a ROS 1 record
/// header's `key=value`).
fn after(bytes: &[u8], name: &str, key: &[u8], len: usize, must_fail: bool) -> Field {
    let at = find_once(bytes, key) + key.len();
    Field {
        name: name.into(),
        range: at..at + len,
        must_fail,
    }
}

#[test]
fn rosbag_bad_input_matrix() {
    let Some(dir) = bags() else { return };
    let good = events();
    let bytes = std::fs::read(dir.path().join("ok.bag")).unwrap();
    let sample = Sample {
        label: "ROS 1 bag",
        file: "case.bag",
        header: vec![
            Field {
                name: "magic".into(),
                range: 0..13,
                must_fail: true,
            },
            after(&bytes, "bag header's index_pos", b"index_pos=", 8, true),
        ],
        valid_cuts: vec![],
        bytes,
        declare: None,
    };
    let no_events = std::fs::read(dir.path().join("no_events.bag")).unwrap();
    with_matrix(|m| {
        m.generic(&sample, &good);
        m.case(&sample, "no event topic", &no_events, Expect::Error);
        let mut declared = sample.bytes.clone();
        declared[..13].copy_from_slice(b"#ROSBAG V1.2\n");
        m.case(&sample, "version 1.2", &declared, Expect::Error);
    });
}

#[test]
fn mcap_bad_input_matrix() {
    let Some(dir) = bags() else { return };
    let good = events();
    let bytes = std::fs::read(dir.path().join("ok.mcap")).unwrap();
    let end = bytes.len();
    let sample = Sample {
        label: "MCAP",
        file: "case.mcap",
        header: vec![
            Field {
                name: "leading magic".into(),
                range: 0..8,
                must_fail: true,
            },
            Field {
                name: "trailing magic".into(),
                range: end - 8..end,
                must_fail: true,
            },
        ],
        valid_cuts: vec![],
        bytes,
        declare: Some(Resolution::new(64, 32)),
    };
    let evt4 = std::fs::read(dir.path().join("evt4.mcap")).unwrap();
    with_matrix(|m| {
        m.generic(&sample, &good);
        m.case(
            &sample,
            "unknown EventPacket encoding",
            &evt4,
            Expect::Error,
        );
    });
}
