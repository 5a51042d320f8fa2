"""Splits the ROS 2 publishing latency at the wire (see `ros2_latency.rs`).

    python3 ros2_hops.py capture OUT SECONDS   # as root, started before the benchmark
    python3 ros2_hops.py split DUMP OUT        # after it: DUMP from EVTAC_ROS2_BENCH_DUMP

`capture` reads every datagram on `lo` through a packet socket, with the kernel's receive time
(SO_TIMESTAMPNS, the wall clock the benchmark's stamps use too), finds each serialized
Vector3Stamped in it by its frame id (`neurotac`; CDR: sec, nanosec and the string's length
precede it) and writes `t_us wire_ns` per message. A packet socket sees each loopback datagram
once as sent and once as received; only the received copy is kept.

`split` pairs each estimate of the dump with its datagram (same `t_us`, the one nearest its hand
over, since repeated runs reuse the stamps) and prints median, P90 and P99 of: handed -> wire
(evtac), wire -> received (the subscriber), and the whole.
"""
import collections, socket, struct, sys, time

FRAME = b"neurotac\x00"
SO_TIMESTAMPNS = 35


def capture(out_path, seconds):
    s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(3))  # ETH_P_ALL
    s.bind(("lo", 0))
    s.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
    s.settimeout(0.5)
    deadline = time.time() + seconds
    with open(out_path, "w") as out:
        while time.time() < deadline:
            try:
                data, ancillary, _, address = s.recvmsg(65536, 1024)
            except socket.timeout:
                continue
            if address[2] == socket.PACKET_OUTGOING:
                continue
            wire = next(struct.unpack("qq", d[:16]) for level, kind, d in ancillary
                        if kind == SO_TIMESTAMPNS)
            wire_ns = wire[0] * 10**9 + wire[1]
            at = data.find(FRAME)
            while at >= 12:
                sec, nanosec, length = struct.unpack_from("<iII", data, at - 12)
                if length == len(FRAME):
                    out.write(f"{sec * 1_000_000 + nanosec // 1000} {wire_ns}\n")
                at = data.find(FRAME, at + len(FRAME))


def split(dump_path, captured_path):
    wire = collections.defaultdict(list)
    for line in open(captured_path):
        t_us, ns = map(int, line.split())
        wire[t_us].append(ns)
    parts = {"handed -> wire (evtac)": [], "wire -> received (subscriber)": [], "whole": []}
    for line in open(dump_path):
        t_us, handed, received = map(int, line.split())
        near = [w for w in wire.get(t_us, []) if handed - 10**6 < w < received + 10**6]
        if not near:
            continue
        w = min(near, key=lambda w: abs(w - handed))
        for name, ns in zip(parts, (w - handed, received - w, received - handed)):
            parts[name].append(ns / 1000)
    for name, us in parts.items():
        us.sort()
        at = lambda q: us[int((len(us) - 1) * q)]
        print(f"{name}: {len(us)} estimates, median {at(0.5):.0f} us, P90 {at(0.9):.0f} us, "
              f"P99 {at(0.99):.0f} us")


if __name__ == "__main__":
    if sys.argv[1] == "capture":
        capture(sys.argv[2], float(sys.argv[3]))
    else:
        split(sys.argv[2], sys.argv[3])
