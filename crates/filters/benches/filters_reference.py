"""dv-processing 2.0.4's event filters from memory (events/s), the reference for
`cargo bench -p evtac-filters --bench filters`, plus `evtac filter` as a whole process.

The events are the ones the Rust bench writes (`events.aedat4`: the real DVXplorer fixture
repeated to about 2 million events, time-shifted so it stays ordered; `mask.npy`: the `mask=`
filter's mask) in DIR, read whole into one `dv.EventStore` with dv-processing's own reader
before any timing. Each filter is fresh per run and is fed 65536-event slices of that store
(shallow slices, cut before timing), `accept` then `generateEvents` per slice, the way a
streaming Python user drives it; only that loop is timed, best of 5 runs.

With `--evtac BIN` it also times `BIN filter events.aedat4 out.npy --filter
background-activity=10ms` as a whole process (AEDAT4 LZ4 decode, filter, NPY write, process
start-up and exit included), best of 5, against dv-processing's BackgroundActivityNoiseFilter
alone on the events already in memory, and checks both keep the same number of events.

Usage: python benches/filters_reference.py [DIR] [--evtac BIN]
(DIR defaults to $EVTAC_FILTER_BENCH_DIR or <tmp>/evtac-filter-bench).
"""

import argparse
import datetime
import os
import subprocess
import tempfile
import time

import numpy as np
import dv_processing as dv

CHUNK = 65536
RUNS = 5


def ms(n):
    return datetime.timedelta(milliseconds=n)


def load(path):
    """The whole file as one EventStore, and its sensor."""
    r = dv.io.MonoCameraRecording(path)
    store = dv.EventStore()
    while True:
        batch = r.getNextEventBatch()
        if batch is None:
            return store, r.getEventResolution()
        store.add(batch)


def run_filter(make, slices):
    """Best of RUNS: a fresh filter over every slice; returns (kept events, seconds)."""
    best, kept = float("inf"), 0
    for _ in range(RUNS):
        f = make()
        start = time.perf_counter()
        n = 0
        for s in slices:
            f.accept(s)
            n += f.generateEvents().size()
        best = min(best, time.perf_counter() - start)
        kept = n
    return kept, best


def whole_process(evtac, events_path, out_dir):
    """Best of RUNS wall time of `evtac filter` (AEDAT4 LZ4 in, NPY out); returns (kept, s)."""
    out = os.path.join(out_dir, "filtered.npy")
    cmd = [evtac, "filter", events_path, out, "--filter", "background-activity=10ms"]
    best = float("inf")
    for _ in range(RUNS):
        if os.path.exists(out):
            os.remove(out)
        start = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        best = min(best, time.perf_counter() - start)
    return len(np.load(out)), best


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dir", nargs="?", default=os.environ.get(
        "EVTAC_FILTER_BENCH_DIR", os.path.join(tempfile.gettempdir(), "evtac-filter-bench")))
    p.add_argument("--evtac", help="the evtac binary, to time `evtac filter` as a whole process")
    args = p.parse_args()

    events_path = os.path.join(args.dir, "events.aedat4")
    store, res = load(events_path)
    mask = np.load(os.path.join(args.dir, "mask.npy"))
    assert mask.dtype == np.uint8 and mask.shape == (res[1], res[0]), mask.shape
    n = store.size()
    slices = [store.slice(i, min(CHUNK, n - i)) for i in range(0, n, CHUNK)]
    print(f"{n} events, {res[0]}x{res[1]}, {len(slices)} slices of {CHUNK}; best of {RUNS}")

    filters = [
        ("background-activity", lambda: dv.noise.BackgroundActivityNoiseFilter(
            res, backgroundActivityDuration=ms(10))),
        ("fast-decay", lambda: dv.noise.FastDecayNoiseFilter(res)),
        ("k-noise", lambda: dv.noise.KNoiseFilter(res, timeDelta=ms(1))),
        ("polarity", lambda: dv.EventPolarityFilter(True)),
        ("region", lambda: dv.EventRegionFilter((40, 0, 240, 240))),
        ("mask", lambda: dv.EventMaskFilter(mask)),
    ]
    ba = None
    for name, make in filters:
        kept, secs = run_filter(make, slices)
        if name == "background-activity":
            ba = (kept, secs)
        print(f"dv-processing {name:20s} kept {kept:8d}  {secs * 1e3:8.1f} ms = "
              f"{n / secs / 1e6:7.1f} Mev/s")

    if args.evtac:
        with tempfile.TemporaryDirectory() as out_dir:
            kept, secs = whole_process(args.evtac, events_path, out_dir)
        print(f"evtac filter (whole process) background-activity=10ms kept {kept:8d}  "
              f"{secs * 1e3:8.1f} ms = {n / secs / 1e6:7.1f} Mev/s; "
              f"{ba[1] / secs:.2f}x dv-processing's filter alone in memory")
        assert kept == ba[0], f"evtac kept {kept}, dv-processing {ba[0]}"


if __name__ == "__main__":
    main()
