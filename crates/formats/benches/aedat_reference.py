"""Reference decoders for the AEDAT 4.0 benchmark: times dv-processing (and the `aedat` PyPI
package when installed) decoding the files `cargo bench --bench aedat_decode` writes.

Usage: python benches/aedat_reference.py [DIR]   (DIR defaults to $EVTAC_BENCH_DIR or
<tmp>/evtac-aedat-bench). Prints events/s per decoder and file (best of 5 runs).
"""

import os
import sys
import tempfile
import time


def best_of(fn, runs=5):
    best, n = float("inf"), 0
    for _ in range(runs):
        start = time.perf_counter()
        n = fn()
        best = min(best, time.perf_counter() - start)
    return n, best


def dv_processing(path):
    import dv_processing as dv

    def run():
        r = dv.io.MonoCameraRecording(path)
        n = 0
        while True:
            b = r.getNextEventBatch()
            if b is None:
                return n
            n += len(b.numpy())  # materialise the events as numpy, as a user would

    return run


def aedat_pkg(path):
    import aedat

    def run():
        n = 0
        for packet in aedat.Decoder(path):
            if "events" in packet:
                n += len(packet["events"])
        return n

    return run


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else os.environ.get(
        "EVTAC_BENCH_DIR", os.path.join(tempfile.gettempdir(), "evtac-aedat-bench"))
    decoders = [("dv-processing", dv_processing)]
    try:
        import aedat  # noqa: F401
        decoders.append(("aedat", aedat_pkg))
    except ImportError:
        print("aedat (PyPI) not installed: skipped")
    for name in ("none", "lz4", "zstd"):
        path = os.path.join(d, f"bench_{name}.aedat4")
        for label, make in decoders:
            try:
                n, secs = best_of(make(path))
            except Exception as e:  # a decoder that cannot read the file is reported, not fatal
                print(f"{label:14s} {name:5s} failed: {e}")
                continue
            print(f"{label:14s} {name:5s} {n} events in {secs * 1e3:8.1f} ms = {n / secs / 1e6:7.1f} Mev/s")


if __name__ == "__main__":
    main()
