//! The NeuroTac lab's per-pixel pickles, written by Python's `pickle` and numpy as the lab's
//! collection scripts write them (both index orders, ON-only, `.npy` with `allow_pickle`), read
//! back event for event; and what is not the lab's structure (an `os.system` call, a dict, a
//! ragged grid, a truncated file) refused with the file and the place named, nothing run.

use evtac_events::Resolution;
use evtac_formats::neurotac::PixelOrder;
use evtac_formats::{Error, Format, Summary};
use evtac_testkit::run_python;

use crate::common::read_expected_csv;

/// Writes the test files into `dir`: sets `a` (object arrays [y, x], ON and OFF, protocol 5),
/// `b` (nested lists [x][y], ON only, protocol 4), `c` (`np.save(allow_pickle=True)`, ON and
/// OFF) and `d` (protocol 2, no extension, OFF only), each with `<set>.expected.csv`: the events
/// the lab's structure means, microseconds, sorted by (t, y, x, polarity).
const WRITE: &str = r#"
import os, pickle, sys
import numpy as np
d = sys.argv[1]
rng = np.random.default_rng(3)
W, H = 64, 48
def times(n):
    # ms since logging started with microsecond resolution, as the lab's clock gives them.
    return sorted(int(v) / 1000 for v in rng.integers(0, 5_000_000, n))
def grid(fill):
    return {(x, y): times(int(rng.integers(0, 4))) if rng.random() < fill else []
            for y in range(H) for x in range(W)}
def as_array(cells):
    a = np.empty((H, W), dtype=object)
    for (x, y), t in cells.items():
        a[y, x] = list(t)
    return a
def as_lists(cells):
    return [[list(cells[(x, y)]) for y in range(H)] for x in range(W)]
def expected(name, on, off):
    rows = []
    for cells, p in ((on, 1), (off, 0)):
        if cells is None: continue
        for (x, y), ts in cells.items():
            rows += [(round(t * 1000), x, y, p) for t in ts]
    rows.sort(key=lambda r: (r[0], r[2], r[1], r[3]))
    with open(os.path.join(d, name + ".expected.csv"), "w") as f:
        f.writelines(f"{t},{x},{y},{p}\n" for t, x, y, p in rows)
def dump(obj, name, protocol):
    with open(os.path.join(d, name), "wb") as f:
        pickle.dump(obj, f, protocol=protocol)
on, off = grid(0.3), grid(0.2)
dump(as_array(on), "a_events_on.pickle", 5); dump(as_array(off), "a_events_off.pickle", 5)
expected("a", on, off)
on = grid(0.25)
# The DV-network version mixes int and float times.
lists = as_lists(on)
lists[3][4] = [7, 8.5]
on[(3, 4)] = [7, 8.5]
dump(lists, "b_events_on.pkl", 4)
expected("b", on, None)
on, off = grid(0.3), grid(0.3)
np.save(os.path.join(d, "c_events_on.npy"), as_array(on), allow_pickle=True)
np.save(os.path.join(d, "c_events_off.npy"), as_array(off), allow_pickle=True)
expected("c", on, off)
off = grid(0.1)
dump(as_array(off), "d_events_off", 2)
expected("d", None, off)
# Not the lab's structure.
class Evil:
    def __reduce__(self):
        return (os.system, ("touch " + os.path.join(d, "PWNED"),))
dump(Evil(), "evil_events_on.pickle", 4)
dump({"events": [1.0, 2.0]}, "dict_events_on.pickle", 4)
ragged = as_lists(grid(0.1)); ragged[5] = ragged[5][:-1]
dump(ragged, "ragged_events_on.pickle", 4)
with open(os.path.join(d, "a_events_on.pickle"), "rb") as f:
    whole = f.read()
with open(os.path.join(d, "cut_events_on.pickle"), "wb") as f:
    f.write(whole[: len(whole) // 2])
"#;

fn written() -> Option<tempfile::TempDir> {
    let dir = tempfile::tempdir().unwrap();
    run_python(WRITE, &[dir.path().to_str().unwrap()])?;
    Some(dir)
}

#[test]
fn the_labs_pickles_read_event_for_event() {
    let Some(dir) = written() else { return };
    let d = dir.path();
    for (set, file, order, note) in [
        (
            "a",
            "a_events_off.pickle",
            PixelOrder::RowMajor,
            "ON and OFF",
        ),
        (
            "b",
            "b_events_on.pkl",
            PixelOrder::ColumnLists,
            "ON events only (no b_events_off.pkl",
        ),
        ("c", "c_events_on.npy", PixelOrder::RowMajor, "ON and OFF"),
        ("d", "d_events_off", PixelOrder::RowMajor, "OFF events only"),
    ] {
        let path = d.join(file);
        assert_eq!(Format::detect(&path).unwrap(), Format::Neurotac, "{file}");
        let rec = evtac_formats::read_recording(&path).unwrap();
        assert_eq!(rec.resolution, Some(Resolution::new(64, 48)), "{file}");
        let want = read_expected_csv(&d.join(format!("{set}.expected.csv")));
        assert!(want.len() > 100, "{file}: {} events", want.len());
        assert_eq!(rec.events.len(), want.len(), "{file}");
        assert!(rec.events == want, "{file}: the events differ");
        let file_read = evtac_formats::neurotac::read_pair(&path).unwrap();
        assert_eq!(file_read.order, order, "{file}");
        let summary = Summary::of_file(&path).unwrap();
        let text = summary.note.unwrap_or_default();
        assert!(text.contains(note), "{file}: {text}");
        assert!(text.contains("milliseconds"), "{file}: {text}");
        assert!(text.contains(order.describe()), "{file}: {text}");
    }
}

#[test]
fn what_is_not_the_labs_structure_is_refused_and_nothing_runs() {
    let Some(dir) = written() else { return };
    let d = dir.path();
    let err = |file: &str| match evtac_formats::read_recording(d.join(file)) {
        Err(e @ Error::Neurotac { .. }) => e.to_string(),
        other => panic!("{file}: {other:?}"),
    };
    let evil = err("evil_events_on.pickle");
    assert!(
        evil.contains("evil_events_on.pickle")
            && evil.contains("system`")
            && evil.contains("nothing is run"),
        "{evil}"
    );
    assert!(!d.join("PWNED").exists(), "the pickle's call ran");
    let dict = err("dict_events_on.pickle");
    assert!(
        dict.contains("not a NeuroTac event file") && dict.contains("a dict"),
        "{dict}"
    );
    let ragged = err("ragged_events_on.pickle");
    assert!(
        ragged.contains("[5] has 47 pixels but [0] has 48"),
        "{ragged}"
    );
    let cut = err("cut_events_on.pickle");
    assert!(
        cut.contains("cut_events_on.pickle") && cut.contains("truncated"),
        "{cut}"
    );
}

#[test]
fn a_declared_sensor_size_must_be_the_structures() {
    let Some(dir) = written() else { return };
    let path = dir.path().join("a_events_on.pickle");
    let mut reader = evtac_formats::open(&path).unwrap();
    reader.set_resolution(Resolution::new(64, 48)).unwrap();
    let err = reader
        .set_resolution(Resolution::new(48, 64))
        .expect_err("transposed");
    assert!(err.to_string().contains("64x48"), "{err}");
}
