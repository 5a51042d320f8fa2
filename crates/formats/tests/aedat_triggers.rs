//! AEDAT 4.0 triggers (the `TRIG` stream DV records from the camera's sync input): read and
//! written exactly as dv-processing 2.0.4 does both ways, all three compressions.

use std::io::{Cursor, Read};
use std::path::Path;

use evtac_events::{Event, Resolution, Trigger};
use evtac_formats::RangeIndex;
use evtac_formats::aedat::{
    AedatError, AedatReader, AedatWriter, Compression, StreamKind, TRIGGERS_PER_PACKET,
    WriterConfig,
};
use support::{Dribble, xorshift};

mod support;

const ALL: [Compression; 3] = [Compression::None, Compression::Lz4, Compression::Zstd];

/// Events and triggers read from a file.
fn read_all<R: Read>(mut reader: AedatReader<R>) -> (Vec<Event>, Vec<Trigger>) {
    let (mut events, mut triggers) = (Vec::new(), Vec::new());
    while let Some(c) = reader.next_chunk().unwrap() {
        events.extend_from_slice(c.events);
        triggers.extend_from_slice(c.triggers);
    }
    (events, triggers)
}

/// Seeded events and triggers (xorshift): triggers of every DV type, some at equal times,
/// sparse (gaps of up to 30 ms, so that packets are cut by time as well as by count).
fn synthetic(seed: u64) -> (Vec<Event>, Vec<Trigger>) {
    let mut next = xorshift(seed);
    let mut t = 1_700_000_000_000_000i64;
    let events: Vec<Event> = (0..20_000)
        .map(|_| {
            t += (next() % 20) as i64;
            Event {
                t,
                x: (next() % 346) as u16,
                y: (next() % 260) as u16,
                polarity: next().is_multiple_of(2),
            }
        })
        .collect();
    let mut t = 1_700_000_000_000_000i64;
    let triggers = (0..1000)
        .map(|_| {
            t += [0, 1, 250, 30_000][(next() % 4) as usize];
            Trigger {
                t,
                kind: (next() % 10) as i8,
            }
        })
        .collect();
    (events, triggers)
}

fn write(path: &Path, c: Compression, events: &[Event], triggers: &[Trigger]) {
    let config = WriterConfig {
        resolution: Resolution::new(346, 260),
        source_name: "DVXplorer_EVTAC01".into(),
        compression: c,
    };
    let mut w = AedatWriter::create(path, config).unwrap();
    // Uneven slices, interleaved, as a converter would call it.
    let (mut e, mut t) = (events.chunks(1777), triggers.chunks(91));
    loop {
        match (e.next(), t.next()) {
            (None, None) => break,
            (a, b) => {
                w.write_events(a.unwrap_or_default()).unwrap();
                w.write_triggers(b.unwrap_or_default()).unwrap();
            }
        }
    }
    w.finish().unwrap();
}

/// Raw dump layout of triggers: `<i8 t`, `i1 type`.
fn read_raw_triggers(path: &Path) -> Vec<Trigger> {
    std::fs::read(path)
        .unwrap()
        .chunks_exact(9)
        .map(|r| Trigger {
            t: i64::from_le_bytes(r[..8].try_into().unwrap()),
            kind: r[8] as i8,
        })
        .collect()
}

/// dv-processing writes seeded events and triggers of every type (`MonoCameraWriter` with
/// `addTriggerStream`, `writeTrigger`), and dumps the triggers raw.
const PY_DV_WRITES: &str = r#"
import sys, numpy as np, dv_processing as dv
out, name = sys.argv[1], sys.argv[2]
rng = np.random.default_rng(16)
n = 20000
t = 1_600_000_000_000_000 + np.cumsum(rng.integers(0, 5, n))
x = rng.integers(0, 640, n); y = rng.integers(0, 480, n); p = rng.integers(0, 2, n)
m = 700
tt = np.sort(rng.integers(int(t[0]), int(t[-1]) + 1, m))
kinds = rng.integers(0, 10, m)
cfg = dv.io.MonoCameraWriter.Config("DVXplorer_PY")
cfg.compression = getattr(dv.CompressionType, name)
cfg.addEventStream((640, 480))
cfg.addImuStream()
cfg.addTriggerStream()
w = dv.io.MonoCameraWriter(f"{out}/dv_{name}.aedat4", cfg)
w.setPackagingCount(50)
j = 0
for start in range(0, n, 1000):
    end = min(n, start + 1000)
    s = dv.EventStore()
    for i in range(start, end):
        s.push_back(int(t[i]), int(x[i]), int(y[i]), bool(p[i]))
    w.writeEvents(s)
    while j < m and tt[j] <= t[end - 1]:
        w.writeTrigger(dv.Trigger(int(tt[j]), dv.TriggerType(int(kinds[j]))))
        j += 1
del w
tr = np.zeros(m, dtype=[("t", "<i8"), ("k", "i1")])
tr["t"], tr["k"] = tt, kinds
tr.tofile(f"{out}/dv_{name}.triggers")
"#;

/// dv-processing reads a file's triggers (`getNextTriggerBatch`) and dumps them raw; prints
/// whether it found the trigger stream and how many events it read.
const PY_DV_READS: &str = r#"
import sys, numpy as np, dv_processing as dv
path, out = sys.argv[1], sys.argv[2]
r = dv.io.MonoCameraRecording(path)
rows = []
while True:
    b = r.getNextTriggerBatch()
    if b is None:
        break
    rows += [(tr.timestamp, int(tr.type)) for tr in b]
n = 0
while True:
    b = r.getNextEventBatch()
    if b is None:
        break
    n += len(b)
tr = np.zeros(len(rows), dtype=[("t", "<i8"), ("k", "i1")])
for i, (t, k) in enumerate(rows):
    tr["t"][i], tr["k"][i] = t, k
tr.tofile(out)
print(r.isTriggerStreamAvailable(), n)
"#;

#[test]
fn triggers_written_by_dv_processing_decode_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    for name in ["NONE", "LZ4", "ZSTD"] {
        if evtac_testkit::run_python(PY_DV_WRITES, &[out, name]).is_none() {
            return;
        }
        let base = dir.path().join(format!("dv_{name}"));
        let reader = AedatReader::open(base.with_extension("aedat4")).unwrap();
        assert_eq!(reader.compression().name(), name);
        let kinds: Vec<_> = reader.header().streams.iter().map(|s| &s.kind).collect();
        assert_eq!(
            kinds,
            [&StreamKind::Events, &StreamKind::Imu, &StreamKind::Triggers]
        );
        let (events, triggers) = read_all(reader);
        let expected = read_raw_triggers(&base.with_extension("triggers"));
        assert_eq!(expected.len(), 700);
        assert_eq!(
            (0..10)
                .filter(|k| expected.iter().any(|t| t.kind == *k))
                .count(),
            10,
            "every trigger type occurs"
        );
        assert!(triggers == expected, "{name}: triggers differ");
        assert_eq!(events.len(), 20_000, "{name}");

        // dv-processing's data table locates the packets of a time range.
        let (from, to) = (expected[100].t, expected[300].t);
        let mut reader = AedatReader::open(base.with_extension("aedat4")).unwrap();
        let index = reader.select_range(from, to).unwrap();
        assert!(matches!(index, RangeIndex::DataTable { .. }), "{index:?}");
        let inside = |t: i64| from <= t && t < to;
        let (range_events, range_triggers) = read_all(reader);
        let in_range: Vec<Trigger> = expected.iter().copied().filter(|t| inside(t.t)).collect();
        assert!(
            in_range.len() >= 200 && range_triggers == in_range,
            "{name}"
        );
        let in_range: Vec<Event> = events.iter().copied().filter(|e| inside(e.t)).collect();
        assert!(!in_range.is_empty() && range_events == in_range, "{name}");
    }
}

#[test]
fn triggers_we_write_read_back_exactly_in_dv_processing() {
    let (events, triggers) = synthetic(5);
    let dir = tempfile::tempdir().unwrap();
    for c in ALL {
        let path = dir.path().join(format!("ours_{c}.aedat4"));
        write(&path, c, &events, &triggers);
        let dump = dir.path().join(format!("dump_{c}.triggers"));
        let Some(stdout) = evtac_testkit::run_python(
            PY_DV_READS,
            &[path.to_str().unwrap(), dump.to_str().unwrap()],
        ) else {
            return;
        };
        assert_eq!(stdout.trim(), format!("True {}", events.len()), "{c}");
        let back = read_raw_triggers(&dump);
        assert_eq!(back.len(), triggers.len(), "{c}");
        assert!(
            back == triggers,
            "{c}: dv-processing read different triggers"
        );
    }
}

#[test]
fn triggers_round_trip_whatever_the_read_size() {
    let (events, triggers) = synthetic(9);
    let dir = tempfile::tempdir().unwrap();
    for c in ALL {
        let path = dir.path().join(format!("rt_{c}.aedat4"));
        write(&path, c, &events, &triggers);
        let bytes = std::fs::read(&path).unwrap();
        let whole = read_all(AedatReader::from_slice(&bytes).unwrap());
        assert!(whole == (events.clone(), triggers.clone()), "{c}");
        for step in [1, 7, 65536] {
            let r = AedatReader::new(Dribble::new(&bytes, step)).unwrap();
            assert!(
                read_all(r) == whole,
                "{c}: read size {step} changed the output"
            );
        }
    }
}

#[test]
fn trigger_packets_are_cut_by_count_and_time() {
    let (_, triggers) = synthetic(3);
    let mut w = AedatWriter::new_seekable(
        Cursor::new(Vec::new()),
        WriterConfig::new(Resolution::new(8, 8), "cam"),
    )
    .unwrap();
    w.write_triggers(&triggers).unwrap();
    let bytes = w.finish().unwrap().into_inner();
    let mut reader = AedatReader::from_slice(&bytes).unwrap();
    let mut packets = 0;
    while let Some(c) = reader.next_chunk().unwrap() {
        packets += 1;
        assert!(c.triggers.len() <= TRIGGERS_PER_PACKET);
        let span = c.triggers.last().unwrap().t - c.triggers[0].t;
        assert!(span < evtac_formats::aedat::PACKET_SPAN_US, "{span}");
    }
    assert!(packets > triggers.len() / TRIGGERS_PER_PACKET);
}

#[test]
fn triggers_going_backwards_are_rejected_naming_the_trigger() {
    let mut w =
        AedatWriter::new(Vec::new(), WriterConfig::new(Resolution::new(8, 8), "cam")).unwrap();
    let tr = |t| Trigger { t, kind: 1 };
    w.write_triggers(&[tr(10), tr(10), tr(12)]).unwrap();
    let err = w.write_triggers(&[tr(11)]).unwrap_err();
    assert!(matches!(err, AedatError::InvalidInput { .. }), "{err}");
    assert!(err.to_string().contains("trigger 3"), "{err}");
}

/// A pass for the triggers only (`--sync trigger` before the cuts) hands out every trigger and
/// nothing else, every compression, from a file and through `evtac_formats::open`.
#[test]
fn a_triggers_only_read_hands_out_the_triggers_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let (events, triggers) = synthetic(5);
    for c in ALL {
        let path = dir.path().join(format!("t-{c}.aedat4"));
        write(&path, c, &events, &triggers);
        let mut reader = AedatReader::open(&path).unwrap();
        reader.triggers_only();
        assert_eq!(read_all(reader), (Vec::new(), triggers.clone()), "{c}");
        let mut reader = evtac_formats::open(&path).unwrap();
        reader.triggers_only();
        let mut found = Vec::new();
        while let Some(chunk) = reader.next_chunk().unwrap() {
            assert!(chunk.events.is_empty() && chunk.imu.is_empty(), "{c}");
            found.extend_from_slice(chunk.triggers);
        }
        assert_eq!(found, triggers, "{c}");
    }
}
