//! AEDAT 4.0 reader and writer: the real DVXplorer recording, interop both ways with
//! dv-processing 2.0.4 (files and the network protocol), chunk invariance, and bad input.

use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

use evtac_events::{Event, ImuSample, Resolution, Trigger};
use evtac_formats::aedat::{
    AedatChunk, AedatError, AedatReader, AedatWriter, Compression, MAGIC, StreamKind, WriterConfig,
};
use proptest::prelude::*;
use support::{Dribble, xorshift};

mod support;

/// Everything a reader produced, packet by packet.
#[derive(Debug, Default, Clone, PartialEq)]
struct Decoded {
    /// (stream id, byte offset) per packet.
    packets: Vec<(i32, u64)>,
    events: Vec<Event>,
    imu: Vec<ImuSample>,
    triggers: Vec<Trigger>,
}

impl Decoded {
    fn push(&mut self, c: &AedatChunk<'_>) {
        self.packets.push((c.stream_id, c.offset));
        self.events.extend_from_slice(c.events);
        self.imu.extend_from_slice(c.imu);
        self.triggers.extend_from_slice(c.triggers);
    }
}

fn decode<R: Read>(mut reader: AedatReader<R>) -> Result<Decoded, AedatError> {
    let mut out = Decoded::default();
    while let Some(c) = reader.next_chunk()? {
        out.push(&c);
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// The real recording
// ---------------------------------------------------------------------------------------------

const DVXPLORER: &str = "dvxplorer_320x240_imu.aedat4";

#[test]
fn dvxplorer_fixture_matches_expected_figures() {
    let Some(path) = evtac_testkit::real_fixture(DVXPLORER) else {
        return;
    };
    let reader = AedatReader::open(&path).unwrap();
    assert_eq!(reader.resolution(), Some(Resolution::new(320, 240)));
    assert_eq!(reader.source(), Some("DVXplorer_DXB00010"));
    assert_eq!(reader.compression(), Compression::Lz4);
    let kinds: Vec<_> = reader
        .header()
        .streams
        .iter()
        .map(|s| s.kind.clone())
        .collect();
    assert_eq!(
        kinds,
        [StreamKind::Events, StreamKind::Imu, StreamKind::Triggers]
    );
    let d = decode(reader).unwrap();

    assert_eq!(d.events.len(), 111_954);
    assert_eq!(d.events[0].t, 1_605_537_493_718_345);
    assert_eq!(d.events.last().unwrap().t, 1_605_537_494_308_262);
    assert_eq!(d.events.iter().filter(|e| e.polarity).count(), 55_023);
    assert!(d.events.iter().all(|e| e.x < 320 && e.y < 240));

    assert_eq!(d.imu.len(), 475);
    let first = d.imu[0];
    assert_eq!(first.t, 1_605_537_493_718_788);
    assert_eq!(
        first.accelerometer,
        [0.126_342_77, -0.995_117_2, -0.393_066_4]
    );
    assert_eq!(
        first.accelerometer.map(f64::from),
        [0.1263427734375, -0.9951171875, -0.39306640625]
    );
    assert_eq!(
        first.gyroscope.map(f64::from),
        [0.4119872748851776, 0.0762939453125, -0.4119872748851776]
    );
    assert_eq!(f64::from(first.temperature), 38.15234375);
    assert_eq!(d.imu.last().unwrap().t, 1_605_537_494_307_448);
    assert!(d.triggers.is_empty());
}

#[test]
fn read_size_does_not_change_the_output() {
    let Some(path) = evtac_testkit::real_fixture(DVXPLORER) else {
        return;
    };
    let bytes = std::fs::read(path).unwrap();
    let whole = decode(AedatReader::from_slice(&bytes).unwrap()).unwrap();
    for step in [1, 7, 65536] {
        let r = AedatReader::new(Dribble::new(&bytes, step)).unwrap();
        assert!(
            decode(r).unwrap() == whole,
            "read size {step} changed the output"
        );
    }
}

#[test]
fn events_iterator_yields_every_event() {
    let Some(path) = evtac_testkit::real_fixture(DVXPLORER) else {
        return;
    };
    let reader = AedatReader::open(&path).unwrap();
    let events: Vec<Event> = reader.into_events().collect::<Result<_, _>>().unwrap();
    let whole = decode(AedatReader::open(&path).unwrap()).unwrap();
    assert_eq!(events, whole.events);
}

// ---------------------------------------------------------------------------------------------
// Our writer
// ---------------------------------------------------------------------------------------------

/// Deterministic test data (xorshift, seeded): `n` events on `res` with increasing timestamps
/// (repeats included), and IMU samples at 1 kHz over the same span.
fn synthetic(n: usize, res: Resolution, seed: u64) -> (Vec<Event>, Vec<ImuSample>) {
    let mut next = xorshift(seed);
    let mut t = 1_700_000_000_000_000i64;
    let events: Vec<Event> = (0..n)
        .map(|_| {
            t += (next() % 4) as i64; // 0..=3 us: bursts with equal timestamps
            Event {
                t,
                x: (next() % u64::from(res.width)) as u16,
                y: (next() % u64::from(res.height)) as u16,
                polarity: next().is_multiple_of(2),
            }
        })
        .collect();
    let t0 = events.first().map_or(0, |e| e.t);
    let t1 = events.last().map_or(0, |e| e.t);
    let mut f = move || (next() % 2_000_001) as f32 / 1000.0 - 1000.0;
    let imu = (t0..=t1)
        .step_by(1000)
        .map(|t| ImuSample {
            t,
            accelerometer: [f(), f(), f()],
            gyroscope: [f(), f(), f()],
            temperature: f(),
        })
        .collect();
    (events, imu)
}

fn write_file(
    path: &Path,
    compression: Compression,
    events: &[Event],
    imu: &[ImuSample],
    res: Resolution,
) {
    let config = WriterConfig {
        resolution: res,
        source_name: "DVXplorer_EVTAC01".into(),
        compression,
    };
    let mut w = AedatWriter::create(path, config).unwrap();
    // Interleave in uneven slices, as a converter would.
    let (mut i, mut j) = (0, 0);
    while i < events.len() || j < imu.len() {
        let ei = (i + 1777).min(events.len());
        w.write_events(&events[i..ei]).unwrap();
        i = ei;
        let until = events.get(i).map_or(i64::MAX, |e| e.t);
        let jj = j + imu[j..].iter().take_while(|s| s.t < until).count();
        w.write_imu(&imu[j..jj]).unwrap();
        j = jj;
    }
    w.finish().unwrap();
}

const ALL: [Compression; 3] = [Compression::None, Compression::Lz4, Compression::Zstd];

#[test]
fn writer_round_trips_and_is_deterministic() {
    let res = Resolution::new(640, 480);
    let (events, imu) = synthetic(20_000, res, 42);
    let dir = tempfile::tempdir().unwrap();
    for c in ALL {
        let a = dir.path().join(format!("a_{c}.aedat4"));
        let b = dir.path().join(format!("b_{c}.aedat4"));
        write_file(&a, c, &events, &imu, res);
        write_file(&b, c, &events, &imu, res);
        assert_eq!(
            std::fs::read(&a).unwrap(),
            std::fs::read(&b).unwrap(),
            "{c}"
        );

        let reader = AedatReader::open(&a).unwrap();
        assert_eq!(reader.compression(), c);
        assert_eq!(reader.resolution(), Some(res));
        assert_eq!(reader.source(), Some("DVXplorer_EVTAC01"));
        assert!(reader.header().data_table_position.is_some(), "{c}");
        let d = decode(reader).unwrap();
        assert_eq!(d.events, events, "{c}");
        assert_eq!(d.imu, imu, "{c}");
        // Bounded packets.
        assert!(d.packets.len() >= events.len() / evtac_formats::aedat::EVENTS_PER_PACKET);
    }
}

#[test]
fn writer_without_seek_writes_no_data_table() {
    let res = Resolution::new(64, 48);
    let (events, imu) = synthetic(5000, res, 3);
    let mut w = AedatWriter::new(Vec::new(), WriterConfig::new(res, "cam")).unwrap();
    w.write_events(&events).unwrap();
    w.write_imu(&imu).unwrap();
    let bytes = w.finish().unwrap();
    let reader = AedatReader::from_slice(&bytes).unwrap();
    assert_eq!(reader.header().data_table_position, None);
    let d = decode(reader).unwrap();
    assert_eq!((d.events, d.imu), (events, imu));
}

#[test]
fn writer_rejects_bad_events() {
    let res = Resolution::new(10, 10);
    let mut w = AedatWriter::new(Vec::new(), WriterConfig::new(res, "cam")).unwrap();
    let e = |t, x, y| Event {
        t,
        x,
        y,
        polarity: true,
    };
    assert!(matches!(
        w.write_events(&[e(5, 10, 0)]),
        Err(AedatError::InvalidInput { .. })
    ));
    w.write_events(&[e(5, 9, 9)]).unwrap();
    let err = w.write_events(&[e(4, 0, 0)]).unwrap_err();
    assert!(err.to_string().contains("event 1"), "{err}");
}

// ---------------------------------------------------------------------------------------------
// Interop with dv-processing
// ---------------------------------------------------------------------------------------------

/// dv-processing writes events and IMU (seeded numpy data) and dumps the same data raw:
/// events `<i8 t, <i2 x, <i2 y, u1 p` and IMU `<i8 t` + 7 `<f4` (temperature, acc, gyro).
const PY_DV_WRITES: &str = r#"
import sys, numpy as np, dv_processing as dv
out, name = sys.argv[1], sys.argv[2]
rng = np.random.default_rng(2024)
n = 12000
t = 1_600_000_000_000_000 + np.cumsum(rng.integers(0, 5, n))
x = rng.integers(0, 640, n); y = rng.integers(0, 480, n); p = rng.integers(0, 2, n)
m = 300
ti = np.linspace(t[0], t[-1], m).astype(np.int64)
f = rng.uniform(-500, 500, (m, 7)).astype(np.float32)
cfg = dv.io.MonoCameraWriter.Config("DVXplorer_PY")
cfg.compression = getattr(dv.CompressionType, name)
cfg.addEventStream((640, 480))
cfg.addImuStream()
w = dv.io.MonoCameraWriter(f"{out}/dv_{name}.aedat4", cfg)
w.setPackagingCount(25)
j = 0
for start in range(0, n, 1000):
    s = dv.EventStore()
    for i in range(start, min(n, start + 1000)):
        s.push_back(int(t[i]), int(x[i]), int(y[i]), bool(p[i]))
    w.writeEvents(s)
    while j < m and ti[j] <= t[min(n, start + 1000) - 1]:
        a = [float(v) for v in f[j]]
        w.writeImu(dv.IMU(int(ti[j]), a[0], a[1], a[2], a[3], a[4], a[5], a[6], 0.0, 0.0, 0.0))
        j += 1
del w
ev = np.zeros(n, dtype=[("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")])
ev["t"], ev["x"], ev["y"], ev["p"] = t, x, y, p
ev.tofile(f"{out}/dv_{name}.events")
im = np.zeros(j, dtype=[("t", "<i8"), ("f", "<f4", 7)])
im["t"], im["f"] = ti[:j], f[:j]
im.tofile(f"{out}/dv_{name}.imu")
"#;

/// dv-processing reads a file and dumps it in the raw layout above; prints camera name,
/// resolution and which streams it found.
const PY_DV_READS: &str = r#"
import sys, numpy as np, dv_processing as dv
path, out = sys.argv[1], sys.argv[2]
r = dv.io.MonoCameraRecording(path)
res = r.getEventResolution()
print(r.getCameraName(), f"{res[0]}x{res[1]}", r.isEventStreamAvailable(), r.isImuStreamAvailable())
evs = []
while True:
    b = r.getNextEventBatch()
    if b is None:
        break
    evs.append(b.numpy())
e = np.concatenate(evs) if evs else np.zeros(0, dtype=[("timestamp", "<i8"), ("x", "<i2"), ("y", "<i2"), ("polarity", "i1")])
ev = np.zeros(len(e), dtype=[("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")])
ev["t"], ev["x"], ev["y"], ev["p"] = e["timestamp"], e["x"], e["y"], e["polarity"]
ev.tofile(out + ".events")
rows = []
while True:
    b = r.getNextImuBatch()
    if b is None:
        break
    rows += [(s.timestamp, [s.temperature, s.accelerometerX, s.accelerometerY, s.accelerometerZ, s.gyroscopeX, s.gyroscopeY, s.gyroscopeZ]) for s in b]
im = np.zeros(len(rows), dtype=[("t", "<i8"), ("f", "<f4", 7)])
for i, (t, f) in enumerate(rows):
    im["t"][i] = t
    im["f"][i] = f
im.tofile(out + ".imu")
"#;

fn read_raw_events(path: &Path) -> Vec<Event> {
    let b = std::fs::read(path).unwrap();
    b.chunks_exact(13)
        .map(|r| Event {
            t: i64::from_le_bytes(r[0..8].try_into().unwrap()),
            x: u16::from_le_bytes(r[8..10].try_into().unwrap()),
            y: u16::from_le_bytes(r[10..12].try_into().unwrap()),
            polarity: r[12] != 0,
        })
        .collect()
}

fn read_raw_imu(path: &Path) -> Vec<ImuSample> {
    let b = std::fs::read(path).unwrap();
    b.chunks_exact(36)
        .map(|r| {
            let f = |i: usize| f32::from_le_bytes(r[8 + 4 * i..12 + 4 * i].try_into().unwrap());
            ImuSample {
                t: i64::from_le_bytes(r[0..8].try_into().unwrap()),
                temperature: f(0),
                accelerometer: [f(1), f(2), f(3)],
                gyroscope: [f(4), f(5), f(6)],
            }
        })
        .collect()
}

#[test]
fn files_written_by_dv_processing_decode_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    for name in ["NONE", "LZ4", "LZ4_HIGH", "ZSTD", "ZSTD_HIGH"] {
        if evtac_testkit::run_python(PY_DV_WRITES, &[out, name]).is_none() {
            return;
        }
        let base = dir.path().join(format!("dv_{name}"));
        let reader = AedatReader::open(base.with_extension("aedat4")).unwrap();
        assert_eq!(reader.compression().name(), name);
        assert_eq!(reader.resolution(), Some(Resolution::new(640, 480)));
        assert_eq!(reader.source(), Some("DVXplorer_PY"));
        let d = decode(reader).unwrap();
        let events = read_raw_events(&base.with_extension("events"));
        let imu = read_raw_imu(&base.with_extension("imu"));
        assert_eq!(events.len(), 12_000);
        assert_eq!(imu.len(), 300);
        assert!(d.events == events, "{name}: events differ");
        assert!(d.imu == imu, "{name}: IMU differs");
    }
}

#[test]
fn files_we_write_read_back_exactly_in_dv_processing() {
    let res = Resolution::new(346, 260);
    let (events, imu) = synthetic(30_000, res, 7);
    let dir = tempfile::tempdir().unwrap();
    for c in ALL {
        let path = dir.path().join(format!("ours_{c}.aedat4"));
        write_file(&path, c, &events, &imu, res);
        let dump = dir.path().join(format!("dump_{c}"));
        let Some(stdout) = evtac_testkit::run_python(
            PY_DV_READS,
            &[path.to_str().unwrap(), dump.to_str().unwrap()],
        ) else {
            return;
        };
        assert_eq!(stdout.trim(), "DVXplorer_EVTAC01 346x260 True True", "{c}");
        let back = read_raw_events(&dump.with_extension("events"));
        assert_eq!(back.len(), events.len(), "{c}");
        assert!(back == events, "{c}: dv-processing read different events");
        let back_imu = read_raw_imu(&dump.with_extension("imu"));
        assert_eq!(back_imu.len(), imu.len(), "{c}");
        assert!(
            back_imu == imu,
            "{c}: dv-processing read different IMU samples"
        );
    }
}

/// Serves seeded events (and then exits) with `dv.io.NetworkWriter` on 127.0.0.1:PORT, after
/// dumping them raw; prints `ready` once listening.
const PY_NETWORK: &str = r#"
import sys, time, numpy as np, dv_processing as dv
port, out, name = int(sys.argv[1]), sys.argv[2], sys.argv[3]
rng = np.random.default_rng(99)
n = 5000
t = 1_650_000_000_000_000 + np.cumsum(rng.integers(0, 3, n))
x = rng.integers(0, 320, n); y = rng.integers(0, 240, n); p = rng.integers(0, 2, n)
ev = np.zeros(n, dtype=[("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")])
ev["t"], ev["x"], ev["y"], ev["p"] = t, x, y, p
ev.tofile(out)
st = dv.io.Stream.EventStream(0, "events", "DVXplorer_NET", (320, 240))
st.setCompression(getattr(dv.CompressionType, name))
w = dv.io.NetworkWriter("127.0.0.1", port, st)
print("ready", flush=True)
deadline = time.time() + 20
while w.getClientCount() < 1 and time.time() < deadline:
    time.sleep(0.01)
for start in range(0, n, 700):
    s = dv.EventStore()
    for i in range(start, min(n, start + 700)):
        s.push_back(int(t[i]), int(x[i]), int(y[i]), bool(p[i]))
    w.writeEvents(s)
while w.getQueuedPacketCount() > 0 and time.time() < deadline:
    time.sleep(0.01)
time.sleep(0.3)
"#;

#[test]
fn network_stream_from_dv_processing_decodes_exactly() {
    let Some(python) = evtac_testkit::python() else {
        return;
    };
    for name in ["NONE", "LZ4", "ZSTD"] {
        let dir = tempfile::tempdir().unwrap();
        let dump = dir.path().join("sent.events");
        // Ask the OS for a free port, then hand it to the server.
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let mut child = std::process::Command::new(&python)
            .arg("-c")
            .arg(PY_NETWORK)
            .args([&port.to_string(), dump.to_str().unwrap(), name])
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        assert_eq!(line.trim(), "ready");
        let socket = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
        socket
            .set_read_timeout(Some(std::time::Duration::from_secs(30)))
            .unwrap();
        let reader = AedatReader::network(BufReader::new(socket)).unwrap();
        assert_eq!(reader.compression().name(), name);
        assert_eq!(reader.resolution(), Some(Resolution::new(320, 240)));
        assert_eq!(reader.source(), Some("DVXplorer_NET"));
        let d = decode(reader).unwrap();
        assert!(child.wait().unwrap().success());
        let sent = read_raw_events(&dump);
        assert_eq!(d.events.len(), sent.len(), "{name}");
        assert!(d.events == sent, "{name}: network events differ");
    }
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

fn small_file(compression: Compression) -> Vec<u8> {
    let res = Resolution::new(32, 24);
    let (events, imu) = synthetic(9000, res, 11);
    let mut cur = io::Cursor::new(Vec::new());
    let mut w = AedatWriter::new_seekable(
        &mut cur,
        WriterConfig {
            resolution: res,
            source_name: "cam".into(),
            compression,
        },
    )
    .unwrap();
    w.write_events(&events).unwrap();
    w.write_imu(&imu).unwrap();
    w.finish().unwrap();
    cur.into_inner()
}

#[test]
fn empty_and_wrong_magic_are_errors() {
    assert!(matches!(
        AedatReader::from_slice(b""),
        Err(AedatError::BadMagic { .. })
    ));
    assert!(matches!(
        AedatReader::from_slice(b"#!AER-DAT3.1\r\n"),
        Err(AedatError::BadMagic { .. })
    ));
    assert!(matches!(
        AedatReader::from_slice(b"#!AER-DAT4"),
        Err(AedatError::TruncatedHeader { offset: 10, .. })
    ));
    assert!(AedatReader::network(&b""[..]).is_err());
}

/// Flatbuffers shorter than a size prefix, root offset and identifier: errors, not the panic
/// inside flatbuffers' identifier check that the `aedat` fuzz target found.
#[test]
fn flatbuffers_too_short_for_an_identifier_are_errors() {
    // The fuzzer's input: a network stream whose IOHeader has a zero size prefix.
    assert!(AedatReader::network(&[0u8, 0, 0, 0][..]).is_err());
    let mut file = MAGIC.to_vec();
    file.extend_from_slice(&[0, 0, 0, 0]);
    assert!(AedatReader::from_slice(&file).is_err());
    // An uncompressed packet whose flatbuffer declares zero bytes.
    let mut bytes = small_file(Compression::None);
    let whole = decode(AedatReader::from_slice(&bytes).unwrap()).unwrap();
    let (_, off) = whole.packets[1];
    let payload = off as usize + 8;
    bytes[payload..payload + 4].copy_from_slice(&0u32.to_le_bytes());
    let err = decode(AedatReader::from_slice(&bytes).unwrap()).unwrap_err();
    assert!(err.to_string().contains("identifier"), "{err}");
}

#[test]
fn truncation_at_every_packet_boundary_and_inside_packets_is_an_error() {
    for c in ALL {
        let bytes = small_file(c);
        let whole = decode(AedatReader::from_slice(&bytes).unwrap()).unwrap();
        let table = AedatReader::from_slice(&bytes)
            .unwrap()
            .header()
            .data_table_position
            .unwrap() as usize;
        assert!(whole.packets.len() > 3);
        let mut cuts: Vec<usize> = Vec::new();
        for &(_, off) in &whole.packets {
            let off = off as usize;
            cuts.extend([off, off + 3, off + 8, off + 20]);
        }
        cuts.extend([0, 5, 14, 17, 40, table, table + 1, bytes.len() - 1]);
        for cut in cuts {
            let result = AedatReader::from_slice(&bytes[..cut]).and_then(decode);
            match result {
                Ok(_) => panic!("{c}: cut at {cut} of {} not detected", bytes.len()),
                Err(e) => assert!(e.to_string().contains("byte"), "{e}"),
            }
        }
    }
}

#[test]
fn truncated_packet_names_its_offset() {
    let bytes = small_file(Compression::Lz4);
    let whole = decode(AedatReader::from_slice(&bytes).unwrap()).unwrap();
    let (stream, off) = whole.packets[2];
    let err = decode(AedatReader::from_slice(&bytes[..off as usize + 30]).unwrap()).unwrap_err();
    match err {
        AedatError::TruncatedPacket {
            offset, stream_id, ..
        } => assert_eq!((offset, stream_id), (off, stream)),
        other => panic!("unexpected error {other}"),
    }
}

#[test]
fn out_of_range_events_and_backwards_time_are_errors() {
    // Declare 32x24, then patch an event's x in an uncompressed file to 40.
    let bytes = small_file(Compression::None);
    let whole = decode(AedatReader::from_slice(&bytes).unwrap()).unwrap();
    let (_, off) = whole.packets[0];
    // Body: 8-byte packet header, then the flatbuffer; find the first event's record by its
    // timestamp bytes.
    let t0 = whole.events[0].t.to_le_bytes();
    let start = off as usize + 8;
    let pos = start + bytes[start..].windows(8).position(|w| w == t0).unwrap();
    let mut bad = bytes.clone();
    bad[pos + 8..pos + 10].copy_from_slice(&40i16.to_le_bytes());
    let err = decode(AedatReader::from_slice(&bad).unwrap()).unwrap_err();
    assert!(
        matches!(
            err,
            AedatError::OutOfBounds {
                index: 0,
                x: 40,
                width: 32,
                ..
            }
        ),
        "{err}"
    );
    let mut bad = bytes.clone();
    bad[pos + 8..pos + 10].copy_from_slice(&(-1i16).to_le_bytes());
    assert!(matches!(
        decode(AedatReader::from_slice(&bad).unwrap()),
        Err(AedatError::OutOfBounds { x: -1, .. })
    ));
    // Second event earlier than the first.
    let mut bad = bytes.clone();
    bad[pos + 16..pos + 24].copy_from_slice(&(whole.events[0].t - 1).to_le_bytes());
    assert!(matches!(
        decode(AedatReader::from_slice(&bad).unwrap()),
        Err(AedatError::TimestampBackwards { index: 1, .. })
    ));
}

#[test]
fn flipped_bytes_never_panic() {
    for c in ALL {
        let bytes = small_file(c);
        // Every byte of the header and first packets, and a stride through the rest.
        let positions = (0..bytes.len().min(3000)).chain((3000..bytes.len()).step_by(97));
        for pos in positions {
            let mut bad = bytes.clone();
            bad[pos] ^= 0xA5;
            evtac_formats::aedat::fuzz_decode(&bad);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_truncation_and_corruption_never_panic(
        compression in 0usize..3,
        cut in 0.0f64..1.0,
        flips in proptest::collection::vec((0.0f64..1.0, any::<u8>()), 0..8),
    ) {
        let bytes = small_file(ALL[compression]);
        let mut bad = bytes[..(cut * bytes.len() as f64) as usize].to_vec();
        let len = bad.len();
        for (at, x) in flips {
            if len > 0 {
                bad[((at * len as f64) as usize).min(len - 1)] ^= x;
            }
        }
        evtac_formats::aedat::fuzz_decode(&bad);
        // A clean cut anywhere is always reported.
        let clean = &bytes[..(cut * bytes.len() as f64) as usize];
        prop_assert!(AedatReader::from_slice(clean).and_then(decode).is_err());
    }
}

/// A file read from disk checks its data table in passes over it (constant memory), a file in
/// memory whole: every byte of the table damaged, and the file cut anywhere in it, the two give
/// the same result and the same error.
#[test]
fn streamed_table_check_rejects_what_the_whole_check_rejects_with_its_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("damaged.aedat4");
    for c in ALL {
        let bytes = small_file(c);
        let table = AedatReader::from_slice(&bytes)
            .unwrap()
            .header()
            .data_table_position
            .unwrap() as usize;
        let mut cases: Vec<Vec<u8>> = (table..bytes.len()).map(|n| bytes[..n].to_vec()).collect();
        for at in table..bytes.len() {
            for flip in [0x01u8, 0xff] {
                let mut bad = bytes.clone();
                bad[at] ^= flip;
                cases.push(bad);
            }
        }
        cases.push(bytes.clone());
        let (mut same_ok, mut same_err) = (0, 0);
        for bad in cases {
            std::fs::write(&path, &bad).unwrap();
            let whole = AedatReader::from_slice(&bad).and_then(decode);
            let streamed = AedatReader::open(&path).and_then(decode);
            match (&whole, &streamed) {
                (Ok(a), Ok(b)) if a == b => same_ok += 1,
                (Err(a), Err(b)) if a.to_string() == b.to_string() => same_err += 1,
                _ => panic!(
                    "{c}, {} bytes: whole {whole:?}, streamed {streamed:?}",
                    bad.len()
                ),
            }
        }
        assert!(
            same_ok > 0 && same_err > 0,
            "{c}: {same_ok} read, {same_err} refused"
        );
    }
}

/// A pass for the IMU only (`evtac import --sync imu`) hands out every IMU sample and nothing
/// else, every compression, from a file and through `evtac_formats::open`.
#[test]
fn an_imu_only_read_hands_out_the_imu_and_nothing_else() {
    let res = Resolution::new(640, 480);
    let (events, imu) = synthetic(20_000, res, 7);
    let dir = tempfile::tempdir().unwrap();
    for c in ALL {
        let path = dir.path().join(format!("imu_{c}.aedat4"));
        write_file(&path, c, &events, &imu, res);
        let mut reader = AedatReader::open(&path).unwrap();
        reader.imu_only();
        let d = decode(reader).unwrap();
        assert_eq!((d.events, d.imu.clone()), (Vec::new(), imu.clone()), "{c}");
        let mut reader = evtac_formats::open(&path).unwrap();
        reader.imu_only();
        let mut found = Vec::new();
        while let Some(chunk) = reader.next_chunk().unwrap() {
            assert!(chunk.events.is_empty() && chunk.triggers.is_empty(), "{c}");
            found.extend_from_slice(chunk.imu);
        }
        assert_eq!(found, imu, "{c}");
    }
}
