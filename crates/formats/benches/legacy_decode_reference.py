"""Reference timing for `legacy_decode.rs`: the AEDAT 2.0 and 3.1 files that bench wrote to
`target/bench-files/`, decoded by iniVation's own Python reader (`dv.LegacyAedatFile`, from the
`dv` package on PyPI; a Python loop over the records, as NeuroTac's first analysis code read
them). No PyPI decoder reads EVT 2.1 (expelliarmus reads EVT 2.0 / 3.0 and DAT), so that row has
no reference.

Run from the workspace root after the bench:
    .venv/bin/python crates/formats/benches/legacy_decode_reference.py target/bench-files

Prints events/s (best of N full-file reads) per file.
"""

import os
import sys
import time

from dv import LegacyAedatFile

FILES = [("aedat2", "davis240.aedat2.aedat"), ("aedat31", "davis240.aedat31.aedat")]
REPEATS = int(sys.argv[2]) if len(sys.argv) > 2 else 3


def read(path):
    """Counts the polarity events, as evtac's reader yields them."""
    n = 0
    with LegacyAedatFile(path) as f:
        for _ in f:
            n += 1
    return n


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join("target", "bench-files")
    for name, file in FILES:
        path = os.path.join(folder, file)
        n = read(path)
        times = []
        for _ in range(REPEATS):
            start = time.perf_counter()
            read(path)
            times.append(time.perf_counter() - start)
        best = min(times)
        print(f"dv.LegacyAedatFile {name}: {n} events, best {best:.3f} s ({n / best / 1e6:.2f} Melem/s)")


if __name__ == "__main__":
    main()
