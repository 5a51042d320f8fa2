"""Writes the seed files the fuzz corpora grew from (see docs/reliability.md): NPY files written
by numpy, AEDAT4 files written by dv-processing, small CSVs, and cuts of the real recordings.

    .venv/bin/python fuzz/make_seeds.py OUT_DIR [FIXTURES_DIR]

OUT_DIR gets one folder per fuzz target; FIXTURES_DIR defaults to ../shared/fixtures/real. Then
`cargo +nightly fuzz run npy corpus/npy OUT_DIR/npy -- ...` adds them to a run.
"""

import os
import sys

import dv_processing as dv
import numpy as np

S = sys.argv[1]
R = sys.argv[2] if len(sys.argv) > 2 else os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "fixtures", "real"
)
for target in ("aedat", "evt2", "evt3", "csv", "npy", "npz", "hdf5", "neurotac"):
    os.makedirs(os.path.join(S, target), exist_ok=True)
rng = np.random.default_rng(7)
# NPY: the event record in several forms numpy writes
base = [("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")]
forms = {
    "plain": np.dtype(base),
    "aligned": np.dtype(base, align=True),
    "reordered": np.dtype([("p", "?"), ("x", "<u2"), ("y", "<u2"), ("t", "<i8")]),
    "bigx": np.dtype([("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "i1")]),
    "be": np.dtype([("t", ">i8"), ("x", ">i2"), ("y", ">i2"), ("p", "u1")]),
    "f8t": np.dtype([("t", "<f8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")]),
    "missing": np.dtype([("t", "<i8"), ("x", "<i2"), ("y", "<i2")]),
    # other tools' names and types: dv-processing's EventStore.numpy(), the aedat package's
    "dv": np.dtype({"names": ["timestamp", "x", "y", "polarity"],
                    "formats": ["<i8", "<i2", "<i2", "i1"], "offsets": [0, 8, 10, 12],
                    "itemsize": 16}),
    "aedat_pkg": np.dtype([("t", "<u8"), ("x", "<u2"), ("y", "<u2"), ("on", "?")]),
    "i4": np.dtype([("ts", "<i4"), ("xs", "<u4"), ("ys", "<i8"), ("ps", "i1")]),
}
for name, dt in forms.items():
    for n in (0, 1, 5, 40):
        a = np.zeros(n, dtype=dt)
        if n:
            values = {"t": np.cumsum(rng.integers(0, 4, n)) + 1000,
                      "x": rng.integers(0, 320, n), "y": rng.integers(0, 240, n),
                      "p": rng.integers(0, 2, n)}
            for field in dt.names:
                a[field] = values[{"timestamp": "t", "ts": "t", "xs": "x", "ys": "y",
                                   "ps": "p", "polarity": "p", "on": "p"}.get(field, field)]
        np.save(f"{S}/npy/{name}_{n}.npy", a)
        if n in (1, 40):
            # NPZ: the record array stored, and one array per field compressed
            np.savez(f"{S}/npz/{name}_{n}.npz", events=a)
            if len(dt.names) == 4:
                np.savez_compressed(f"{S}/npz/cols_{name}_{n}.npz",
                                    **{k: a[k] for k in dt.names})
np.savez(f"{S}/npz/two.npz", a=np.zeros(2, dtype=np.dtype(base)), b=np.zeros(1, dtype=np.dtype(base)))
np.savez(f"{S}/npz/ragged.npz", t=np.arange(3), x=np.arange(2), y=np.arange(3), p=np.arange(3) % 2)
for n, dt in [(4, "<f8"), (3, "<i8")]:
    np.save(f"{S}/npy/scalar_{dt[1:]}.npy", np.arange(n, dtype=dt))
np.save(f"{S}/npy/2d.npy", np.zeros((3, 2), dtype=np.dtype(base)))
np.save(f"{S}/npy/fortran.npy", np.asfortranarray(np.zeros((2, 2), dtype="<i8")))
# format version 2.0 and 3.0 headers
from numpy.lib import format as fmt
for v in ((2, 0), (3, 0)):
    a = np.zeros(3, dtype=np.dtype(base))
    with open(f"{S}/npy/v{v[0]}.npy", "wb") as f:
        fmt.write_array(f, a, version=v)
# the expected events of the EVT3 fixture, cut small
e = np.load(f"{R}/prophesee_gen4_1280x720.evt3.expected.npy")
np.save(f"{S}/npy/real_cut.npy", e[:64])
# CSV
for n in (0, 1, 10, 50):
    with open(f"{S}/csv/ev_{n}.csv", "w") as f:
        f.write("t,x,y,p\n")
        t = 100
        for i in range(n):
            t += int(rng.integers(0, 3))
            f.write(f"{t},{rng.integers(0,700)},{rng.integers(0,500)},{rng.integers(0,2)}\n")
open(f"{S}/csv/crlf.csv", "w").write("t,x,y,p\r\n1,2,3,1\r\n2,3,4,0\r\n")
open(f"{S}/csv/back.csv", "w").write("t,x,y,p\n5,1,1,1\n3,1,1,0\n")
open(f"{S}/csv/headerless.csv", "w").write("1,2,3,1\n2,3,4,0\n3,4,5,-1\n")
open(f"{S}/csv/named.csv", "w").write("x,y,polarity,timestamp\n2,3,1,1\n3,4,0,2\n")
open(f"{S}/csv/neg.csv", "w").write("t,x,y,p\n-5,1,1,1\n3,-1,1,0\n4,1,1,2\n")
# AEDAT4 written by dv-processing: every compression, small packets
for comp in ("NONE", "LZ4", "LZ4_HIGH", "ZSTD", "ZSTD_HIGH"):
    cfg = dv.io.MonoCameraWriter.Config("DVXplorer_PY")
    cfg.compression = getattr(dv.CompressionType, comp)
    cfg.addEventStream((320, 240))
    cfg.addImuStream()
    cfg.addTriggerStream()
    path = f"{S}/aedat/dv_{comp}.aedat4"
    w = dv.io.MonoCameraWriter(path, cfg)
    w.setPackagingCount(4)
    t = 1_600_000_000_000_000
    for k in range(3):
        s = dv.EventStore()
        for i in range(6):
            t += int(rng.integers(0, 3))
            s.push_back(t, int(rng.integers(0, 320)), int(rng.integers(0, 240)), bool(rng.integers(0, 2)))
        w.writeEvents(s)
        w.writeImu(dv.IMU(t, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.0, 0.0, 0.0))
        w.writeTrigger(dv.Trigger(t, dv.TriggerType.EXTERNAL_SIGNAL_RISING_EDGE))
    del w


# EVT: the real recordings cut to their header plus 0 B..16 KiB, 4 KiB slices from inside the
# data, and the last 2 KiB; AEDAT4: the first 4, 16 and 64 KiB of the real recording.
def header_length(b):
    i = 0
    while b[i : i + 1] == b"%":
        i = b.index(b"\n", i) + 1
    return i


for kind, name in (
    ("evt2", "prophesee_gen3_640x480.evt2.raw"),
    ("evt3", "prophesee_gen4_1280x720.evt3.raw"),
):
    b = open(f"{R}/{name}", "rb").read()
    h = header_length(b)
    for n in (0, 64, 1024, 4096, 16384):
        open(f"{S}/{kind}/head_{n}.raw", "wb").write(b[: h + n])
    for k, off in enumerate((len(b) // 4, len(b) // 2, 3 * len(b) // 4, len(b) - 4096)):
        off = h + ((off - h) // 4) * 4
        open(f"{S}/{kind}/mid_{k}.raw", "wb").write(b[off : off + 4096])
    open(f"{S}/{kind}/tail.raw", "wb").write(b[-2048:])
b = open(f"{R}/dvxplorer_320x240_imu.aedat4", "rb").read()
for n in (4096, 16384, 65536):
    open(f"{S}/aedat/real_{n}.aedat4", "wb").write(b[:n])

# NeuroTac: the lab's per-pixel pickles, small grids, every protocol, both index orders, NPY
import pickle
for h, w in ((3, 4), (2, 2), (5, 1)):
    a = np.empty((h, w), dtype=object)
    for y in range(h):
        for x in range(w):
            a[y, x] = [round(float(v), 3) for v in np.sort(rng.uniform(0, 50, rng.integers(0, 3)))]
    lists = [[list(a[y, x]) for y in range(h)] for x in range(w)]
    for protocol in (2, 3, 4, 5):
        with open(os.path.join(S, "neurotac", f"array_{h}x{w}_p{protocol}"), "wb") as f:
            pickle.dump(a, f, protocol=protocol)
        with open(os.path.join(S, "neurotac", f"lists_{h}x{w}_p{protocol}"), "wb") as f:
            pickle.dump(lists, f, protocol=protocol)
    np.save(os.path.join(S, "neurotac", f"npy_{h}x{w}.npy"), a, allow_pickle=True)
    cells = np.empty((h, w), dtype=object)
    for y in range(h):
        for x in range(w):
            cells[y, x] = np.array(a[y, x], dtype=np.float64)
    with open(os.path.join(S, "neurotac", f"numeric_cells_{h}x{w}"), "wb") as f:
        pickle.dump(cells, f, protocol=4)
with open(os.path.join(S, "neurotac", "dict"), "wb") as f:
    pickle.dump({"events": [1.0, 2.5], "n": 2}, f, protocol=4)
# HDF5 written by h5py: event_utils' layout (float seconds, bool p, attributes), DSEC's (t_offset,
# ms_to_idx), gzip-compressed and contiguous, and a few broken ones
import h5py
def h5(name, t, x, y, p, names=("ts", "xs", "ys", "ps"), gzip=False, dsec=False, attrs=True):
    with h5py.File(os.path.join(S, "hdf5", name + ".h5"), "w") as f:
        for k, v in zip(names, (t, x, y, p)):
            f.create_dataset("events/" + k, data=v, compression="gzip" if gzip else None)
        if attrs:
            f.attrs["num_events"] = len(x); f.attrs["sensor_resolution"] = (240, 320)
        if dsec:
            f.create_dataset("t_offset", data=np.int64(1000))
            f.create_dataset("ms_to_idx", data=np.searchsorted(t, np.arange(0, 8) * 1000).astype(np.uint64))
for n in (0, 1, 30):
    t = np.sort(rng.integers(0, 8000, n)); x = rng.integers(0, 320, n).astype(np.int16)
    y = rng.integers(0, 240, n).astype(np.int16); p = rng.integers(0, 2, n)
    h5(f"eu_{n}", t / 1e6, x, y, p.astype(bool))
    h5(f"eu_gzip_{n}", t / 1e6, x, y, p.astype(bool), gzip=True)
    h5(f"dsec_{n}", t.astype(np.uint32), x.astype(np.uint16), y.astype(np.uint16),
       p.astype(np.uint8), names=("t", "x", "y", "p"), dsec=True, attrs=False)
h5("ragged", np.arange(3) / 1e6, np.arange(2), np.arange(3), np.arange(3) % 2)
h5("string", np.arange(3) / 1e6, np.array([b"a"] * 3), np.arange(3), np.arange(3) % 2)
