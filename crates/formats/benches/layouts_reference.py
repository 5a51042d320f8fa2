"""HDF5, NPZ and other tools' CSV: evtac against the fastest Python way to get the same events.

    .venv/bin/python crates/formats/benches/layouts_reference.py target/release/evtac [EVENTS]

Writes EVENTS events (default 5,000,000; a DVXplorer's 640 x 480, time-sorted) in each layout,
then times, best of 5, on the same file:

- Python, to the events as numpy arrays (t in microseconds int64, x, y, p):
  - HDF5 (event_utils' layout: `events/xs, ys` int16, `ts` float seconds, `ps` bool; and DSEC's:
    `events/x, y` uint16, `t` uint32 after `t_offset`, `p` uint8), uncompressed and gzip: h5py
    reading each dataset whole (`[:]`), then the conversions evtac does (seconds to rounded
    microseconds; adding `t_offset`);
  - NPZ (`np.savez` of one array per field, stored): `np.load` and each member read;
  - CSV without a header line: `np.loadtxt(delimiter=",", dtype=np.int64)` (numpy 2's C
    parser).
- evtac: `evtac info FILE --sensor 640x480` (reads every event, checks it against the sensor
  and the time order, counts them), one process per run.

Prints one line per layout: both times, events per second, and the ratio; then evtac's time
less its process start (`evtac info` of a 10-event NPZ, timed the same way), the part that
compares with Python's in-process read.
"""

import os
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

EXE = sys.argv[1]
N = int(sys.argv[2]) if len(sys.argv) > 2 else 5_000_000
W, H = 640, 480
rng = np.random.default_rng(0)
t_us = np.sort(rng.integers(1_700_000_000_000_000, 1_700_000_000_000_000 + 10 * N, N))
x = rng.integers(0, W, N)
y = rng.integers(0, H, N)
p = rng.integers(0, 2, N)


def best(f, runs=5):
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        f()
        out.append(time.perf_counter() - start)
    return min(out)


def write_event_utils(path, gzip):
    c = "gzip" if gzip else None
    with h5py.File(path, "w") as f:
        f.create_dataset("events/xs", data=x.astype(np.int16), compression=c)
        f.create_dataset("events/ys", data=y.astype(np.int16), compression=c)
        f.create_dataset("events/ts", data=t_us / 1e6, compression=c)
        f.create_dataset("events/ps", data=p.astype(bool), compression=c)
        f.attrs["sensor_resolution"] = (H, W)
        f.attrs["num_events"] = N


def read_event_utils(path):
    with h5py.File(path, "r") as f:
        t = np.rint(f["events/ts"][:] * 1e6).astype(np.int64)
        return t, f["events/xs"][:], f["events/ys"][:], f["events/ps"][:]


def write_dsec(path, gzip):
    c = "gzip" if gzip else None
    t_offset = int(t_us[0])
    rel = (t_us - t_offset).astype(np.uint32)
    with h5py.File(path, "w") as f:
        f.create_dataset("events/x", data=x.astype(np.uint16), compression=c)
        f.create_dataset("events/y", data=y.astype(np.uint16), compression=c)
        f.create_dataset("events/t", data=rel, compression=c)
        f.create_dataset("events/p", data=p.astype(np.uint8), compression=c)
        f.create_dataset("t_offset", data=np.int64(t_offset))
        ms = np.arange(0, int(rel[-1]) // 1000 + 1) * 1000
        f.create_dataset("ms_to_idx", data=np.searchsorted(rel, ms).astype(np.uint64))


def read_dsec(path):
    with h5py.File(path, "r") as f:
        t = f["events/t"][:].astype(np.int64) + int(f["t_offset"][()])
        return t, f["events/x"][:], f["events/y"][:], f["events/p"][:]


def write_npz(path, _):
    np.savez(path, t=t_us.astype(np.int64), x=x.astype(np.uint16), y=y.astype(np.uint16),
             p=p.astype(np.uint8))


def read_npz(path):
    with np.load(path) as z:
        return z["t"], z["x"], z["y"], z["p"]


def write_csv(path, _):
    np.savetxt(path, np.stack([t_us, x, y, p], 1), fmt="%d", delimiter=",")


def read_csv(path):
    a = np.loadtxt(path, delimiter=",", dtype=np.int64)
    return a[:, 0], a[:, 1], a[:, 2], a[:, 3]


def evtac(path):
    subprocess.run([EXE, "info", path, "--sensor", f"{W}x{H}"], check=True,
                   stdout=subprocess.DEVNULL)


LAYOUTS = [
    ("HDF5 event_utils", "eu.h5", write_event_utils, read_event_utils, False),
    ("HDF5 event_utils, gzip", "eu_gzip.h5", write_event_utils, read_event_utils, True),
    ("HDF5 DSEC", "dsec.h5", write_dsec, read_dsec, False),
    ("HDF5 DSEC, gzip", "dsec_gzip.h5", write_dsec, read_dsec, True),
    ("NPZ, one array per field", "cols.npz", write_npz, read_npz, None),
    ("CSV without a header", "headerless.csv", write_csv, read_csv, None),
]

with tempfile.TemporaryDirectory() as d:
    print(f"{N} events, best of 5")
    tiny = os.path.join(d, "tiny.npz")
    np.savez(tiny, t=t_us[:10], x=x[:10].astype(np.uint16), y=y[:10].astype(np.uint16),
             p=p[:10].astype(np.uint8))
    start = best(lambda: evtac(tiny), 10)
    print(f"evtac info of a 10-event NPZ (the process start): {start:.4f} s")
    for name, file, write, read, arg in LAYOUTS:
        path = os.path.join(d, file)
        write(path, arg)
        got = read(path)
        assert len(got[0]) == N and np.array_equal(got[0], t_us), name
        runs = 2 if file.endswith(".csv") else 5
        py = best(lambda: read(path), runs)
        ours = best(lambda: evtac(path), runs)
        size = os.path.getsize(path) / 1e6
        print(f"{name:28} {size:7.1f} MB  Python {py:7.3f} s ({N / py / 1e6:6.1f} M/s)  "
              f"evtac {ours:7.3f} s ({N / ours / 1e6:6.1f} M/s)  Python/evtac {py / ours:5.2f}x  "
              f"(evtac less its start {ours - start:6.3f} s: {py / (ours - start):5.2f}x)")
