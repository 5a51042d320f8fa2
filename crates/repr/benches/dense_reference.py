"""tonic 1.7's side of `cargo bench -p evtac-repr --bench dense`: the same kinds and settings on
the same events, per sample: tonic's frame at the sample and numpy's 8x8 mean over it (the
features evtac hands out).

- time-surface(-binary): `to_timesurface_numpy` over segments of 250 samples at once (tonic's
  own batching: its memory carries over within a call, and every slice end is a sample), then
  `> 0.5` for the binary form; per-sample time = the segment's time / its samples.
- histogram: `to_frame_numpy(time_window=W, overlap=W - step)` over segments of 250 samples at
  once (one frame per sample), likewise.
- voxel-grid: `to_voxel_grid_numpy` per sample on the window's events, with the window's edges
  as its first and last events (tonic has no batched form).

Usage: python dense_reference.py EVENTS.bin N WIDTH HEIGHT T0_US STEP_US SAMPLES
EVENTS.bin holds N int64 timestamps, N uint16 x, N uint16 y, N uint8 polarities, back to back.
Prints one line per kind: name, median and P99 per sample (us), events per second.
"""
import sys
import time

import numpy as np
import tonic.functional as F

path, n, w, h, t0, step, samples = sys.argv[1], *map(int, sys.argv[2:])
raw = open(path, "rb").read()
ev = np.zeros(n, dtype=[("x", "<i2"), ("y", "<i2"), ("t", "<i8"), ("p", "<i1")])
ev["t"] = np.frombuffer(raw, "<i8", n, 0)
ev["x"] = np.frombuffer(raw, "<u2", n, 8 * n)
ev["y"] = np.frombuffer(raw, "<u2", n, 10 * n)
ev["p"] = np.frombuffer(raw, "u1", n, 12 * n)
times = t0 + step * np.arange(1, samples + 1, dtype=np.int64)
size = (w, h, 2)
TAU, WINDOW, BINS, SEGMENT = 100_000.0, 100_000, 5, 250


def pool(frames):
    c = frames.shape[-3]
    return frames.reshape(-1, c, h // 8, 8, w // 8, 8).mean(axis=(3, 5), dtype=np.float32)


def report(name, per_sample_ns):
    lat = np.sort(np.asarray(per_sample_ns, dtype=np.float64)) / 1e3
    rate = n / (lat.sum() / 1e6) * (len(times) / len(lat))
    p99 = lat[int(np.ceil(0.99 * len(lat))) - 1]
    print(f"{name} {np.median(lat):.3f} {p99:.3f} {rate:.1f}", flush=True)


def segments():
    for i in range(0, len(times), SEGMENT):
        yield times[i : i + SEGMENT]


def time_surface(binary):
    per = []
    for seg in segments():
        # Events from one step before the segment's first sample: its first slice ends there.
        lo, hi = np.searchsorted(ev["t"], [seg[0] - step, seg[-1]])
        part = ev[lo:hi]
        start = time.perf_counter_ns()
        surf = F.to_timesurface_numpy(part, size, dt=step, tau=TAU)
        if binary:
            surf = (surf > 0.5).astype(np.float32)
        feats = pool(surf)
        took = time.perf_counter_ns() - start
        assert feats.shape[0] >= 1
        per += [took / len(surf)] * len(surf)
    return per


def histogram():
    per = []
    for seg in segments():
        start = time.perf_counter_ns()
        frames = F.to_frame_numpy(ev, size, time_window=WINDOW, overlap=WINDOW - step,
                                  start_time=seg[0] - WINDOW, end_time=seg[-1])
        feats = pool(frames)
        took = time.perf_counter_ns() - start
        assert feats.shape[0] == len(seg), (feats.shape, len(seg))
        per += [took / len(seg)] * len(seg)
    return per


def voxel_grid():
    per = []
    edge = np.zeros(3, dtype=ev.dtype)
    edge["p"] = [1, 0, 1]
    for t_k in times:
        start = time.perf_counter_ns()
        lo, hi = np.searchsorted(ev["t"], [t_k - WINDOW, t_k])
        edge["t"] = [t_k - WINDOW, t_k - WINDOW, t_k]
        arr = np.concatenate([edge[:2], ev[lo:hi], edge[2:]])
        grid = F.to_voxel_grid_numpy(arr, size, n_time_bins=BINS)[:, 0]
        feats = pool(grid[None])
        per.append(time.perf_counter_ns() - start)
        assert feats.shape == (1, BINS, h // 8, w // 8)
    return per


report("time-surface", time_surface(False))
report("time-surface-binary", time_surface(True))
report("histogram", histogram())
report("voxel-grid", voxel_grid())
