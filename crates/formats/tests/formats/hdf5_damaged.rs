//! Damaged HDF5 files: the inputs that crashed or exhausted libhdf5 when evtac read through it
//! (found by fuzzing, kept in `regressions/`), datasets claiming far more than the file holds,
//! and one h5py file per broken case (cut short, a dataset missing, a float pixel). Each is an
//! error naming the file (and the dataset, where one is at fault), with no large allocation.

use std::path::Path;

use evtac_formats::read_recording;
use evtac_testkit::run_python;

use crate::alloc::largest_allocation_during;

/// The most a damaged file may make the reader allocate at once: slices of 65,536 events take
/// about a MiB; the claims below go to terabytes.
const ALLOCATION_LIMIT: usize = 64 << 20;

/// Reads `path`, which must fail; returns the message after checking the allocations.
fn refused(path: &Path) -> String {
    let (result, largest) = largest_allocation_during(|| read_recording(path));
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let err = match result {
        Ok(rec) => panic!("{name}: read {} events", rec.events.len()),
        Err(e) => e.to_string(),
    };
    assert!(err.contains(&name), "the error names no file: {err}");
    assert!(
        largest < ALLOCATION_LIMIT,
        "{name}: allocated {largest} bytes"
    );
    err
}

/// A heap-buffer-overflow (SIGSEGV outside the fuzzer), a 3.4 PB allocation and a leak inside
/// libhdf5 1.10.8: now errors from the Rust reader.
#[test]
fn inputs_that_broke_libhdf5_are_errors() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/formats/regressions");
    for name in [
        "libhdf5-1.10.8-heap-overflow-H5O_msg_read_oh.h5",
        "libhdf5-1.10.8-claimed-3PB-H5C_protect.h5",
        "libhdf5-1.10.8-leak-904B.h5",
    ] {
        refused(&dir.join(name));
    }
}

/// Found by the `hdf5` fuzz target on the first version of this reader: a pixel dataset whose
/// integer element claims over 512 MiB overflowed the bit count in the type error's message.
#[test]
fn an_element_size_overflowing_its_bit_count_is_an_error() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/formats/regressions/hdf5-element-size-overflow.h5");
    let err = refused(&path);
    assert!(err.contains("events/"), "{err}");
}

/// Writes the cases into `argv[1]`.
const WRITE: &str = r#"
import os, sys
import numpy as np
import h5py
d = sys.argv[1]
rng = np.random.default_rng(3)
n = 50_000
t = np.sort(rng.integers(1_700_000_000_000_000, 1_700_000_001_000_000, n))
x = rng.integers(0, 640, n); y = rng.integers(0, 480, n); p = rng.integers(0, 2, n)
def write(name, gzip=False, **over):
    data = {"xs": x.astype(np.int16), "ys": y.astype(np.int16), "ts": t / 1e6,
            "ps": p.astype(bool)}
    data.update(over)
    with h5py.File(os.path.join(d, name + ".h5"), "w") as f:
        for k, v in data.items():
            if v is not None:
                f.create_dataset("events/" + k, data=v, compression="gzip" if gzip else None)
write("contiguous")
write("gzip", gzip=True)
write("no_ys", ys=None)
write("float_x", xs=x.astype(np.float32))
bad_x = x.astype(np.int16); bad_x[40_000] = -3
write("negative_x", xs=bad_x)
bad_p = p.astype(np.int8); bad_p[123] = 2
write("p_of_2", gzip=True, ps=bad_p)
# Datasets whose storage was never written, claiming 2^40 events (contiguous, and chunked with
# gzip): a file of a few KiB.
for name, opts in (("claims_contiguous", {}), ("claims_gzip", {"compression": "gzip"})):
    with h5py.File(os.path.join(d, name + ".h5"), "w") as f:
        for k, dt in (("xs", "i2"), ("ys", "i2"), ("ts", "f8"), ("ps", "?")):
            f.create_dataset("events/" + k, shape=(2**40,), dtype=dt, **opts)
for name in ("contiguous", "gzip"):
    with open(os.path.join(d, name + ".h5"), "rb") as f:
        whole = f.read()
    for share in (2, 4):
        cut = len(whole) * (share - 1) // share
        with open(os.path.join(d, f"{name}_cut_{share}.h5"), "wb") as f:
            f.write(whole[:cut])
    with open(os.path.join(d, f"{name}_cut_1.h5"), "wb") as f:
        f.write(whole[:-1])
"#;

#[test]
fn broken_files_are_errors_naming_the_file_and_dataset() {
    let dir = tempfile::tempdir().unwrap();
    if run_python(WRITE, &[dir.path().to_str().unwrap()]).is_none() {
        return;
    }
    let d = dir.path();
    // The intact files read.
    for name in ["contiguous", "gzip"] {
        let rec = read_recording(d.join(format!("{name}.h5"))).unwrap();
        assert_eq!(rec.events.len(), 50_000, "{name}");
    }
    for (name, needles) in [
        ("no_ys", &["no event datasets", "ys"][..]),
        (
            "float_x",
            &["events/xs", "float32", "pixels and polarities are integers"],
        ),
        (
            "claims_contiguous",
            &["events/", "claims 1099511627776 elements"],
        ),
        ("claims_gzip", &["events/", "claims 1099511627776 elements"]),
        // Cut: the dataset whose bytes are missing is named, or the group `events` when the
        // cut took the metadata its listing reads.
        ("contiguous_cut_2", &["events"]),
        ("contiguous_cut_4", &["events"]),
        ("contiguous_cut_1", &["events"]),
        ("gzip_cut_2", &["events"]),
        ("gzip_cut_4", &["events"]),
        ("gzip_cut_1", &["events"]),
    ] {
        let err = refused(&d.join(format!("{name}.h5")));
        for needle in needles {
            assert!(err.contains(needle), "{name}: {err}");
        }
    }
}
