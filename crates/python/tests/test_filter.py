"""Filters from Python: the same events as `evtac filter` and as dv-processing, on a
Recording with its IMU kept, and bad SPECs as ValueErrors naming them."""

import numpy as np
import pytest

import evtac


def test_filter_matches_the_cli(cli, aedat, tmp_path):
    rec = evtac.read(aedat)
    specs = ["polarity=on", "background-activity=2ms"]
    kept, removed = evtac.filter(rec.events, rec.resolution, specs, counts=True)
    out = tmp_path / "kept.npy"
    cli("filter", str(aedat), str(out), *[a for s in specs for a in ("--filter", s)])
    np.testing.assert_array_equal(kept, evtac.read(out, resolution=rec.resolution).events)
    assert [s for s, _ in removed] == ["polarity=on", "background-activity=2ms"]
    assert sum(n for _, n in removed) == len(rec.events) - len(kept) > 0


def test_background_activity_matches_dv_processing(aedat):
    dv = pytest.importorskip("dv_processing")
    import datetime

    rec = evtac.read(aedat)
    store = dv.EventStore()
    for e in rec.events:
        store.push_back(int(e["t"]), int(e["x"]), int(e["y"]), bool(e["p"]))
    f = dv.noise.BackgroundActivityNoiseFilter(
        rec.resolution, backgroundActivityDuration=datetime.timedelta(milliseconds=10)
    )
    f.accept(store)
    theirs = f.generateEvents().numpy()
    ours = evtac.filter(rec.events, rec.resolution, "background-activity=10ms")
    assert 0 < len(ours) < len(rec.events)
    np.testing.assert_array_equal(ours["t"], theirs["timestamp"])
    np.testing.assert_array_equal(ours["x"], theirs["x"])
    np.testing.assert_array_equal(ours["y"], theirs["y"])
    np.testing.assert_array_equal(ours["p"], theirs["polarity"])


def test_a_recording_filters_itself_and_keeps_its_imu(aedat, tmp_path):
    rec = evtac.read(aedat)
    mask = np.zeros((rec.resolution[1], rec.resolution[0]), np.uint8)
    mask[:, : rec.resolution[0] // 2] = 1
    np.save(tmp_path / "left.npy", mask)
    filtered, removed = rec.filter([f"mask={tmp_path / 'left.npy'}"])
    assert filtered.resolution == rec.resolution and filtered.format == rec.format
    assert filtered.imu.tobytes() == rec.imu.tobytes()
    left = rec.events[rec.events["x"] < rec.resolution[0] // 2]
    np.testing.assert_array_equal(filtered.events, left)
    assert removed == [(f"mask={tmp_path / 'left.npy'}", len(rec.events) - len(left))]


def test_bad_specs_and_events_are_value_errors(aedat):
    rec = evtac.read(aedat)
    with pytest.raises(ValueError, match="unknown filter `blur=3`"):
        evtac.filter(rec.events, rec.resolution, ["blur=3"])
    with pytest.raises(ValueError, match="the duration `0ms` is not positive"):
        evtac.filter(rec.events, rec.resolution, ["refractory=0ms"])
    with pytest.raises(ValueError, match="do not fit the 320x240 sensor"):
        evtac.filter(rec.events, rec.resolution, ["region=300,0,40,10"])
    with pytest.raises(ValueError, match="events to filter"):
        evtac.filter(rec.events, (100, 100), ["polarity=on"])
    with pytest.raises(ValueError, match="resolution"):
        evtac.filter(rec.events, None, ["polarity=on"])


def test_hot_pixels_auto_learns_from_the_events_as_the_cli_does(cli, tmp_path):
    # 2 s of sparse background on a 32x32 sensor, every bin alike (all at rest), and one pixel
    # firing every millisecond: the one hot pixel.
    t = np.arange(0, 2_000_000, 1_000, dtype=np.int64)
    background = np.zeros(len(t), dtype=evtac.EVENT_DTYPE)
    background["t"], background["x"], background["y"] = t, (t // 1000) % 32, (t // 32000) % 32
    background["p"] = 1
    hot = np.zeros(len(t), dtype=evtac.EVENT_DTYPE)
    hot["t"], hot["x"], hot["y"], hot["p"] = t, 7, 9, 1
    events = np.sort(np.concatenate([background, hot]), order="t", kind="stable")
    kept, removed = evtac.filter(events, (32, 32), ["hot-pixels=auto"], counts=True)
    at_hot = (events["x"] == 7) & (events["y"] == 9)
    assert removed == [("hot-pixels=auto", int(at_hot.sum()))]
    np.testing.assert_array_equal(kept, events[~at_hot])
    path = tmp_path / "events.npy"
    np.save(path, events)
    out = tmp_path / "kept.npy"
    cli("filter", str(path), str(out), "--sensor", "32x32", "--filter", "hot-pixels=auto")
    np.testing.assert_array_equal(kept, evtac.read(out, resolution=(32, 32)).events)
    with pytest.raises(ValueError, match="hot-pixels=auto learns the hot pixels"):
        evtac.filter(events[:0], (32, 32), ["hot-pixels=auto"])
