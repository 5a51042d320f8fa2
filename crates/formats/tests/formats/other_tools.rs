//! The NPY, NPZ and CSV layouts other tools write, written by those tools (numpy, and
//! dv-processing's own `EventStore.numpy()`), read back event for event through `open`; and
//! what is not an event layout refused with the member or column named.

use evtac_formats::{Format, read_recording};
use evtac_testkit::run_python;

use crate::common::read_expected_csv;

/// Writes every variant into `argv[1]` from one set of events, and the events themselves as
/// `expected.csv` (`t,x,y,p`). Every file holds the same events.
const WRITE: &str = r#"
import os, sys
import numpy as np
d = sys.argv[1]
rng = np.random.default_rng(11)
n = 3000
t = np.sort(rng.integers(1_600_000_000_000_000, 1_600_000_005_000_000, n))
x = rng.integers(0, 640, n); y = rng.integers(0, 480, n); p = rng.integers(0, 2, n)
with open(os.path.join(d, "expected.csv"), "w") as f:
    f.writelines(f"{a},{b},{c},{e}\n" for a, b, c, e in zip(t, x, y, p))
def record(fields, path):
    a = np.zeros(n, dtype=fields)
    for name, col in zip(a.dtype.names, (t, x, y, p)):
        a[name] = col
    np.save(os.path.join(d, path), a)
# The aedat package's event arrays: t u64, x/y u16, polarity `on` as bool.
record([("t", "<u8"), ("x", "<u2"), ("y", "<u2"), ("on", "?")], "aedat_package.npy")
# p as int8, with OFF written -1.
a = np.zeros(n, dtype=[("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "i1")])
a["t"], a["x"], a["y"], a["p"] = t, x, y, np.where(p == 1, 1, -1)
np.save(os.path.join(d, "int8_minus_one.npy"), a)
# dv-processing's own structured array.
try:
    import dv_processing as dv
    store = dv.EventStore()
    for a_, b_, c_, e_ in zip(t, x, y, p):
        store.push_back(int(a_), int(b_), int(c_), bool(e_))
    np.save(os.path.join(d, "dv_processing.npy"), store.numpy())
    print("dv")
except ImportError:
    pass
# NPZ: one record array, stored; one array per field, compressed, dv-processing's names.
ours = np.zeros(n, dtype=[("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")])
ours["t"], ours["x"], ours["y"], ours["p"] = t, x, y, p
np.savez(os.path.join(d, "record.npz"), events=ours)
np.savez_compressed(os.path.join(d, "columns.npz"), timestamp=t.astype(np.int64),
                    x=x.astype(np.uint16), y=y.astype(np.uint16), polarity=p.astype(bool))
# One array per field, stored (uncompressed), as `np.savez` writes it: the members are read
# straight from the file.
np.savez(os.path.join(d, "columns_stored.npz"), t=t.astype(np.int64), x=x.astype(np.uint16),
         y=y.astype(np.uint16), p=p.astype(np.uint8))
# CSV: without a header line, and with DV's column names in another order.
np.savetxt(os.path.join(d, "headerless.csv"), np.stack([t, x, y, p], 1), fmt="%d", delimiter=",")
np.savetxt(os.path.join(d, "named.csv"), np.stack([x, y, p, t], 1), fmt="%d", delimiter=",",
           header="x,y,polarity,timestamp", comments="")
# Not events: a float time column, an NPZ without event members, columns of unequal length.
np.savez(os.path.join(d, "float_t.npz"), t=t / 1e6, x=x, y=y, p=p)
np.savez(os.path.join(d, "no_events.npz"), image=np.zeros((4, 4)), label=np.arange(3))
np.savez(os.path.join(d, "ragged.npz"), t=t, x=x[:-1], y=y, p=p)
"#;

#[test]
fn every_layout_reads_the_same_events() {
    let dir = tempfile::tempdir().unwrap();
    let Some(out) = run_python(WRITE, &[dir.path().to_str().unwrap()]) else {
        return;
    };
    let expected = read_expected_csv(&dir.path().join("expected.csv"));
    let mut files = vec![
        ("aedat_package.npy", Format::Npy),
        ("int8_minus_one.npy", Format::Npy),
        ("record.npz", Format::Npz),
        ("columns.npz", Format::Npz),
        ("columns_stored.npz", Format::Npz),
        ("headerless.csv", Format::Csv),
        ("named.csv", Format::Csv),
    ];
    if out.contains("dv") {
        files.push(("dv_processing.npy", Format::Npy));
    } else {
        assert!(std::env::var_os("CI").is_none(), "dv-processing is missing");
    }
    for (name, format) in files {
        let rec = read_recording(dir.path().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(rec.format, format, "{name}");
        assert_eq!(rec.events, expected, "{name}");
    }
    let notes = |name: &str| {
        evtac_formats::open(dir.path().join(name))
            .unwrap()
            .note()
            .map(str::to_string)
    };
    assert!(notes("headerless.csv").unwrap().contains("no header line"));
    assert_eq!(notes("named.csv"), None);
    assert!(notes("columns.npz").unwrap().contains("timestamp.npy"));
    assert!(notes("record.npz").unwrap().contains("events.npy"));
}

#[test]
fn what_is_not_events_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let Some(_) = run_python(WRITE, &[dir.path().to_str().unwrap()]) else {
        return;
    };
    for (name, needles) in [
        (
            "float_t.npz",
            &["float_t.npz", "member `t.npy`", "`<f8` is not"][..],
        ),
        ("no_events.npz", &["no member holds events", "image.npy"]),
        ("ragged.npz", &["differ in length", "x.npy 2999"]),
    ] {
        let err = read_recording(dir.path().join(name))
            .unwrap_err()
            .to_string();
        for needle in needles {
            assert!(err.contains(needle), "{name}: {err}");
        }
    }
    // An NPZ is not written, and a zip that is not named .npz is not taken for one.
    let err = evtac_formats::EventWriter::create(dir.path().join("out.npz"), None, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("NPZ"), "{err}");
    std::fs::copy(dir.path().join("record.npz"), dir.path().join("record.zip")).unwrap();
    assert!(read_recording(dir.path().join("record.zip")).is_err());
}

/// The per-field members are read from their own offsets, not through the zip crate's reader,
/// which checked each member's CRC-32: a damaged byte in a stored member's values must still
/// fail the read, naming the member, and so must a member cut short.
#[test]
fn a_damaged_stored_member_fails_its_checksum() {
    let dir = tempfile::tempdir().unwrap();
    let Some(_) = run_python(WRITE, &[dir.path().to_str().unwrap()]) else {
        return;
    };
    let bytes = std::fs::read(dir.path().join("columns_stored.npz")).unwrap();
    // The local header of `x.npy`: 30 fixed bytes (the name's length at 26, the extra field's
    // at 28), the name, the extra field, then the stored NPY file.
    let local = bytes
        .windows(35)
        .position(|w| w.starts_with(b"PK\x03\x04") && &w[30..] == b"x.npy")
        .expect("x.npy's local header");
    let le16 = |at: usize| usize::from(u16::from_le_bytes([bytes[at], bytes[at + 1]]));
    let data = local + 30 + le16(local + 26) + le16(local + 28);
    assert_eq!(&bytes[data..data + 6], b"\x93NUMPY");
    let mut damaged = bytes.clone();
    damaged[data + 200] ^= 0x01;
    let path = dir.path().join("damaged.npz");
    std::fs::write(&path, &damaged).unwrap();
    let err = read_recording(&path).unwrap_err().to_string();
    assert!(
        err.contains("damaged.npz") && err.contains("member `x.npy`") && err.contains("CRC-32"),
        "{err}"
    );
    // Cut inside `x.npy`'s values: the central directory is gone, so the zip crate refuses it.
    let cut = dir.path().join("cut.npz");
    std::fs::write(&cut, &bytes[..data + 300]).unwrap();
    assert!(read_recording(&cut).is_err());
}
