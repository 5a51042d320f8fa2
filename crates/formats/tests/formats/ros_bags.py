"""Writes the ROS bags that `ros.rs` reads, with the `rosbags` package (ROS 1 and rosbag2 MCAP
writers) and the `mcap` package, and beside each the values the reader must produce, computed
here from the source arrays: `NAME.events.csv` (t us, x, y, p) and `NAME.imu.csv` (t us, accel g,
gyro deg/s).

Usage: ros_bags.py OUT_DIR [EVT3_RAW]. With the EVT3 fixture, also the `evt3` bag: its words cut
into event_camera_msgs/EventPacket messages.
"""
import os, sys
import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Writer as Writer2
from rosbags.rosbag2.enums import CompressionMode, CompressionFormat, StoragePlugin
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

d = sys.argv[1]
raw_path = sys.argv[2] if len(sys.argv) > 2 else None
rng = np.random.default_rng(7)
EVENT1 = "uint16 x\nuint16 y\ntime ts\nbool polarity\n"
EVENT2 = "uint16 x\nuint16 y\nbuiltin_interfaces/Time ts\nbool polarity\n"
ARRAY = "std_msgs/Header header\nuint32 height\nuint32 width\ndvs_msgs/Event[] events\n"
PACKET = ("std_msgs/Header header\nuint32 height\nuint32 width\nuint64 seq\nuint64 time_base\n"
          "string encoding\nbool is_bigendian\nuint8[] events\n")

def store(ros1):
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    types = {}
    types.update(get_types_from_msg(EVENT1 if ros1 else EVENT2, 'dvs_msgs/msg/Event'))
    types.update(get_types_from_msg(ARRAY, 'dvs_msgs/msg/EventArray'))
    types.update(get_types_from_msg(PACKET, 'event_camera_msgs/msg/EventPacket'))
    ts.register(types)
    return ts

def header(ts, ros1, sec, nsec, seq=0):
    T = ts.types['builtin_interfaces/msg/Time']
    H = ts.types['std_msgs/msg/Header']
    if ros1:
        return H(seq=seq, stamp=T(sec=sec, nanosec=nsec), frame_id='cam')
    return H(stamp=T(sec=sec, nanosec=nsec), frame_id='cam')

W, H_ = 346, 260
def dvs_messages(ts, ros1, n_msgs, per_msg, t0_sec):
    """EventArray messages and the expected events (t us truncated, x, y, p)."""
    Ev = ts.types['dvs_msgs/msg/Event']; Arr = ts.types['dvs_msgs/msg/EventArray']
    T = ts.types['builtin_interfaces/msg/Time']
    msgs, rows = [], []
    ns = t0_sec * 10**9 + 123_456_789
    for m in range(n_msgs):
        evs = []
        for _ in range(per_msg):
            ns += int(rng.integers(0, 40_000))
            x, y, p = int(rng.integers(0, W)), int(rng.integers(0, H_)), int(rng.integers(0, 2))
            sec, nsec = divmod(ns, 10**9)
            evs.append(Ev(x=x, y=y, ts=T(sec=sec, nanosec=nsec), polarity=bool(p)))
            rows.append((sec * 1_000_000 + nsec // 1000, x, y, p))
        sec, nsec = divmod(ns, 10**9)
        msgs.append((ns, Arr(header=header(ts, ros1, sec, nsec, m), height=H_, width=W, events=evs)))
    return msgs, rows

def imu_messages(ts, ros1, n, t0_sec):
    """Imu messages and the expected samples (t us, accel g, gyro deg/s)."""
    Imu = ts.types['sensor_msgs/msg/Imu']; V = ts.types['geometry_msgs/msg/Vector3']
    Q = ts.types['geometry_msgs/msg/Quaternion']
    msgs, rows = [], []
    ns = t0_sec * 10**9 + 123_654_321
    for k in range(n):
        ns += 1_000_000 + int(rng.integers(0, 999))
        sec, nsec = divmod(ns, 10**9)
        acc = rng.normal(0, 3, 3); acc[2] += 9.81
        gyr = rng.normal(0, 0.5, 3)
        m = Imu(header=header(ts, ros1, sec, nsec, k), orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=np.full(9, 0.5),
                angular_velocity=V(x=gyr[0], y=gyr[1], z=gyr[2]),
                angular_velocity_covariance=np.full(9, 0.25),
                linear_acceleration=V(x=acc[0], y=acc[1], z=acc[2]),
                linear_acceleration_covariance=np.full(9, 0.125))
        msgs.append((ns, m))
        rows.append((sec * 1_000_000 + nsec // 1000, *(acc / 9.80665), *np.degrees(gyr)))
    return msgs, rows

def save(name, rows):
    with open(os.path.join(d, name), 'w') as f:
        f.writelines(','.join(repr(float(v)) if isinstance(v, float) else str(v) for v in r) + '\n' for r in rows)

def write1(path, topics, compression=None):
    w = Writer1(path)
    if compression:
        w.set_compression(compression)
    with w:
        conns = {name: w.add_connection(name, msgtype, typestore=ts1) for name, msgtype, _ in topics}
        allm = sorted(((t, name, msgtype, m) for name, msgtype, ms in topics for t, m in ms), key=lambda r: r[0])
        for t, name, msgtype, m in allm:
            w.write(conns[name], t, ts1.serialize_ros1(m, msgtype))

def write2(path, topics, compressed=False):
    w = Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP)
    if compressed:
        w.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with w:
        conns = {name: w.add_connection(name, msgtype, typestore=ts2) for name, msgtype, _ in topics}
        allm = sorted(((t, name, msgtype, m) for name, msgtype, ms in topics for t, m in ms), key=lambda r: r[0])
        for t, name, msgtype, m in allm:
            w.write(conns[name], t, ts2.serialize_cdr(m, msgtype))

ts1, ts2 = store(True), store(False)
STR = 'std_msgs/msg/String'

# ROS 1: dvs events and IMU, uncompressed, bz2 and lz4 chunks.
ev, ev_rows = dvs_messages(ts1, True, 12, 400, 1_600_000_000)
imu, imu_rows = imu_messages(ts1, True, 50, 1_600_000_000)
note = [(1_600_000_000 * 10**9 + 5, ts1.types[STR](data='hello'))]
topics1 = [('/dvs/events', 'dvs_msgs/msg/EventArray', ev), ('/dvs/imu', 'sensor_msgs/msg/Imu', imu),
           ('/note', STR, note)]
for name, comp in [('dvs.bag', None), ('dvs_bz2.bag', Writer1.CompressionFormat.BZ2),
                   ('dvs_lz4.bag', Writer1.CompressionFormat.LZ4)]:
    write1(os.path.join(d, name), topics1, comp)
save('dvs1.events.csv', ev_rows); save('dvs1.imu.csv', imu_rows)

# ROS 2: the same kind in MCAP, plain and zstd chunks, as a rosbag2 folder.
ev, ev_rows = dvs_messages(ts2, False, 9, 300, 1_700_000_000)
imu, imu_rows = imu_messages(ts2, False, 40, 1_700_000_000)
topics2 = [('/dvs/events', 'dvs_msgs/msg/EventArray', ev), ('/dvs/imu', 'sensor_msgs/msg/Imu', imu)]
write2(os.path.join(d, 'dvs2'), topics2)
write2(os.path.join(d, 'dvs2_zstd'), topics2, compressed=True)
save('dvs2.events.csv', ev_rows); save('dvs2.imu.csv', imu_rows)

# ROS 2: the real EVT3 words cut into packets of uneven (even) sizes.
Pkt = ts2.types['event_camera_msgs/msg/EventPacket']
def evt3_bag(raw_path):
    with open(raw_path, 'rb') as f:
        raw = f.read()
    pos = 0
    while raw[pos:pos + 1] == b'%':
        pos = raw.index(b'\n', pos) + 1
    words = raw[pos:]
    assert len(words) % 2 == 0
    cuts = sorted(set(int(c) * 2 for c in rng.integers(1, len(words) // 2, 7)))
    pieces = [words[a:b] for a, b in zip([0] + cuts, cuts + [len(words)])]
    packets = []
    for k, piece in enumerate(pieces):
        t = 1_700_000_100 * 10**9 + k * 1_000_000
        packets.append((t, Pkt(header=header(ts2, False, *divmod(t, 10**9)), height=720, width=1280, seq=k,
                               time_base=0, encoding='evt3', is_bigendian=False,
                               events=np.frombuffer(piece, dtype=np.uint8))))
    imu, imu_rows = imu_messages(ts2, False, 20, 1_700_000_100)
    write2(os.path.join(d, 'evt3'), [('/prophesee/events', 'event_camera_msgs/msg/EventPacket', packets),
                                    ('/prophesee/imu', 'sensor_msgs/msg/Imu', imu)])
    # The same packets in a ROS 1 bag (event_camera_msgs builds for ROS 1 too), lz4 chunks.
    Pkt1 = ts1.types['event_camera_msgs/msg/EventPacket']
    packets1 = [(t, Pkt1(header=header(ts1, True, *divmod(t, 10**9), m.seq), height=720, width=1280,
                         seq=m.seq, time_base=0, encoding='evt3', is_bigendian=False, events=m.events))
                for t, m in packets]
    write1(os.path.join(d, 'evt3.bag'), [('/prophesee/events', 'event_camera_msgs/msg/EventPacket', packets1)],
           Writer1.CompressionFormat.LZ4)
    save('evt3.imu.csv', imu_rows)
    with open(os.path.join(d, 'evt3.packets'), 'w') as f:
        f.write(str(len(pieces)))

if raw_path:
    evt3_bag(raw_path)

# ROS 2 `mono` packets, written with the mcap package (lz4 chunks); then an unknown encoding.
from mcap.writer import Writer as McapWriter, CompressionType
def write_mcap(path, topic, msgs, compression):
    with open(path, 'wb') as f:
        w = McapWriter(f, compression=compression)
        w.start(profile='ros2', library='evtac-test')
        sid = w.register_schema(name='event_camera_msgs/msg/EventPacket', encoding='ros2msg', data=PACKET.encode())
        ch = w.register_channel(topic=topic, message_encoding='cdr', schema_id=sid)
        for t, m in msgs:
            w.add_message(channel_id=ch, log_time=t, publish_time=t,
                          data=bytes(ts2.serialize_cdr(m, 'event_camera_msgs/msg/EventPacket')))
        w.finish()
mono, mono_rows = [], []
base = 1_700_000_200 * 10**9 + 555
for k in range(5):
    n = 200
    dt = np.sort(rng.integers(0, 900_000, n)).astype(np.uint64)
    x = rng.integers(0, 640, n).astype(np.uint64); y = rng.integers(0, 480, n).astype(np.uint64)
    p = rng.integers(0, 2, n).astype(np.uint64)
    word = (p << np.uint64(63)) | (y << np.uint64(48)) | (x << np.uint64(32)) | dt
    tb = base + k * 1_000_000
    mono.append((tb, Pkt(header=header(ts2, False, *divmod(tb, 10**9)), height=480, width=640, seq=k,
                         time_base=tb, encoding='mono', is_bigendian=False,
                         events=np.frombuffer(word.astype('<u8').tobytes(), dtype=np.uint8))))
    mono_rows += [((tb + int(a)) // 1000, int(b), int(c), int(e)) for a, b, c, e in zip(dt, x, y, p)]
write_mcap(os.path.join(d, 'mono.mcap'), '/mono/events', mono, CompressionType.LZ4)
save('mono.events.csv', mono_rows)
bad = list(mono)
t, m = bad[2]
bad[2] = (t, Pkt(header=m.header, height=480, width=640, seq=2, time_base=t, encoding='evt4',
                 is_bigendian=False, events=m.events))
write_mcap(os.path.join(d, 'evt4.mcap'), '/mono/events', bad, CompressionType.NONE)

# Two cameras: a topic must be chosen.
a, _ = dvs_messages(ts1, True, 3, 50, 1_600_000_100)
b, b_rows = dvs_messages(ts1, True, 4, 60, 1_600_000_100)
ia, _ = imu_messages(ts1, True, 5, 1_600_000_100)
ib, ib_rows = imu_messages(ts1, True, 6, 1_600_000_100)
write1(os.path.join(d, 'stereo.bag'), [
    ('/cam0/events', 'dvs_msgs/msg/EventArray', a), ('/cam0/imu', 'sensor_msgs/msg/Imu', ia),
    ('/cam1/events', 'dvs_msgs/msg/EventArray', b), ('/cam1/imu', 'sensor_msgs/msg/Imu', ib)])
save('stereo1.events.csv', b_rows); save('stereo1.imu.csv', ib_rows)

# Cut short.
for name, src in [('cut.bag', 'dvs.bag'), ('cut.mcap', 'dvs2/dvs2.mcap')]:
    with open(os.path.join(d, src), 'rb') as f:
        whole = f.read()
    with open(os.path.join(d, name), 'wb') as f:
        f.write(whole[: len(whole) * 3 // 5])
