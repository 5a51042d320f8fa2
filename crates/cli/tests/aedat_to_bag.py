"""Writes an AEDAT4 recording's events and IMU as a ROS 1 bag, as the rpg_dvs_ros driver records
them: `dvs_msgs/EventArray` on /dvs/events (one message per 10 ms) and `sensor_msgs/Imu` on
/dvs/imu (m/s^2 and rad/s), read with dv-processing and written with the `rosbags` package.
The messages are serialised with numpy (a ROS 1 message is its fields packed in order), so a
session of millions of events converts in seconds.

Usage: aedat_to_bag.py IN.aedat4 OUT.bag
"""
import sys
import numpy as np
import dv_processing as dv
from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

src, out = sys.argv[1], sys.argv[2]
rec = dv.io.MonoCameraRecording(src)
width, height = rec.getEventResolution()
events = []
while (batch := rec.getNextEventBatch()) is not None:
    events.append(batch.numpy())
events = np.concatenate(events)
imu = []
while (batch := rec.getNextImuBatch()) is not None:
    imu.extend(batch)

ts = get_typestore(Stores.ROS1_NOETIC)
ts.register(get_types_from_msg("uint16 x\nuint16 y\ntime ts\nbool polarity\n", 'dvs_msgs/msg/Event'))
ts.register(get_types_from_msg(
    "std_msgs/Header header\nuint32 height\nuint32 width\ndvs_msgs/Event[] events\n",
    'dvs_msgs/msg/EventArray'))

FRAME = b'dvs'
def header(seq, t_us):
    """A std_msgs/Header: seq, stamp (sec, nsec), frame_id."""
    return (np.array([seq, t_us // 1_000_000, t_us % 1_000_000 * 1000], '<u4').tobytes()
            + np.array([len(FRAME)], '<u4').tobytes() + FRAME)

EVENT = np.dtype([('x', '<u2'), ('y', '<u2'), ('sec', '<u4'), ('nsec', '<u4'), ('p', 'u1')])
def event_array(seq, chunk):
    packed = np.empty(len(chunk), EVENT)
    t = chunk['timestamp'].astype(np.int64)
    packed['x'], packed['y'] = chunk['x'], chunk['y']
    packed['sec'], packed['nsec'] = t // 1_000_000, t % 1_000_000 * 1000
    packed['p'] = chunk['polarity']
    return (header(seq, int(t[-1])) + np.array([height, width, len(chunk)], '<u4').tobytes()
            + packed.tobytes())

G = 9.80665
def imu_message(seq, s):
    t = int(s.timestamp)
    orientation = [0.0, 0.0, 0.0, 1.0]
    unknown = [-1.0] + [0.0] * 8  # orientation covariance -1: no orientation estimate
    zeros = [0.0] * 9
    gyro = np.radians([s.gyroscopeX, s.gyroscopeY, s.gyroscopeZ]).tolist()
    accel = [s.accelerometerX * G, s.accelerometerY * G, s.accelerometerZ * G]
    return header(seq, t) + np.array(orientation + unknown + gyro + zeros + accel + zeros,
                                     '<f8').tobytes()

with Writer(out) as w:
    ce = w.add_connection('/dvs/events', 'dvs_msgs/msg/EventArray', typestore=ts)
    ci = w.add_connection('/dvs/imu', 'sensor_msgs/msg/Imu', typestore=ts)
    t = events['timestamp'].astype(np.int64)
    bounds = np.flatnonzero(np.diff(t // 10_000)) + 1
    messages = [(int(c['timestamp'][-1]) * 1000, ce, event_array(k, c))
                for k, c in enumerate(np.split(events, bounds))]
    messages += [(int(s.timestamp) * 1000, ci, imu_message(k, s)) for k, s in enumerate(imu)]
    messages.sort(key=lambda m: m[0])
    for t_ns, conn, data in messages:
        w.write(conn, t_ns, data)
print(f"{len(events)} events and {len(imu)} IMU samples written to {out}")
