//! HDF5 event files written by h5py in the layouts labs have (event_utils' and the NeuroTac
//! code's `events/xs, ys, ts, ps` with float seconds; DSEC's `events/x, y, t, p` with
//! `t_offset` and `ms_to_idx`), read back event for event, and time ranges read through
//! `ms_to_idx` equal to the filtered whole; broken files refused with the dataset or attribute
//! named.

use evtac_events::Resolution;
use evtac_formats::{Error, Format, RangeIndex, open, read_recording, read_recording_range};
use evtac_testkit::run_python;

use crate::common::read_expected_csv;

/// Writes the files into `argv[1]`, each with `<name>.expected.csv` (`t,x,y,p` in us).
const WRITE: &str = r#"
import os, sys
import numpy as np
import h5py
d = sys.argv[1]
rng = np.random.default_rng(5)
n = 200_000
t_us = np.sort(rng.integers(1_700_000_000_000_000, 1_700_000_004_000_000, n))
x = rng.integers(0, 640, n); y = rng.integers(0, 480, n); p = rng.integers(0, 2, n)
def expected(name, t):
    np.savetxt(os.path.join(d, name + ".expected.csv"), np.stack([t, x, y, p], 1), fmt="%d",
               delimiter=",")
# event_utils: float seconds, gzip, sensor_resolution [height, width] on the file.
with h5py.File(os.path.join(d, "event_utils.h5"), "w") as f:
    f.create_dataset("events/xs", data=x.astype(np.int16), compression="gzip", chunks=True)
    f.create_dataset("events/ys", data=y.astype(np.int16), compression="gzip", chunks=True)
    f.create_dataset("events/ts", data=t_us / 1e6, compression="gzip", chunks=True)
    f.create_dataset("events/ps", data=p.astype(bool), compression="gzip", chunks=True)
    f.attrs["t0"] = t_us[0] / 1e6; f.attrs["tk"] = t_us[-1] / 1e6
    f.attrs["num_events"] = n; f.attrs["sensor_resolution"] = (480, 640)
expected("event_utils", t_us)
# The NeuroTac code: dv-processing's [width, height] as int64.
with h5py.File(os.path.join(d, "neurotac.h5"), "w") as f:
    for k, v in (("xs", x.astype(np.int16)), ("ys", y.astype(np.int16)),
                 ("ts", t_us / 1e6), ("ps", p.astype(bool))):
        f.create_dataset("events/" + k, data=v)
    f.attrs["sensor_resolution"] = np.array([640, 480], dtype="int64")
    f.attrs["num_events"] = n
# DSEC: microseconds after t_offset, the millisecond index, no sensor size.
t_offset = int(t_us[0]) - 1234
rel = (t_us - t_offset).astype(np.uint32)
with h5py.File(os.path.join(d, "dsec.h5"), "w") as f:
    f.create_dataset("events/x", data=x.astype(np.uint16), compression="gzip")
    f.create_dataset("events/y", data=y.astype(np.uint16), compression="gzip")
    f.create_dataset("events/t", data=rel, compression="gzip")
    f.create_dataset("events/p", data=p.astype(np.uint8), compression="gzip")
    f.create_dataset("t_offset", data=np.int64(t_offset))
    ms = np.arange(0, int(rel[-1]) // 1000 + 1) * 1000
    f.create_dataset("ms_to_idx", data=np.searchsorted(rel, ms, side="left").astype(np.uint64))
    print(t_offset)
expected("dsec", t_us)
# DSEC uncompressed (contiguous storage, read at its address rather than through the library),
# and event_utils big-endian (no one-pass kernel: the column-at-a-time path).
with h5py.File(os.path.join(d, "dsec_plain.h5"), "w") as f:
    for k, v in (("x", x.astype(np.uint16)), ("y", y.astype(np.uint16)), ("t", rel),
                 ("p", p.astype(np.uint8))):
        f.create_dataset("events/" + k, data=v)
    f.create_dataset("t_offset", data=np.int64(t_offset))
    f.create_dataset("ms_to_idx", data=np.searchsorted(rel, ms, side="left").astype(np.uint64))
with h5py.File(os.path.join(d, "big_endian.h5"), "w") as f:
    for k, v in (("xs", x.astype(">i2")), ("ys", y.astype(">i2")), ("ts", (t_us / 1e6).astype(">f8")),
                 ("ps", p.astype(">i1"))):
        f.create_dataset("events/" + k, data=v)
# Bad values the one-pass kernel must notice, in its second slice (65,536 events per slice):
# a polarity of 2, a negative coordinate, a time that does not fit, each named by element.
for name, field, value in (("bad_p", "ps", 2), ("bad_x", "xs", -3), ("bad_t", "ts", 1e300)):
    with h5py.File(os.path.join(d, name + ".h5"), "w") as f:
        cols = {"xs": x.astype(np.int16), "ys": y.astype(np.int16), "ts": t_us / 1e6,
                "ps": p.astype(np.int8)}
        cols[field] = cols[field].copy(); cols[field][70_000] = value
        for k, v in cols.items():
            f.create_dataset("events/" + k, data=v)
# Broken: no event datasets; a string dataset; a count that disagrees; ragged; a wrong index.
def small(name, **sets):
    with h5py.File(os.path.join(d, name + ".h5"), "w") as f:
        base = {"xs": x[:10].astype(np.int16), "ys": y[:10].astype(np.int16),
                "ts": t_us[:10] / 1e6, "ps": p[:10].astype(bool)}
        base.update(sets.pop("data", {}))
        for k, v in base.items():
            if v is not None: f.create_dataset("events/" + k, data=v)
        for k, v in sets.items(): f.attrs[k] = v
small("no_ps", data={"ps": None})
small("string_x", data={"xs": np.array([b"a"] * 10)})
small("count", num_events=11)
small("ragged", data={"ys": y[:9].astype(np.int16)})
with h5py.File(os.path.join(d, "bad_index.h5"), "w") as f:
    for k, v in (("x", x[:1000]), ("y", y[:1000]), ("t", rel[:1000]), ("p", p[:1000])):
        f.create_dataset("events/" + k, data=v.astype(np.uint32))
    f.create_dataset("t_offset", data=np.int64(t_offset))
    f.create_dataset("ms_to_idx", data=np.zeros(100, dtype=np.uint64))
with open(os.path.join(d, "event_utils.h5"), "rb") as f:
    whole = f.read()
with open(os.path.join(d, "cut.h5"), "wb") as f:
    f.write(whole[: len(whole) // 2])
"#;

fn written() -> Option<(tempfile::TempDir, i64)> {
    let dir = tempfile::tempdir().unwrap();
    let out = run_python(WRITE, &[dir.path().to_str().unwrap()])?;
    let t_offset = out.trim().parse().unwrap();
    Some((dir, t_offset))
}

#[test]
fn the_labs_layouts_read_event_for_event() {
    let Some((dir, t_offset)) = written() else {
        return;
    };
    let d = dir.path();
    for name in [
        "event_utils",
        "neurotac",
        "dsec",
        "dsec_plain",
        "big_endian",
    ] {
        let rec = read_recording(d.join(format!("{name}.h5"))).unwrap();
        assert_eq!(rec.format, Format::Hdf5);
        let source = if name.starts_with("dsec") {
            "dsec"
        } else {
            "event_utils"
        };
        let want = read_expected_csv(&d.join(format!("{source}.expected.csv")));
        assert_eq!(rec.events.len(), want.len(), "{name}");
        assert!(rec.events == want, "{name}: the events differ");
        let stated = ["event_utils", "neurotac"].contains(&name);
        let sensor = stated.then_some(Resolution::new(640, 480));
        assert_eq!(rec.resolution, sensor, "{name}");
    }
    let note = |name: &str| open(d.join(name)).unwrap().note().unwrap().to_string();
    assert!(note("event_utils.h5").contains("[480, 640] read as 640x480"));
    assert!(note("event_utils.h5").contains("float seconds"));
    assert!(note("dsec.h5").contains(&format!("t_offset = {t_offset} us")));
    // A declared size must be the file's two numbers, in either order.
    let mut r = open(d.join("neurotac.h5")).unwrap();
    r.set_resolution(Resolution::new(640, 480)).unwrap();
    let err = r.set_resolution(Resolution::new(346, 260)).unwrap_err();
    assert!(matches!(err, Error::ResolutionMismatch { .. }), "{err}");
    let mut r = open(d.join("dsec.h5")).unwrap();
    r.set_resolution(Resolution::new(600, 480)).unwrap();
    let err = r.into_recording().unwrap_err().to_string();
    assert!(err.contains("x must be < 600"), "{err}");
}

#[test]
fn ranges_go_through_ms_to_idx_and_equal_the_filtered_whole() {
    let Some((dir, t_offset)) = written() else {
        return;
    };
    let d = dir.path();
    let whole = read_recording(d.join("dsec.h5")).unwrap();
    let (first, last) = (whole.events[0].t, whole.events.last().unwrap().t);
    for ((from, to), file) in [
        (first + 1_000_000, first + 1_500_000),
        (t_offset + 999, t_offset + 1001),
        (t_offset + 123_456, t_offset + 123_457),
        (first - 5_000_000, first + 10),
        (last - 10, last + 10_000_000),
        (last + 1, last + 2),
        (first - 10, first - 5),
    ]
    .into_iter()
    .flat_map(|range| [(range, "dsec.h5"), (range, "dsec_plain.h5")])
    {
        let (part, how) = read_recording_range(d.join(file), from, to).unwrap();
        let want: Vec<_> = whole
            .events
            .iter()
            .copied()
            .filter(|e| e.t >= from && e.t < to)
            .collect();
        assert_eq!(part.events, want, "{file} [{from}, {to})");
        let RangeIndex::EventIndex { events, total } = how else {
            panic!("{how:?}");
        };
        assert_eq!(total, whole.events.len() as u64);
        // At most the two partial milliseconds' events beyond the range are read.
        assert!(
            events < want.len() as u64 + 2_000,
            "{events} read for {}",
            want.len()
        );
    }
    let (_, how) = read_recording_range(d.join("event_utils.h5"), first, first + 10).unwrap();
    assert!(matches!(how, RangeIndex::Scan(_)), "{how:?}");
    let err = read_recording_range(d.join("bad_index.h5"), t_offset + 50_000, t_offset + 60_000)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("ms_to_idx") && err.contains("bad_index.h5"),
        "{err}"
    );
}

#[test]
fn broken_files_name_the_dataset_or_attribute() {
    let Some((dir, _)) = written() else {
        return;
    };
    for (name, needles) in [
        ("no_ps", &["no event datasets", "ps"][..]),
        (
            "string_x",
            &["events/xs", "pixels and polarities are integers"],
        ),
        ("count", &["num_events", "hold 10"]),
        ("ragged", &["one length", "events/ys [9]"]),
        ("cut", &["cut.h5"]),
        ("bad_p", &["events/ps", "element 70000", "p = 2 is not"]),
        (
            "bad_x",
            &["events/xs", "element 70000", "negative coordinate (x=-3)"],
        ),
        ("bad_t", &["events/ts", "element 70000", "not a time"]),
    ] {
        let path = dir.path().join(format!("{name}.h5"));
        let err = read_recording(&path).unwrap_err().to_string();
        for needle in needles {
            assert!(err.contains(needle), "{name}: {err}");
        }
    }
}
