//! The bad-input matrix (see `bad_input.rs`) for the files of older setups: AEDAT 2.0 (jAER) and
//! AEDAT 3.1 (cAER), written here from iniVation's format descriptions.
//!
//! Neither format has a checksum, and AEDAT 3.1's packet headers have fields a flipped byte can
//! turn into another valid value (a packet of another type is skipped, an overflow counter moves
//! the last packet's time), so only the fields whose every change the format forbids must fail:
//! the version line, AEDAT 3.1's `#!END-HEADER`, `eventSize` and `eventTSOffset`. Every other
//! flip must give an error that locates it, or events, and never a panic or a large allocation.
//! AEDAT 2.0 declares no sizes at all (its sensor comes from the camera's name), so its 4 GiB row
//! is AEDAT 3.1's alone.

use evtac_events::Event;

use crate::bad_input::{
    Expect, Field, Matrix, Sample, events, evt_header_fields, find_once, with_matrix,
};

/// DAVIS240, the camera both samples name.
const WIDTH: u16 = 240;
const HEIGHT: u16 = 180;

/// A sample of an AEDAT 2.0 / 3.1 file (the sensor comes from the camera its header names).
fn legacy_sample(
    label: &'static str,
    bytes: Vec<u8>,
    header: Vec<Field>,
    valid_cuts: Vec<(usize, usize)>,
) -> Sample {
    Sample {
        label,
        file: "case.aedat",
        bytes,
        declare: None,
        valid_cuts,
        header,
    }
}

/// The rows every legacy format gets: the generic ones, a wrong version (`version` replaces the
/// version line's text), a timestamp going back, an x and a y outside the sensor (`outside`),
/// each in a file `build` writes; then the format's own rows (`more`).
fn legacy_matrix(
    build: fn(&[Event]) -> Sample,
    version: &[u8; 12],
    (x, y): (u16, u16),
    more: impl FnOnce(&mut Matrix<'_>, &Sample),
) {
    let good = events();
    with_matrix(|m| {
        let sample = build(&good);
        m.generic(&sample, &good);
        let mut bad = sample.bytes.clone();
        bad[..12].copy_from_slice(version);
        m.case(&sample, "wrong version", &bad, Expect::Error);
        bad_events(m, &sample, build, x, y);
        more(m, &sample);
    });
}

/// The event rows of the matrix: a timestamp going back, an x and a y outside the sensor
/// (`x`, `y`), each in a file `build` writes.
fn bad_events(m: &mut Matrix<'_>, sample: &Sample, build: fn(&[Event]) -> Sample, x: u16, y: u16) {
    let good = events();
    let mut back = good.clone();
    back[6].t = back[5].t - 5_000;
    m.case(
        sample,
        "timestamps going back",
        &build(&back).bytes,
        Expect::Error,
    );
    let mut outside = good.clone();
    outside[4].x = x;
    m.case(
        sample,
        "x outside the sensor",
        &build(&outside).bytes,
        Expect::Error,
    );
    let mut outside = good;
    outside[7].y = y;
    m.case(
        sample,
        "y outside the sensor",
        &build(&outside).bytes,
        Expect::Error,
    );
}

// ---------------------------------------------------------------------------------------------
// AEDAT 2.0
// ---------------------------------------------------------------------------------------------

const AEDAT2_HEADER: [(&str, bool); 3] = [
    ("#!AER-DAT2.0\r\n", true),
    ("# This is a raw AE data file - do not edit\r\n", false),
    (
        "# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n",
        false,
    ),
];

/// A jAER record: big-endian address and timestamp; `x` and `y` mirrored as jAER stores them.
fn aedat2_record(e: &Event) -> [u8; 8] {
    let x = u32::from(WIDTH - 1).wrapping_sub(u32::from(e.x)) & 0x3FF;
    let y = u32::from(HEIGHT - 1).wrapping_sub(u32::from(e.y)) & 0x1FF;
    let address = y << 22 | x << 12 | u32::from(e.polarity) << 11;
    let mut out = [0; 8];
    out[..4].copy_from_slice(&address.to_be_bytes());
    out[4..].copy_from_slice(&(e.t as u32).to_be_bytes());
    out
}

fn aedat2_sample(events: &[Event]) -> Sample {
    let (mut bytes, header, mut valid_cuts) = evt_header_fields(&AEDAT2_HEADER);
    // A file cut after any whole header line is a header without data; after a whole record,
    // the events before it.
    for (n, e) in events.iter().enumerate() {
        bytes.extend_from_slice(&aedat2_record(e));
        valid_cuts.push((bytes.len(), n + 1));
    }
    legacy_sample("AEDAT 2.0", bytes, header, valid_cuts)
}

#[test]
fn aedat2_bad_input_matrix() {
    // Addresses past the sensor: mirrored, an x address of 240 or more, a y of 180 or more.
    legacy_matrix(
        aedat2_sample,
        b"#!AER-DAT1.0",
        (u16::MAX, u16::MAX),
        |m, sample| {
            let mut bad = sample.bytes.clone();
            let chip = find_once(&bad, b"DAVIS240C");
            bad[chip..chip + 9].copy_from_slice(b"DVS128XYZ");
            m.case(
                sample,
                "a camera evtac does not decode",
                &bad,
                Expect::Error,
            );
        },
    );
}

// ---------------------------------------------------------------------------------------------
// AEDAT 3.1
// ---------------------------------------------------------------------------------------------

const AEDAT31_HEADER: [(&str, bool); 4] = [
    ("#!AER-DAT3.1\r\n", true),
    ("#Format: RAW\r\n", false),
    ("#Source 1: DAVIS240C\r\n", false),
    ("#!END-HEADER\r\n", true),
];

/// Packet types (libcaer `events/common.h`).
const SPECIAL: i16 = 0;
const POLARITY: i16 = 1;
const IMU6: i16 = 3;

/// A packet header: type, source 1, event size, TS offset 4, overflow, capacity, number, valid.
fn packet_header(kind: i16, size: i32, overflow: i32, capacity: i32, number: i32) -> Vec<u8> {
    let mut out = kind.to_le_bytes().to_vec();
    out.extend(1i16.to_le_bytes());
    for v in [size, 4, overflow, capacity, number, number] {
        out.extend(v.to_le_bytes());
    }
    out
}

/// The packet header's fields, and whether every change of one must make the file unreadable.
const PACKET_FIELDS: [(&str, std::ops::Range<usize>, bool); 8] = [
    ("eventType", 0..2, false),
    ("eventSource", 2..4, false),
    ("eventSize", 4..8, true),
    ("eventTSOffset", 8..12, true),
    ("eventTSOverflow", 12..16, false),
    ("eventCapacity", 16..20, false),
    ("eventNumber", 20..24, false),
    ("eventValid", 24..28, false),
];

/// Polarity packets of three events each, then an IMU6 sample and an external-input edge after
/// each of them (so that IMU and special packets are in every cut and every flip).
fn aedat31_sample(events: &[Event]) -> Sample {
    let (mut bytes, mut header, mut valid_cuts) = evt_header_fields(&AEDAT31_HEADER);
    // Before `#!END-HEADER` the header is incomplete: only the cut after it is valid.
    valid_cuts.retain(|&(at, _)| at == bytes.len());
    let packet = |bytes: &mut Vec<u8>, header: &mut Vec<Field>, kind, size, body: Vec<u8>| {
        let start = bytes.len();
        let number = (body.len() / size) as i32;
        bytes.extend(packet_header(kind, size as i32, 0, number, number));
        for (name, range, must_fail) in PACKET_FIELDS {
            header.push(Field {
                name: format!("packet at {start}: {name}"),
                range: start + range.start..start + range.end,
                must_fail,
            });
        }
        bytes.extend(body);
    };
    let mut n = 0;
    for chunk in events.chunks(3) {
        let mut body = Vec::new();
        for e in chunk {
            let data = u32::from(e.x) << 17 | u32::from(e.y) << 2 | u32::from(e.polarity) << 1 | 1;
            body.extend(data.to_le_bytes());
            body.extend((e.t as i32).to_le_bytes());
        }
        packet(&mut bytes, &mut header, POLARITY, 8, body);
        n += chunk.len();
        valid_cuts.push((bytes.len(), n));
        let t = chunk.last().unwrap().t as i32;
        let mut imu = 1u32.to_le_bytes().to_vec();
        imu.extend(t.to_le_bytes());
        for v in [0.0f32, 0.0, 1.0, 0.5, -0.5, 0.25, 30.0] {
            imu.extend(v.to_le_bytes());
        }
        packet(&mut bytes, &mut header, IMU6, 36, imu);
        valid_cuts.push((bytes.len(), n));
        let mut edge = (2u32 << 1 | 1).to_le_bytes().to_vec();
        edge.extend(t.to_le_bytes());
        packet(&mut bytes, &mut header, SPECIAL, 8, edge);
        valid_cuts.push((bytes.len(), n));
    }
    legacy_sample("AEDAT 3.1", bytes, header, valid_cuts)
}

#[test]
fn aedat31_bad_input_matrix() {
    legacy_matrix(
        aedat31_sample,
        b"#!AER-DAT3.0",
        (WIDTH, HEIGHT),
        |m, sample| {
            let text = String::from_utf8_lossy(&sample.bytes).into_owned();
            let bad = text
                .replacen("#Format: RAW", "#Format: LZ4", 1)
                .into_bytes();
            m.case(sample, "a compressed format", &bad, Expect::Error);

            // Packets that claim 2^31 - 1 events of 8 bytes (16 GiB) or 36 bytes, of a type evtac
            // decodes and of one it skips, behind the whole file.
            for (kind, size) in [(POLARITY, 8), (IMU6, 36), (2, 1 << 20)] {
                let mut bad = sample.bytes.clone();
                bad.extend(packet_header(kind, size, 0, i32::MAX, i32::MAX));
                bad.extend([0u8; 64]);
                let case = format!("a type-{kind} packet of 2^31 - 1 events of {size} bytes");
                m.case(sample, &case, &bad, Expect::Error);
            }
            let mut bad = sample.bytes.clone();
            bad.extend(packet_header(POLARITY, 8, 0, 3, 4));
            m.case(
                sample,
                "eventNumber above eventCapacity",
                &bad,
                Expect::Error,
            );
            let mut bad = sample.bytes.clone();
            bad.extend(packet_header(POLARITY, 8, -1, 0, 0));
            m.case(sample, "a negative eventTSOverflow", &bad, Expect::Error);
        },
    );
}
