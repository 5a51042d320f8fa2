"""Writes the seed files of the `rosbag` and `mcap` fuzz corpora: small ROS bags written by the
`rosbags` package (ROS 1 uncompressed, bz2 and lz4; rosbag2 MCAP plain and zstd) and the `mcap`
package (lz4), holding dvs_msgs/EventArray, event_camera_msgs/EventPacket (evt3 words from the
real Prophesee recording, and mono) and sensor_msgs/Imu messages, each file a few KiB.

    .venv/bin/python fuzz/make_ros_seeds.py OUT_DIR [FIXTURES_DIR]

OUT_DIR gets `rosbag/` and `mcap/`; FIXTURES_DIR defaults to ../shared/fixtures/real.
"""

import os
import shutil
import sys
import tempfile

import numpy as np
from mcap.writer import CompressionType, Writer as McapWriter
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Writer as Writer2
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode, StoragePlugin
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

S = sys.argv[1]
R = sys.argv[2] if len(sys.argv) > 2 else os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "fixtures", "real"
)
for target in ("rosbag", "mcap"):
    os.makedirs(os.path.join(S, target), exist_ok=True)
rng = np.random.default_rng(11)
PACKET = ("std_msgs/Header header\nuint32 height\nuint32 width\nuint64 seq\nuint64 time_base\n"
          "string encoding\nbool is_bigendian\nuint8[] events\n")
ARRAY = "std_msgs/Header header\nuint32 height\nuint32 width\ndvs_msgs/Event[] events\n"


def store(ros1):
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    event = "uint16 x\nuint16 y\n" + ("time" if ros1 else "builtin_interfaces/Time") + " ts\nbool polarity\n"
    types = {}
    types.update(get_types_from_msg(event, "dvs_msgs/msg/Event"))
    types.update(get_types_from_msg(ARRAY, "dvs_msgs/msg/EventArray"))
    types.update(get_types_from_msg(PACKET, "event_camera_msgs/msg/EventPacket"))
    ts.register(types)
    return ts


def header(ts, ros1, ns):
    T, H = ts.types["builtin_interfaces/msg/Time"], ts.types["std_msgs/msg/Header"]
    stamp = T(sec=ns // 10**9, nanosec=ns % 10**9)
    return H(seq=0, stamp=stamp, frame_id="c") if ros1 else H(stamp=stamp, frame_id="c")


def messages(ts, ros1, evt3_words):
    """(topic, type, [(t_ns, msg)]) for an event array topic, an IMU topic and a packet topic."""
    T = ts.types["builtin_interfaces/msg/Time"]
    Ev, Arr = ts.types["dvs_msgs/msg/Event"], ts.types["dvs_msgs/msg/EventArray"]
    Imu, V, Q = (ts.types[n] for n in ("sensor_msgs/msg/Imu", "geometry_msgs/msg/Vector3",
                                        "geometry_msgs/msg/Quaternion"))
    Pkt = ts.types["event_camera_msgs/msg/EventPacket"]
    t0 = 1_600_000_000 * 10**9
    arrays, imus, packets = [], [], []
    for k in range(2):
        evs = [Ev(x=int(rng.integers(0, 64)), y=int(rng.integers(0, 48)),
                  ts=T(sec=1_600_000_000, nanosec=k * 1000 + i), polarity=bool(i % 2)) for i in range(4)]
        arrays.append((t0 + k, Arr(header=header(ts, ros1, t0 + k), height=48, width=64, events=evs)))
        v = V(x=0.1, y=-9.8, z=0.2)
        imus.append((t0 + k, Imu(header=header(ts, ros1, t0 + k), orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
                                 orientation_covariance=np.zeros(9), angular_velocity=v,
                                 angular_velocity_covariance=np.zeros(9), linear_acceleration=v,
                                 linear_acceleration_covariance=np.zeros(9))))
    for k, piece in enumerate(evt3_words):
        packets.append((t0 + k, Pkt(header=header(ts, ros1, t0 + k), height=720, width=1280, seq=k,
                                    time_base=0, encoding="evt3", is_bigendian=False,
                                    events=np.frombuffer(piece, dtype=np.uint8))))
    word = (np.uint64(1) << np.uint64(63)) | (np.uint64(5) << np.uint64(48)) | (np.uint64(9) << np.uint64(32)) | np.uint64(77)
    packets.append((t0 + 9, Pkt(header=header(ts, ros1, t0 + 9), height=48, width=64, seq=9,
                                time_base=t0, encoding="mono", is_bigendian=False,
                                events=np.frombuffer(np.array([word], "<u8").tobytes(), dtype=np.uint8))))
    return [("/dvs/events", "dvs_msgs/msg/EventArray", arrays), ("/dvs/imu", "sensor_msgs/msg/Imu", imus),
            ("/cam/events", "event_camera_msgs/msg/EventPacket", packets)]


raw = open(os.path.join(R, "prophesee_gen4_1280x720.evt3.raw"), "rb").read()
pos = 0
while raw[pos:pos + 1] == b"%":
    pos = raw.index(b"\n", pos) + 1
words = raw[pos:pos + 600]
evt3_words = [words[:200], words[200:424], words[424:]]

ts1, ts2 = store(True), store(False)
for name, comp in (("plain", None), ("bz2", Writer1.CompressionFormat.BZ2), ("lz4", Writer1.CompressionFormat.LZ4)):
    path = os.path.join(S, "rosbag", f"{name}.bag")
    if os.path.exists(path):
        os.remove(path)
    w = Writer1(path)
    if comp:
        w.set_compression(comp)
    with w:
        for topic, msgtype, msgs in messages(ts1, True, evt3_words):
            conn = w.add_connection(topic, msgtype, typestore=ts1)
            for t, m in msgs:
                w.write(conn, t, ts1.serialize_ros1(m, msgtype))

tmp = tempfile.mkdtemp()
for name, zstd in (("plain", False), ("zstd", True)):
    folder = os.path.join(tmp, name)
    w = Writer2(folder, version=9, storage_plugin=StoragePlugin.MCAP)
    if zstd:
        w.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with w:
        for topic, msgtype, msgs in messages(ts2, False, evt3_words):
            conn = w.add_connection(topic, msgtype, typestore=ts2)
            for t, m in msgs:
                w.write(conn, t, ts2.serialize_cdr(m, msgtype))
    shutil.copy(os.path.join(folder, f"{name}.mcap"), os.path.join(S, "mcap", f"{name}.mcap"))
shutil.rmtree(tmp)
with open(os.path.join(S, "mcap", "lz4.mcap"), "wb") as f:
    w = McapWriter(f, compression=CompressionType.LZ4)
    w.start(profile="ros2", library="evtac-seeds")
    for topic, msgtype, msgs in messages(ts2, False, evt3_words):
        sid = w.register_schema(name=msgtype, encoding="ros2msg", data=b"")
        ch = w.register_channel(topic=topic, message_encoding="cdr", schema_id=sid)
        for t, m in msgs:
            w.add_message(channel_id=ch, log_time=t, publish_time=t, data=bytes(ts2.serialize_cdr(m, msgtype)))
    w.finish()
