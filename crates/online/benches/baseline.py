"""Python baseline for `cargo bench -p evtac-online --bench latency`: the paper's pipeline style,
per-estimate latency at 1 ms intervals, on a stream of the same rate and shape.

Per sample: the events of the last millisecond enter the representation (static: dv-processing's
Accumulator, exponential lazy decay, generateFrame, threshold 2 contributions on the 8-bit frame;
dynamic: numpy sliding-window counts, threshold > 0; combined: both, OR), 8x8 mean pooling
(numpy), then a PyTorch (CPU, one thread) forward pass of the 900-256-128-64-2 MLP. Timed from
the sample's events being handed over (as dv EventStores, built before timing) to the end of the
forward pass.

Usage: python baseline.py RATE_EV_PER_S SAMPLES
Prints one JSON object per representation: median, P99 and max latency in us.
"""
import json
import sys
import time

import numpy as np
import torch
import dv_processing as dv

torch.set_num_threads(1)
rate, samples = float(sys.argv[1]), int(sys.argv[2])
W = H = 240  # the crop (events are generated inside it)
rng = np.random.default_rng(1)
step = 1000
n_per = int(round(rate * step * 1e-6 * 0.75))  # about 3/4 of a 640x480 stream's events land in the crop
TAU_US, ETA, THRESHOLD, WINDOW_US = 1e6, 0.15, 2.0, 640_000
thr_u8 = THRESHOLD * ETA * 255.0

model = torch.nn.Sequential(
    torch.nn.Linear(900, 256), torch.nn.ReLU(), torch.nn.Linear(256, 128), torch.nn.ReLU(),
    torch.nn.Linear(128, 64), torch.nn.ReLU(), torch.nn.Linear(64, 2)).eval()

packets = []
for k in range(samples):
    t = np.sort(rng.integers(k * step, (k + 1) * step, n_per))
    # pins on a 16-pixel grid, jittered: a busy contact
    x = (rng.integers(0, 15, n_per) * 16 + rng.integers(0, 3, n_per)).astype(np.int64)
    y = (rng.integers(0, 15, n_per) * 16 + rng.integers(0, 3, n_per)).astype(np.int64)
    p = rng.integers(0, 2, n_per).astype(bool)
    packets.append((t, x, y, p))


def pool(b):
    return b.reshape(H // 8, 8, W // 8, 8).mean(axis=(1, 3), dtype=np.float32).ravel()


def run(name, static, dynamic):
    acc = dv.Accumulator((W, H), dv.Accumulator.Decay.EXPONENTIAL, TAU_US, False, ETA, 1.0, 0.0,
                         0.0, False)
    stores = []
    for t, x, y, p in packets:
        s = dv.EventStore()
        for i in range(len(t)):
            s.push_back(int(t[i]), int(x[i]), int(y[i]), bool(p[i]))
        stores.append(s)
    counts = np.zeros(W * H, dtype=np.int32)
    window = []  # (t, idx) arrays still inside the window
    lat = []
    with torch.inference_mode():
        for k, (t, x, y, p) in enumerate(packets):
            t_k = (k + 1) * step
            start = time.perf_counter_ns()
            binary = np.zeros((H, W), dtype=bool)
            if static:
                acc.accept(stores[k])
                frame = acc.generateFrame().image
                binary |= frame.reshape(H, W) > thr_u8
            if dynamic:
                idx = y * W + x
                np.add.at(counts, idx, 1)
                window.append((t, idx))
                while window and window[0][0][-1] <= t_k - WINDOW_US:
                    _, old = window.pop(0)
                    np.subtract.at(counts, old, 1)
                binary |= (counts > 0).reshape(H, W)
            features = torch.from_numpy(pool(binary.astype(np.float32)))
            out = model(features.unsqueeze(0))
            _ = out.numpy()
            lat.append(time.perf_counter_ns() - start)
    lat = np.sort(np.asarray(lat[samples // 10:], dtype=np.float64)) / 1e3
    print(json.dumps({
        "repr": name, "rate": rate, "samples": len(lat),
        "median_us": float(np.median(lat)),
        "p99_us": float(lat[int(np.ceil(0.99 * len(lat))) - 1]),
        "max_us": float(lat[-1]),
    }), flush=True)


run("static", True, False)
run("dynamic", False, True)
run("combined", True, True)
