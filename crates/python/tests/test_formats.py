"""The formats without a real fixture: AEDAT 2.0 (jAER), AEDAT 3.1 (cAER), Prophesee EVT 2.1,
written here from the format descriptions (as evtac-events' own tests write them), and the
NeuroTac lab's per-pixel pickles, written by Python's pickle as its collection scripts do, and
event_utils' HDF5, written by h5py. `read` and
`open` give the events, IMU samples and triggers the writer encoded, and the events of the CLI's
`evtac convert`."""

import random
import struct

import numpy as np
import pytest

import evtac


def _aedat2(path):
    """A DAVIS240 file as jAER writes it: CR LF header lines, then big-endian (address,
    timestamp) pairs, x mirrored and the origin bottom left; APS samples and external input
    events mixed in (skipped); timestamps wrap past 2^32."""
    rng = random.Random(2)
    out = bytearray(b"#!AER-DAT2.0\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n")
    events, t = [], (1 << 32) - 4000
    for _ in range(3000):
        t += rng.choice([0, 1, 2, 5])
        r = rng.random()
        if r < 0.05:
            address = 1 << 31 | rng.randrange(180) << 22 | rng.randrange(240) << 12
        elif r < 0.06:
            address = 1 << 10
        else:
            x, y, p = rng.randrange(240), rng.randrange(180), rng.randint(0, 1)
            address = (179 - y) << 22 | (239 - x) << 12 | p << 11
            events.append((t, x, y, p))
        out += struct.pack(">II", address, t % (1 << 32))
    path.write_bytes(bytes(out))
    return events, [], [], (240, 180), "AEDAT2"


def _aedat31(path):
    """cAER's packets: polarity (type 1), IMU6 (type 3) and special (type 0: rising and falling
    edges) events of source 1, some events marked invalid."""
    rng = random.Random(31)
    out = bytearray(b"#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS240C\r\n#!END-HEADER\r\n")

    def packet(kind, size, records):
        valid = sum(struct.unpack_from("<I", e)[0] & 1 for e in records)
        out.extend(struct.pack("<hhiiiiii", kind, 1, size, 4, 0, len(records), len(records),
                               valid))
        for e in records:
            out.extend(e)

    events, imu, triggers, t = [], [], [], 10_000
    for _ in range(60):
        batch = []
        for _ in range(rng.randrange(1, 80)):
            t += rng.choice([0, 1, 3, 9])
            x, y, p = rng.randrange(240), rng.randrange(180), rng.randint(0, 1)
            valid = 0 if rng.random() < 0.03 else 1
            batch.append(struct.pack("<Ii", x << 17 | y << 2 | p << 1 | valid, t))
            if valid:
                events.append((t, x, y, p))
        packet(1, 8, batch)
        r = rng.random()
        if r < 0.4:
            values = [rng.uniform(-2, 2) for _ in range(3)] + [rng.uniform(-250, 250)
                                                               for _ in range(3)]
            values.append(rng.uniform(20, 40))
            packet(3, 36, [struct.pack("<Ii7f", 1, t, *values)])
            imu.append((t, *np.float32(values)))
        elif r < 0.6:
            code = rng.choice([2, 3])
            packet(0, 8, [struct.pack("<Ii", code << 1 | 1, t)])
            triggers.append((t, code - 1))
    path.write_bytes(bytes(out))
    return events, imu, triggers, (240, 180), "AEDAT3.1"


def _evt21(path):
    """Prophesee EVT 2.1: little-endian 64-bit words, 32-pixel vectors of one polarity, time
    highs, external triggers (rising 1, falling 2) and words of other types (skipped)."""
    rng = random.Random(21)
    out = bytearray(b"% format EVT21;height=180;width=240\n% end\n")
    events, triggers, t, high = [], [], 70_000, None
    for _ in range(800):
        t += rng.choice([0, 0, 1, 3, 17, 64, 200])
        if t >> 6 != high:
            high = t >> 6
            out += struct.pack("<Q", 0x8 << 60 | high << 32)
        kind, y, base = rng.randint(0, 1), rng.randrange(180), rng.randrange(0, 240, 32)
        mask = (rng.getrandbits(32) & ((1 << min(32, 240 - base)) - 1)) or 1
        out += struct.pack("<Q", kind << 60 | (t & 63) << 54 | base << 43 | y << 32 | mask)
        events += [(t, base + i, y, kind) for i in range(32) if mask >> i & 1]
        r = rng.random()
        if r < 0.05:
            value = rng.randint(0, 1)
            out += struct.pack("<Q", 0xA << 60 | (t & 63) << 54 | 1 << 40 | value << 32)
            triggers.append((t, 1 if value else 2))
        elif r < 0.1:
            out += struct.pack("<Q", 0xE << 60 | rng.getrandbits(40))
    path.write_bytes(bytes(out))
    return events, [], triggers, (240, 180), "EVT21"


def _neurotac(path):
    """The lab's pair: `<trial>_events_on` / `_events_off`, each a numpy object array [y, x] of
    per-pixel lists of millisecond times (microsecond resolution)."""
    import pickle
    rng = random.Random(5)
    w, h = 240, 180
    events = []
    for pol, name in ((1, path.name), (0, path.name.replace("events_on", "events_off"))):
        cells = np.empty((h, w), dtype=object)
        for i in range(w * h):
            cells.flat[i] = []
        for _ in range(3000):
            x, y = rng.randrange(w), rng.randrange(h)
            t_us = rng.randrange(10_000_000)
            cells[y, x].append(t_us / 1000)
            events.append((t_us, x, y, pol))
        with open(path.with_name(name), "wb") as f:
            pickle.dump(cells, f, protocol=5)
    events.sort(key=lambda e: (e[0], e[2], e[1], e[3]))
    return events, [], [], (w, h), "NeuroTac pickle"


def _hdf5(path):
    """event_utils' layout, written by h5py: `events/xs, ys` int16, `ts` float seconds, `ps`
    bool, `sensor_resolution` as [height, width]."""
    import h5py
    rng = np.random.default_rng(6)
    w, h, n = 240, 180, 5000
    t = np.sort(rng.integers(1_700_000_000_000_000, 1_700_000_010_000_000, n))
    x, y, p = rng.integers(0, w, n), rng.integers(0, h, n), rng.integers(0, 2, n)
    with h5py.File(path, "w") as f:
        f.create_dataset("events/xs", data=x.astype(np.int16), compression="gzip")
        f.create_dataset("events/ys", data=y.astype(np.int16))
        f.create_dataset("events/ts", data=t / 1e6)
        f.create_dataset("events/ps", data=p.astype(bool))
        f.attrs["sensor_resolution"] = (h, w)
    events = [(int(a), int(b), int(c), int(d)) for a, b, c, d in zip(t, x, y, p)]
    return events, [], [], (w, h), "HDF5"


@pytest.mark.parametrize("name,writer", [("aedat2.aedat", _aedat2), ("aedat31.aedat", _aedat31),
                                         ("evt21.raw", _evt21),
                                         ("trial_events_on.pickle", _neurotac),
                                         ("event_utils.h5", _hdf5)])
def test_read_and_open_give_what_was_written_and_the_clis_events(cli, tmp_path, name, writer):
    path = tmp_path / name
    events, imu, triggers, resolution, fmt = writer(path)
    rec = evtac.read(path)
    assert rec.format == fmt and rec.resolution == resolution
    assert len(rec.events) == len(events) > 1000
    assert rec.events.tolist() == events
    assert rec.imu[["t", "ax", "ay", "az", "gx", "gy", "gz", "temperature"]].tolist() == imu
    assert rec.triggers.tolist() == triggers
    cli("convert", path, tmp_path / "cli.npy")
    assert np.load(tmp_path / "cli.npy").tobytes() == rec.events.tobytes()
    chunks = list(evtac.open(path, chunk_events=500))  # reader chunks of at least 500 events
    assert all(c.format == fmt and c.resolution == resolution for c in chunks)
    assert np.concatenate([c.events for c in chunks]).tobytes() == rec.events.tobytes()
    assert np.concatenate([c.imu for c in chunks]).tobytes() == rec.imu.tobytes()
    assert np.concatenate([c.triggers for c in chunks]).tobytes() == rec.triggers.tobytes()
    # The centered crop, as `evtac convert --roi`.
    cli("convert", path, tmp_path / "roi.npy", "--roi", "160x120")
    cropped = evtac.read(path, roi=(160, 120))
    assert cropped.resolution == (160, 120)
    assert np.load(tmp_path / "roi.npy").tobytes() == cropped.events.tobytes()
