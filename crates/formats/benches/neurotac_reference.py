"""NeuroTac pickles: evtac against the fastest Python way to get the same events.

    .venv/bin/python crates/formats/benches/neurotac_reference.py target/release/evtac [EVENTS]

Writes a DVXplorer-sized (640 x 480) trial as the lab's collection script does (a numpy object
array [y, x] of per-pixel lists of millisecond times, ON and OFF files, pickle protocol 5) with
EVENTS events in all (default 3,000,000), then times, best of 5, on the same files:

- Python: `pickle.load` of both files, then the events as numpy arrays (t in microseconds, x, y,
  p) sorted by time as evtac orders them: a list comprehension over the cells into flat arrays,
  then `np.lexsort`. `pickle.load` alone is printed too (it is most of the time).
- evtac: `evtac info FILE` (reads both files of the pair whole, sorts the events, checks them
  against the sensor, counts them), one process per run.

Prints one line per contender with seconds and events per second, and the ratio.
"""

import os
import pickle
import subprocess
import sys
import tempfile
import time

import numpy as np

EXE = sys.argv[1]
N = int(sys.argv[2]) if len(sys.argv) > 2 else 3_000_000
W, H = 640, 480
rng = np.random.default_rng(0)


def trial(n):
    """An object array [y, x] of sorted ms lists, n events spread over the pixels."""
    pixels = rng.integers(0, W * H, n)
    times = np.round(rng.uniform(0, 5000, n), 3)
    order = np.lexsort((times, pixels))
    pixels, times = pixels[order], times[order]
    a = np.empty((H, W), dtype=object)
    for i in range(H * W):
        a.flat[i] = []
    bounds = np.flatnonzero(np.diff(pixels)) + 1
    for chunk_p, chunk_t in zip(np.split(pixels, bounds), np.split(times, bounds)):
        if len(chunk_p):
            a.flat[chunk_p[0]] = chunk_t.tolist()
    return a


def python_events(paths):
    ts, xs, ys, ps = [], [], [], []
    for path, p in paths:
        with open(path, "rb") as f:
            a = pickle.load(f)
        for (y, x), cell in np.ndenumerate(a):
            if cell:
                ts.append(np.asarray(cell))
                xs.append(np.full(len(cell), x, np.uint16))
                ys.append(np.full(len(cell), y, np.uint16))
                ps.append(np.full(len(cell), p, np.uint8))
    t = np.rint(np.concatenate(ts) * 1000).astype(np.int64)
    x, y, p = np.concatenate(xs), np.concatenate(ys), np.concatenate(ps)
    order = np.lexsort((p, x, y, t))
    return t[order], x[order], y[order], p[order]


def best(f, runs=5):
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        f()
        out.append(time.perf_counter() - start)
    return min(out)


with tempfile.TemporaryDirectory() as d:
    on, off = os.path.join(d, "t_events_on.pickle"), os.path.join(d, "t_events_off.pickle")
    for path, n in ((on, N * 55 // 100), (off, N - N * 55 // 100)):
        with open(path, "wb") as f:
            pickle.dump(trial(n), f, protocol=5)
    size = os.path.getsize(on) + os.path.getsize(off)
    t, *_ = python_events([(on, 1), (off, 0)])
    assert len(t) == N
    load = best(lambda: [pickle.load(open(p, "rb")) for p in (on, off)])
    py = best(lambda: python_events([(on, 1), (off, 0)]))
    ev = best(lambda: subprocess.run([EXE, "info", on], check=True, capture_output=True))
    out = subprocess.run([EXE, "info", "--json", on], check=True, capture_output=True).stdout
    assert f'"events": {N}' in out.decode() or f'"events":{N}' in out.decode(), out[:200]
    print(f"files: 640x480, {N} events, {size / 1e6:.1f} MB (ON + OFF, protocol 5)")
    print(f"pickle.load only            {load:7.3f} s")
    print(f"Python (pickle + numpy)     {py:7.3f} s  {N / py / 1e6:6.2f} Mev/s")
    print(f"evtac info                  {ev:7.3f} s  {N / ev / 1e6:6.2f} Mev/s")
    print(f"evtac / Python: {py / ev:.2f}x faster; / pickle.load alone: {load / ev:.2f}x")
