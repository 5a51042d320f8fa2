"""ROS bags: evtac against the fastest Python way to get the same events.

    .venv/bin/python crates/formats/benches/ros_reference.py [target/release/evtac] [EVENTS]

Writes the same recording twice with the `rosbags` package, EVENTS events in all (default
3,000,000) in `dvs_msgs/EventArray` messages of 25,000 events, 346 x 260: a ROS 1 `.bag`
(uncompressed chunks) and a ROS 2 `.mcap` (rosbag2, CDR). The messages are serialized here with
numpy (the layouts `evtac_events::ros` documents) because building millions of message objects
would take longer than any reader. Then times, best of 5, on the same files:

- Python: `rosbags`' readers for the raw message bytes (the way to skip its per-event Python
  objects, which cost about a microsecond each), then every message's events viewed as a numpy
  structured array and concatenated into t (us, truncated like evtac), x, y, p arrays. ROS 1
  events are packed 13-byte records; CDR aligns each event's `ts` to 4 bytes, so after the
  first event (13 bytes + 1 of padding) they are 16-byte records.
- evtac (when its binary is given): `evtac info FILE`, one process per run; and the same less
  its process start (`evtac info` of a one-message bag, timed the same way), the part that
  compares with Python's in-process read.

Prints one line per contender with seconds and events per second, and checks that both Python
readers found the same events.
"""

import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from rosbags.rosbag1 import Reader as Reader1
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Reader as Reader2
from rosbags.rosbag2 import Writer as Writer2
from rosbags.rosbag2.enums import StoragePlugin
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

EXE = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].isdigit() else None
N = int(sys.argv[-1]) if len(sys.argv) > 1 and sys.argv[-1].isdigit() else 3_000_000
PER_MSG = 25_000
W, H = 346, 260
T0 = 1_600_000_000 * 10**9
rng = np.random.default_rng(0)

ROS1_EVENT = np.dtype([("x", "<u2"), ("y", "<u2"), ("sec", "<u4"), ("nsec", "<u4"), ("p", "u1")])
CDR_EVENT = np.dtype({"names": ["x", "y", "sec", "nsec", "p"],
                      "formats": ["<u2", "<u2", "<i4", "<u4", "u1"],
                      "offsets": [0, 2, 4, 8, 12], "itemsize": 16})
CDR_LATER = np.dtype({"names": ["x", "y", "sec", "nsec", "p"],
                      "formats": ["<u2", "<u2", "<i4", "<u4", "u1"],
                      "offsets": [0, 2, 6, 10, 14], "itemsize": 16})


def typestore(ros1):
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    event = "uint16 x\nuint16 y\n" + ("time" if ros1 else "builtin_interfaces/Time") + " ts\nbool polarity\n"
    types = get_types_from_msg(event, "dvs_msgs/msg/Event")
    types.update(get_types_from_msg("std_msgs/Header header\nuint32 height\nuint32 width\n"
                                    "dvs_msgs/Event[] events\n", "dvs_msgs/msg/EventArray"))
    ts.register(types)
    return ts


def recording(n):
    ns = T0 + np.cumsum(rng.integers(0, 2_000, n, dtype=np.int64))
    return (ns, rng.integers(0, W, n).astype(np.uint16), rng.integers(0, H, n).astype(np.uint16),
            rng.integers(0, 2, n).astype(np.uint8))


def ros1_message(ns, x, y, p):
    """Header (seq, stamp, frame_id ""), height, width, the events as 13-byte records."""
    ev = np.empty(len(x), ROS1_EVENT)
    ev["x"], ev["y"], ev["sec"], ev["nsec"], ev["p"] = x, y, ns // 10**9, ns % 10**9, p
    head = np.array([0, ns[-1] // 10**9, ns[-1] % 10**9, 0, H, W, len(x)], "<u4").tobytes()
    return head + ev.tobytes()


def cdr_message(ns, x, y, p):
    """Encapsulation, header (stamp, frame_id "" as length 1 + NUL, padded), height, width,
    count, the first event in 13 bytes + 1 of padding, then 16-byte events."""
    ev = np.zeros(len(x), CDR_LATER)
    ev["x"], ev["y"], ev["sec"], ev["nsec"], ev["p"] = x, y, ns // 10**9, ns % 10**9, p
    first = np.zeros(1, CDR_EVENT)
    for k in CDR_EVENT.names:
        first[k] = ev[k][0]
    head = (b"\x00\x01\x00\x00" + np.array([ns[-1] // 10**9, ns[-1] % 10**9, 1], "<u4").tobytes()
            + b"\x00\x00\x00\x00" + np.array([H, W, len(x)], "<u4").tobytes())
    return head + first.tobytes()[:14] + ev[1:].tobytes()[: 16 * (len(x) - 1) - 1]


def check_layout():
    """The numpy-built messages must be what `rosbags` itself deserializes."""
    ns, x, y, p = recording(5)
    for ros1, raw in ((True, ros1_message(ns, x, y, p)), (False, cdr_message(ns, x, y, p))):
        ts = typestore(ros1)
        msg = (ts.deserialize_ros1 if ros1 else ts.deserialize_cdr)(raw, "dvs_msgs/msg/EventArray")
        assert (msg.height, msg.width) == (H, W)
        got = [(e.x, e.y, e.ts.sec * 10**9 + e.ts.nanosec, int(e.polarity)) for e in msg.events]
        assert got == list(zip(x.tolist(), y.tolist(), ns.tolist(), p.tolist())), (ros1, got)


def write(folder, n):
    check_layout()
    ns, x, y, p = recording(n)
    bag, mcap = os.path.join(folder, "events.bag"), os.path.join(folder, "events_mcap")
    with Writer1(bag) as w:
        conn = w.add_connection("/dvs/events", "dvs_msgs/msg/EventArray", typestore=typestore(True))
        for s in range(0, n, PER_MSG):
            sl = slice(s, s + PER_MSG)
            w.write(conn, int(ns[sl][-1]), ros1_message(ns[sl], x[sl], y[sl], p[sl]))
    w2 = Writer2(mcap, version=9, storage_plugin=StoragePlugin.MCAP)
    with w2:
        conn = w2.add_connection("/dvs/events", "dvs_msgs/msg/EventArray", typestore=typestore(False))
        for s in range(0, n, PER_MSG):
            sl = slice(s, s + PER_MSG)
            w2.write(conn, int(ns[sl][-1]), cdr_message(ns[sl], x[sl], y[sl], p[sl]))
    return bag, mcap


def arrays(records):
    ev = np.concatenate(records)
    t = ev["sec"].astype(np.int64) * 1_000_000 + ev["nsec"] // 1000
    return t, ev["x"], ev["y"], ev["p"]


def python_ros1(path):
    records = []
    with Reader1(path) as r:
        for _, _, raw in r.messages():
            frame_id = int.from_bytes(raw[12:16], "little")
            body = 16 + frame_id + 8
            n = int.from_bytes(raw[body:body + 4], "little")
            records.append(np.frombuffer(raw, ROS1_EVENT, n, body + 4))
    return arrays(records)


def python_mcap(path):
    records = []
    with Reader2(path) as r:
        for _, _, raw in r.messages():
            frame_id = int.from_bytes(raw[12:16], "little")
            body = 16 + frame_id
            body += -(body - 4) % 4  # align the height to 4 past the encapsulation header
            n = int.from_bytes(raw[body + 8:body + 12], "little")
            start = body + 12
            first = np.frombuffer(raw[start:start + 14] + b"\x00\x00", CDR_EVENT, 1)
            later = np.frombuffer(raw[start + 14:] + b"\x00\x00", CDR_LATER, n - 1)
            records += [first.astype(CDR_LATER), later]
    return arrays(records)


def best(f, runs=5):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - start)
    return min(times), out


def main():
    with tempfile.TemporaryDirectory() as d:
        bag, mcap = write(d, N)
        results = []
        for name, f in (("python rosbags ROS 1 + numpy", lambda: python_ros1(bag)),
                        ("python rosbags MCAP + numpy", lambda: python_mcap(mcap))):
            secs, out = best(f)
            results.append(out)
            print(f"{name:32s} {secs:8.3f} s  {N / secs / 1e6:7.2f} Mev/s")
        for a, b in zip(*results):
            assert np.array_equal(a, b), "the two Python readers disagree"
        assert len(results[0][0]) == N
        if EXE:
            def info(path):
                return subprocess.run([EXE, "info", path], check=True, stdout=subprocess.DEVNULL)
            tiny = os.path.join(d, "tiny")
            os.mkdir(tiny)
            tiny_bag, _ = write(tiny, PER_MSG)
            start, _ = best(lambda: info(tiny_bag), 10)
            print(f"{'evtac info, one-message bag':32s} {start:8.3f} s  (the process start)")
            for name, path in (("evtac info (ROS 1 bag)", bag), ("evtac info (MCAP)", mcap)):
                secs, _ = best(lambda: info(path))
                print(f"{name:32s} {secs:8.3f} s  {N / secs / 1e6:7.2f} Mev/s  "
                      f"(less the start {secs - start:6.3f} s)")


if __name__ == "__main__":
    main()
