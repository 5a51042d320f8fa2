"""A ROS 2 event camera driver's publisher, written with Cyclone DDS's Python binding: the IDL
types ROS 2 generates for event_camera_msgs/msg/EventPacket and dvs_msgs/msg/EventArray (module
`msg::dds_`, names ending in `_`), plain CDR (XCDR1, as rmw_cyclonedds_cpp writes), keep last,
volatile, reliable or best effort.

argv: domain id, DDS topic (`rt/event_camera/events`), `packet` or `array`, `reliable` or
`best_effort`, the EVT 3.0 fixture (.raw), its decoded events (.npy: t us, x, y, p), the MCAP
file to write, how many messages to publish (`all`, or a count: a publisher that stops there),
and `leave` (delete the writer at the end) or `stay` (stay silent until killed); optionally the
index of a packet to send broken (its events an odd number of bytes, no whole EVT3 words),
which the MCAP file then leaves out.

`packet`: the fixture's EVT3 words cut into packets of uneven (even) sizes, as the metavision
driver cuts the camera's stream. `array`: the decoded events, 3000 to a message, `ts` = t us as
seconds and nanoseconds. Either way the messages published are also written, byte for byte as
serialized, to the MCAP file (schema and channel as rosbag2 writes them), so that the bag
readers see exactly what the subscriber was sent.

Discovery follows CYCLONEDDS_URI (the test confines it to loopback). The script waits (up to
60 s) for a reader to match before it publishes: volatile durability delivers nothing published
before. Prints `matched`, then `published N` when done.
"""
import sys, time
import numpy as np
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter
from cyclonedds.core import Qos, Policy
from cyclonedds.util import duration
from mcap.writer import Writer as McapWriter, CompressionType
# Beside this script (Python puts the script's folder first on the path).
from ros2_types import Time_, Header_, EventPacket_, Event_, EventArray_

HEADER = "std_msgs/Header header\n"
TIME = ("\n================================================================================\n"
        "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
        "\n================================================================================\n"
        "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n")
SCHEMAS = {
    "packet": ("event_camera_msgs/msg/EventPacket",
               HEADER + "uint32 height\nuint32 width\nuint64 seq\nuint64 time_base\n"
               "string encoding\nbool is_bigendian\nuint8[] events\n" + TIME),
    "array": ("dvs_msgs/msg/EventArray",
              HEADER + "uint32 height\nuint32 width\ndvs_msgs/Event[] events\n" + TIME +
              "\n================================================================================\n"
              "MSG: dvs_msgs/Event\nuint16 x\nuint16 y\nbuiltin_interfaces/Time ts\nbool polarity\n"),
}

(domain, topic, kind, reliability, raw_path, npy_path, bag_path, count, end) = sys.argv[1:10]
broken = int(sys.argv[10]) if len(sys.argv) > 10 else -1
domain = int(domain)
W, H = 1280, 720
STAMP = 1_700_000_000  # header stamps: a ROS clock, unrelated to the camera's counter

def header(k):
    return Header_(stamp=Time_(sec=STAMP + k // 1000, nanosec=(k % 1000) * 1_000_000), frame_id="camera")

messages = []
if kind == "packet":
    with open(raw_path, "rb") as f:
        raw = f.read()
    pos = 0
    while raw[pos:pos + 1] == b"%":
        pos = raw.index(b"\n", pos) + 1
    words = raw[pos:]
    rng = np.random.default_rng(11)
    cuts, at = [], 0
    while True:
        at += 2 * int(rng.integers(500, 5000))
        if at >= len(words):
            break
        cuts.append(at)
    for k, (a, b) in enumerate(zip([0] + cuts, cuts + [len(words)])):
        messages.append(EventPacket_(header=header(k), height=H, width=W, seq=k, time_base=0,
                                     encoding="evt3", is_bigendian=False, events=words[a:b]))
else:
    ev = np.load(npy_path)
    for k, a in enumerate(range(0, len(ev), 3000)):
        part = ev[a:a + 3000]
        messages.append(EventArray_(header=header(k), height=H, width=W, events=[
            Event_(x=int(e["x"]), y=int(e["y"]),
                   ts=Time_(sec=int(e["t"]) // 1_000_000, nanosec=int(e["t"]) % 1_000_000 * 1000),
                   polarity=bool(e["p"])) for e in part]))
if count != "all":
    messages = messages[:int(count)]

dp = DomainParticipant(domain)
Type = EventPacket_ if kind == "packet" else EventArray_
tp = Topic(dp, topic, Type)
rel = (Policy.Reliability.Reliable(duration(seconds=1)) if reliability == "reliable"
       else Policy.Reliability.BestEffort)
qos = Qos(rel, Policy.Durability.Volatile, Policy.History.KeepLast(len(messages) + 1),
          Policy.DataRepresentation(use_cdrv0_representation=True))
writer = DataWriter(dp, tp, qos=qos)
start = time.monotonic()
while writer.get_publication_matched_status().current_count < 1:
    if time.monotonic() - start > 60:
        sys.exit("no reader matched within 60 s")
    time.sleep(0.01)
# The reader's side of the match (its discovery of this writer) may come a moment later.
time.sleep(0.5)
print("matched", flush=True)

name, definition = SCHEMAS[kind]
with open(bag_path, "wb") as f:
    bag = McapWriter(f, compression=CompressionType.NONE)
    bag.start(profile="ros2", library="evtac-test")
    schema = bag.register_schema(name=name, encoding="ros2msg", data=definition.encode())
    channel = bag.register_channel(topic="/" + topic[3:], message_encoding="cdr", schema_id=schema)
    for k, m in enumerate(messages):
        if k == broken:
            m.events = m.events[:-1]
            writer.write(m)
            continue
        t = (STAMP * 1000 + k) * 1_000_000
        bag.add_message(channel_id=channel, log_time=t, publish_time=t,
                        data=m.serialize(use_version_2=False))
        writer.write(m)
        # A driver's pace, roughly: a packet every few hundred microseconds.
        time.sleep(0.0003)
    bag.finish()
if reliability == "reliable":
    writer.wait_for_acks(duration(seconds=10))
print(f"published {len(messages)}", flush=True)
if end == "stay":
    while True:
        time.sleep(1)
