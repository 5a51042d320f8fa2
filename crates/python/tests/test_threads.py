"""The interpreter is released while evtac works: another Python thread runs meanwhile."""

import sys
import threading

import numpy as np

import evtac
from evtac import _evtac


def test_other_threads_run_during_a_call(aedat):
    rec = evtac.read(aedat)
    rep = evtac.Representation("combined", sensor=rec.resolution)
    events = evtac._event_bytes(rec.events)
    t = rec.events["t"]
    times = np.linspace(t[0], t[-1], 20000).astype(np.int64)  # a call of some 100 ms
    counter = [0]
    seen = {}
    done = threading.Event()

    def work():
        # Between reading the counter and entering Rust no other thread runs unless the call
        # lets go of the interpreter (forced switches are made rare below).
        before = counter[0]
        rep._inner.features(events, times)
        seen["during"] = counter[0] - before
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
    assert seen["during"] > 0
