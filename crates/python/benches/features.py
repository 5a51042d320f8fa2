"""Features per sample from Python: evtac against the paper-style pipeline, in the same run.

The paper's implementation style (see crates/repr/benches/baseline.py): dv-processing's
Accumulator with generateFrame() per sample for the static part (threshold 2 contributions on the
8-bit frame), a numpy sliding window (np.add.at / np.subtract.at) for the dynamic part, their OR,
and 8x8 mean pooling in numpy. Its dv EventStores are built before timing, as a camera or file
reader hands them out. evtac runs the same settings (threshold on the 8-bit frame, as the
baseline does) and the script checks that all three give the same features. evtac is timed two
ways: `Representation.features` over all sample times in one call, and `push` + `advance_to`
per sample from Python (what a live loop does).

Usage: python features.py [RECORDING] [--interval-us 1000] [--repeat 5]
Default recording: the DVXplorer fixture in ../shared/fixtures/real. Prints a table (markdown).
"""

import argparse
import os
import platform
import time
from pathlib import Path

import numpy as np

import evtac

ROOT = Path(__file__).resolve().parents[3]
SHARED = Path(os.environ.get("EVTAC_SHARED", ROOT.parent / "shared"))

args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
args.add_argument("recording", nargs="?",
                  default=SHARED / "fixtures" / "real" / "dvxplorer_320x240_imu.aedat4")
args.add_argument("--interval-us", type=int, default=1000)
args.add_argument("--repeat", type=int, default=5)
a = args.parse_args()

rec = evtac.read(a.recording, roi=(240, 240))
ev = rec.events
w = h = 240
times = np.arange(ev["t"][0] + a.interval_us, ev["t"][-1] + 1, a.interval_us)
ends = np.searchsorted(ev["t"], times, side="right")
n = len(times)


def evtac_batch():
    rep = evtac.Representation("combined", threshold_space="u8")
    start = time.perf_counter()
    features = rep.features(ev, times)
    return time.perf_counter() - start, features


def evtac_incremental():
    rep = evtac.Representation("combined", threshold_space="u8")
    rows = []
    start = time.perf_counter()
    begin = 0
    for t_k, end in zip(times, ends):
        rep.push(ev[begin:end])
        begin = end
        rows.append(rep.advance_to(t_k))
    return time.perf_counter() - start, np.stack(rows)


def paper_style():
    import dv_processing as dv

    tau_us, eta, threshold, window_us = 1e6, 0.15, 2.0, 640_000
    thr_u8 = threshold * eta * 255.0
    x = ev["x"].astype(np.int64)
    y = ev["y"].astype(np.int64)
    idx = y * w + x
    stores, begin = [], 0
    for end in ends:
        s = dv.EventStore()
        for i in range(begin, end):
            s.push_back(int(ev["t"][i]), int(x[i]), int(y[i]), bool(ev["p"][i]))
        stores.append(s)
        begin = end
    acc = dv.Accumulator((w, h), dv.Accumulator.Decay.EXPONENTIAL, tau_us, False, eta, 1.0, 0.0,
                         0.0, False)
    counts = np.zeros(w * h, dtype=np.int32)
    head = tail = 0
    rows = []
    start = time.perf_counter()
    for k, t_k in enumerate(times):
        acc.accept(stores[k])
        binary = acc.generateFrame().image.reshape(h, w) > thr_u8
        end = ends[k]
        np.add.at(counts, idx[tail:end], 1)
        tail = end
        first = np.searchsorted(ev["t"], t_k - window_us, side="right")
        if first > head:
            np.subtract.at(counts, idx[head:first], 1)
            head = first
        binary |= counts.reshape(h, w) > 0
        rows.append(binary.reshape(h // 8, 8, w // 8, 8).mean(axis=(1, 3), dtype=np.float32))
    return time.perf_counter() - start, np.stack(rows).reshape(n, -1)


results = {}
for name, run in [("evtac, one call (features)", evtac_batch),
                  ("evtac, per sample (push + advance_to)", evtac_incremental),
                  ("paper style (dv-processing + numpy)", paper_style)]:
    best = min(run()[0] for _ in range(a.repeat))
    results[name] = best

_, f_batch = evtac_batch()
_, f_incr = evtac_incremental()
_, f_ref = paper_style()
assert f_batch.tobytes() == f_incr.tobytes()
same = "the same features" if f_batch.tobytes() == f_ref.tobytes() else "DIFFERENT features"

print(f"{Path(a.recording).name}: {len(ev)} events in the 240x240 crop, {n} samples every "
      f"{a.interval_us} us; combined representation; best of {a.repeat}; "
      f"{platform.processor() or platform.machine()}, evtac {evtac.__version__}; all three give "
      f"{same}\n")
print("| pipeline | us per sample | samples per s | vs paper style |")
print("| --- | ---: | ---: | ---: |")
ref = results["paper style (dv-processing + numpy)"]
for name, seconds in results.items():
    print(f"| {name} | {seconds / n * 1e6:.1f} | {n / seconds:,.0f} | {ref / seconds:.1f}x |")
