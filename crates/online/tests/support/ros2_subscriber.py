"""A subscriber of ROS 2's geometry_msgs/msg/Vector3Stamped written with Cyclone DDS's Python
binding, as an rclpy node on Cyclone (ROS 2's default middleware in several distributions) sees
the topic: the IDL types ROS 2 generates (module `msg::dds_`, names ending in `_`), a reliable,
volatile reader.

argv: domain id, DDS topic (`rt/contact_angle`), seconds without a sample after which to stop
once samples came, seconds after which to stop in any case, and optionally `count`. Discovery
follows CYCLONEDDS_URI (the test confines it to loopback).

With `count` (the soak test: an hour of samples would not fit a list), nothing is kept: when it
stops it prints one line `count N backwards B first_us F last_us L` (samples received, stamps not
later than the one before, first and last stamp in microseconds), then `end`.

With `poll` (the latency benchmark), the reader is polled in a loop instead of waited on, so
`recv_ns` is when Cyclone had the sample, not when the operating system woke Python up.

Prints `ready` once the reader exists, then, when it stops, one line per sample received,
`recv_ns sec nanosec frame_id x y z` (recv_ns: wall clock, time.time_ns(), when the sample was
taken; floats as repr, which round-trips exactly), then `end`.
"""
import sys, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.sub import DataReader
from cyclonedds.core import Qos, Policy, WaitSet, ReadCondition, ViewState, InstanceState, SampleState
from cyclonedds.util import duration
# Beside this script (Python puts the script's folder first on the path).
from ros2_types import Vector3Stamped_

domain, topic, idle_s, deadline_s = int(sys.argv[1]), sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
mode = sys.argv[5] if len(sys.argv) > 5 else ""
count_only, poll = mode == "count", mode == "poll"
count, backwards, first_us, last_us = 0, 0, None, None
dp = DomainParticipant(domain)
tp = Topic(dp, topic, Vector3Stamped_)
# What a default rclpy subscription asks for (reliable, volatile), with a history deep enough
# that a slow Python loop loses nothing.
qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile,
          Policy.History.KeepLast(100000))
reader = DataReader(dp, tp, qos=qos)
cond = ReadCondition(reader, SampleState.Any | ViewState.Any | InstanceState.Any)
ws = WaitSet(dp)
ws.attach(cond)
print("ready", flush=True)
start = time.monotonic()
last = None
out = []
while True:
    now = time.monotonic()
    if now - start > deadline_s or (last is not None and now - last > idle_s):
        break
    if not poll:
        ws.wait(duration(milliseconds=50))
    before = time.time_ns()
    samples = reader.take(N=1000)
    # Polling, an empty take lasts about a microsecond, so a sample that this take returns
    # reached the reader within about a microsecond of `before`; stamping after the take would
    # add Python's decoding of the sample (tens of microseconds). Waking, the sample is
    # stamped as the subscriber has it, decoded.
    t = before if poll else time.time_ns()
    for s in samples:
        # The writer leaving comes as an invalid sample (instance state, no data).
        if not isinstance(s, Vector3Stamped_):
            continue
        if count_only:
            us = s.header.stamp.sec * 1_000_000 + s.header.stamp.nanosec // 1000
            if last_us is not None and us <= last_us:
                backwards += 1
            first_us = us if first_us is None else first_us
            last_us, count = us, count + 1
            continue
        out.append(f"{t} {s.header.stamp.sec} {s.header.stamp.nanosec} {s.header.frame_id} "
                   f"{s.vector.x!r} {s.vector.y!r} {s.vector.z!r}")
    if samples:
        last = time.monotonic()
if count_only:
    print(f"count {count} backwards {backwards} first_us {first_us} last_us {last_us}")
else:
    print("\n".join(out))
print("end", flush=True)
