"""Reference timing for `evt_decode.rs`: the same Prophesee fixtures decoded by the Python
decoders installable from PyPI: `expelliarmus` (C core; the EVT3 fixture's `.expected.npy` was
written by it) and `evlib` (Rust core, returns a polars frame). Either is skipped when missing.

Run from the workspace root with the venv that has them (bench-only packages):
    .venv/bin/pip install expelliarmus evlib
    .venv/bin/python crates/formats/benches/evt_decode_reference.py

Prints events/s (best of N full-file reads, like criterion's estimate of a fast run) per file.
"""

import os
import sys
import time

try:
    from expelliarmus import Wizard
except ImportError:
    Wizard = None
try:
    import evlib
except ImportError:
    evlib = None

SHARED = os.environ.get(
    "EVTAC_SHARED",
    os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "shared"),
)
FILES = [
    ("evt3", "evt3", "prophesee_gen4_1280x720.evt3.raw"),
    ("evt2", "evt2", "prophesee_gen3_640x480.evt2.raw"),
]
REPEATS = int(sys.argv[1]) if len(sys.argv) > 1 else 30


def timed(label, n_of, read):
    """Times `read()` REPEATS times after one warm-up; prints best and median rates."""
    n = n_of(read())
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        read()
        times.append(time.perf_counter() - start)
    best, median = min(times), sorted(times)[len(times) // 2]
    print(
        f"{label}: {n} events, best {best * 1e3:.3f} ms ({n / best / 1e6:.1f} Melem/s), "
        f"median {median * 1e3:.3f} ms ({n / median / 1e6:.1f} Melem/s)"
    )


def main():
    for name, encoding, file in FILES:
        path = os.path.join(SHARED, "fixtures", "real", file)
        if Wizard is not None:
            wizard = Wizard(encoding=encoding)
            timed(f"expelliarmus {name}", len, lambda: wizard.read(path))
        if evlib is not None:
            timed(f"evlib {name}", lambda df: df.height, lambda: evlib.load_events(path).collect())


if __name__ == "__main__":
    main()
