"""numpy/SciPy reference for benches/label_trial.rs: the same label steps on the same number of
IMU samples (9,360: 11.7 s at 800 Hz) -- projection through the extrinsics onto the rolling axis,
bias from the stationary segment, cumulative trapezoid restricted to the moving intervals (with
exact window edges by interpolation), scale onto the total, sosfiltfilt (Butterworth order 4,
20 Hz), hold, contact angles. Prints the median time of `label` and of `sosfiltfilt` alone.
Needs scipy in the venv; not used by tests.

Usage: python label_reference.py [--repeats 200]
"""

import argparse
import time

import numpy as np
from scipy import signal
from scipy.integrate import cumulative_trapezoid


def label(t_us, gyro, m, phi, start, end, stop, sos):
    a = np.array([-np.sin(phi), np.cos(phi), 0.0])
    rate = -(gyro @ m.T) @ a
    bias = rate[t_us < start - 50_000].mean()
    c = rate - bias
    t = t_us * 1e-6
    cum = cumulative_trapezoid(c, t, initial=0.0)

    def at(x):
        # exact integral of the linear interpolant up to x
        i = np.clip(np.searchsorted(t_us, x, side="right") - 1, 0, len(t_us) - 2)
        w = (x - t_us[i]) / (t_us[i + 1] - t_us[i])
        y = c[i] + w * (c[i + 1] - c[i])
        return cum[i] + 0.5 * (c[i] + y) * (x - t_us[i]) * 1e-6

    intervals = [(start, stop[0]), (stop[1], end)]
    held = sum(at(np.clip(t_us, lo, hi)) - at(lo) for lo, hi in intervals)
    total = sum(at(hi) - at(lo) for lo, hi in intervals)
    held *= 20.0 / total
    theta = signal.sosfiltfilt(sos, held)
    moving = np.zeros(len(t_us), bool)
    for lo, hi in intervals:
        moving |= (t_us > lo) & (t_us < hi)
    theta[~moving] = held[~moving]
    th = np.radians(theta)
    d = np.stack([np.sin(th) * np.cos(phi), np.sin(th) * np.sin(phi), np.cos(th)])
    return np.degrees(np.arctan2(d[0], d[2])), np.degrees(np.arctan2(d[1], d[2]))


def median_time(f, repeats):
    times = []
    for _ in range(repeats):
        s = time.perf_counter()
        f()
        times.append(time.perf_counter() - s)
    return float(np.median(times))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=200)
    args = parser.parse_args()
    n = 9_360
    rng = np.random.default_rng(1)
    t_us = np.arange(n, dtype=np.int64) * 1250
    gyro = rng.normal(0.0, 0.12, (n, 3)).astype(np.float32).astype(np.float64)
    moving = (t_us > 600_000) & (t_us < 11_100_000)
    gyro[moving, 0] += 2.0
    m = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    sos = signal.butter(4, 20.0, fs=800.0, output="sos")
    phi = np.radians(54.0)
    f = lambda: label(t_us, gyro, m, phi, 600_000, 11_100_000, (5_100_000, 5_600_000), sos)
    x = np.sin(np.arange(n) * 0.01)
    print(f"label {n} samples: {median_time(f, args.repeats) * 1e6:.1f} us (median)")
    g = lambda: signal.sosfiltfilt(sos, x)
    print(f"sosfiltfilt {n} samples: {median_time(g, args.repeats) * 1e6:.1f} us (median)")


if __name__ == "__main__":
    main()
