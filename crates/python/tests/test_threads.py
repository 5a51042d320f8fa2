"""The interpreter is released while evtac works: another Python thread runs meanwhile."""

import sys
import threading
import time

import numpy as np
import pytest

import evtac
from evtac import _evtac


def _counted_while(call):
    """How often the main thread counted while ``call`` ran in another thread. Between reading
    the counter and entering Rust no other thread runs unless the call lets go of the
    interpreter (forced switches are made rare)."""
    counter = [0]
    seen = {}
    done = threading.Event()

    def work():
        before = counter[0]
        # Repeated for some 200 ms (well under the switch interval): on a loaded machine the
        # counting thread may take longer than one short call to be scheduled.
        end = time.perf_counter() + 0.2
        try:
            while time.perf_counter() < end:
                call()
            seen["during"] = counter[0] - before
        finally:
            done.set()

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1.0)
    try:
        worker = threading.Thread(target=work)
        worker.start()
        while not done.is_set():
            counter[0] += 1
        worker.join()
    finally:
        sys.setswitchinterval(interval)
    return seen["during"]


def _calls(aedat):
    """Native calls of some 10-100 ms each."""
    rec = evtac.read(aedat)
    rep = evtac.Representation("combined", sensor=rec.resolution)
    events = evtac._event_bytes(rec.events)
    t = rec.events["t"]
    times = np.linspace(t[0], t[-1], 20000).astype(np.int64)
    model = evtac.Model.untrained(0)
    features = np.ascontiguousarray(
        np.random.default_rng(0).random((20000, 900)) < 0.1, dtype=np.float32)
    incremental = evtac.Representation("combined", sensor=rec.resolution)._inner

    def push():
        incremental.reset()
        incremental.push(events)
        incremental.advance_to(int(t[-1]))
    return {
        "features": lambda: rep._inner.features(events, times),
        "read": lambda: _evtac.read(str(aedat)),
        "predict": lambda: model._inner.predict(features),
        "estimator": lambda: _evtac.Estimator(model._inner, rec.resolution, 100).push(events),
        "push": push,
    }


@pytest.mark.parametrize("name", ["features", "read", "predict", "estimator", "push"])
def test_other_threads_run_during_a_call(aedat, name):
    assert _counted_while(_calls(aedat)[name]) > 0
