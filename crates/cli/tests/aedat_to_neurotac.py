"""Writes each trial of a simulated dataset as the NeuroTac lab's collection script saves it, and
the robot's log on the same clock: per trial, pickles `<trial>_events_on.pickle` and
`<trial>_events_off.pickle` (a numpy object array indexed [y, x], one Python list per pixel of
its event times in whole milliseconds since logging started, the trial's first event), and
`robot_log.csv` with the trial's motion in microseconds since the same start. Read with
dv-processing; the lab's code stores no IMU.

Usage: aedat_to_neurotac.py DATASET OUT_DIR
"""
import csv, os, pickle, sys
import numpy as np
import dv_processing as dv

src, out = sys.argv[1], sys.argv[2]
os.makedirs(out, exist_ok=True)
with open(os.path.join(src, 'trials.csv')) as f:
    trials = list(csv.DictReader(f))
LOG = ['trial', 'direction_deg', 'speed_deg_s', 'depth_mm', 'total_deg', 'motion_start_us',
       'motion_end_us', 'stop_start_us', 'stop_end_us', 'stop_deg', 'group']
rows = []
for t in trials:
    rec = dv.io.MonoCameraRecording(os.path.join(src, t['file']))
    width, height = rec.getEventResolution()
    batches = []
    while (b := rec.getNextEventBatch()) is not None:
        batches.append(b.numpy())
    ev = np.concatenate(batches)
    t0 = int(ev['timestamp'][0])
    ms = (ev['timestamp'].astype(np.int64) - t0) // 1000
    for pol, name in ((1, 'on'), (0, 'off')):
        cells = np.empty((height, width), dtype=object)
        for i in range(cells.size):
            cells.flat[i] = []
        sel = ev['polarity'] == pol
        # Each pixel's times in time order: sorted by pixel (stable, so time order is kept),
        # then cut where the pixel changes.
        pixel = ev['y'][sel].astype(np.int64) * width + ev['x'][sel]
        order = np.argsort(pixel, kind='stable')
        pixel, times = pixel[order], ms[sel][order].astype(float)
        starts = np.flatnonzero(np.r_[True, pixel[1:] != pixel[:-1]])
        for p, chunk in zip(pixel[starts].tolist(), np.split(times, starts[1:])):
            cells.flat[p] = chunk.tolist()
        with open(os.path.join(out, f"{t['trial']}_events_{name}.pickle"), 'wb') as f:
            pickle.dump(cells, f)
    row = {k: t.get(k, '') for k in LOG}
    for k in ('motion_start_us', 'motion_end_us', 'stop_start_us', 'stop_end_us'):
        if row[k]:
            row[k] = str(int(row[k]) - t0)
    rows.append(row)
with open(os.path.join(out, 'robot_log.csv'), 'w', newline='') as f:
    w = csv.DictWriter(f, LOG)
    w.writeheader()
    w.writerows(rows)
print(f"{len(rows)} trials written to {out}")
