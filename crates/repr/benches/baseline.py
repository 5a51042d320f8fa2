"""Python baseline for `cargo bench -p evtac-repr --bench represent`: the paper's implementation
style on the same synthetic stream, per-sample latency and throughput at a fixed sampling interval.

- static:   dv-processing's Accumulator (exponential, lazy decay), generateFrame() per sample,
            threshold at 2 contributions on the 8-bit frame, 8x8 mean pooling (numpy).
- dynamic:  a numpy incremental sliding window (np.add.at for events entering, np.subtract.at for
            events leaving), threshold count > 0, 8x8 mean pooling.
- combined: both, OR, pooling.

Usage: python baseline.py EVENTS.bin N WIDTH HEIGHT T0_US INTERVAL_US SAMPLES
EVENTS.bin holds N int64 timestamps, N uint16 x, N uint16 y, N uint8 polarities, back to back.
Prints one JSON object per representation. Building dv EventStores per sample is done before
timing (a camera or file reader hands out EventStores already).
"""
import json
import sys
import time

import numpy as np
import dv_processing as dv

path, n, w, h, t0, step, samples = sys.argv[1], *map(int, sys.argv[2:])
raw = open(path, "rb").read()
t = np.frombuffer(raw, "<i8", n, 0)
x = np.frombuffer(raw, "<u2", n, 8 * n).astype(np.int64)
y = np.frombuffer(raw, "<u2", n, 10 * n).astype(np.int64)
p = np.frombuffer(raw, "u1", n, 12 * n)
idx = y * w + x
times = t0 + step * np.arange(1, samples + 1, dtype=np.int64)
ends = np.searchsorted(t, times, side="right")

TAU_US, ETA, THRESHOLD, WINDOW_US = 1e6, 0.15, 2.0, 640_000
thr_u8 = THRESHOLD * ETA * 255.0


def pool(b):
    return b.reshape(h // 8, 8, w // 8, 8).mean(axis=(1, 3), dtype=np.float32).ravel()


def stores():
    out, start = [], 0
    for end in ends:
        s = dv.EventStore()
        for i in range(start, end):
            s.push_back(int(t[i]), int(x[i]), int(y[i]), bool(p[i]))
        out.append(s)
        start = end
    return out


def report(name, lat_ns, events):
    lat = np.sort(np.asarray(lat_ns, dtype=np.float64)) / 1e3
    total_s = lat.sum() / 1e6
    print(json.dumps({
        "repr": name,
        "events": int(events),
        "samples": len(lat),
        "events_per_s": events / total_s,
        "median_us": float(np.median(lat)),
        "p99_us": float(lat[int(np.ceil(0.99 * len(lat))) - 1]),
        "max_us": float(lat[-1]),
    }), flush=True)


def run(static, dynamic):
    acc = dv.Accumulator((w, h), dv.Accumulator.Decay.EXPONENTIAL, TAU_US, False, ETA, 1.0, 0.0,
                         0.0, False)
    mask = np.zeros((h, w), dtype=bool)
    counts = np.zeros(w * h, dtype=np.int32)
    per_sample = stores() if static else None
    head = tail = 0
    lat = []
    for k, t_k in enumerate(times):
        start_ns = time.perf_counter_ns()
        binary = None
        if static:
            acc.accept(per_sample[k])
            frame = acc.generateFrame().image
            binary = (frame.reshape(h, w) > thr_u8) & ~mask
        if dynamic:
            end = ends[k]
            np.add.at(counts, idx[tail:end], 1)
            tail = end
            start = np.searchsorted(t, t_k - WINDOW_US, side="right")
            if start > head:
                np.subtract.at(counts, idx[head:start], 1)
                head = start
            d = counts.reshape(h, w) > 0
            binary = d if binary is None else (binary | d)
        features = pool(binary)
        lat.append(time.perf_counter_ns() - start_ns)
        assert features.shape == ((w // 8) * (h // 8),)
    return lat


events = int(ends[-1])
report("static", run(True, False), events)
report("dynamic", run(False, True), events)
report("combined", run(True, True), events)
