"""Reading and writing: equal to dv-processing's decoding and to `evtac convert`, errors."""

import gc

import numpy as np
import pytest

import evtac


def test_aedat4_matches_dv_processing(aedat):
    dv = pytest.importorskip("dv_processing")
    rec = evtac.read(aedat)
    r = dv.io.MonoCameraRecording(str(aedat))
    batches = []
    while (b := r.getNextEventBatch()) is not None:
        batches.append(b.numpy())
    e = np.concatenate(batches)
    assert rec.resolution == tuple(r.getEventResolution()) == (320, 240)
    assert rec.source == r.getCameraName()
    assert rec.format == "AEDAT4"
    assert rec.events.dtype == evtac.EVENT_DTYPE
    assert len(rec.events) == len(e) == 111954
    np.testing.assert_array_equal(rec.events["t"], e["timestamp"])
    np.testing.assert_array_equal(rec.events["x"], e["x"])
    np.testing.assert_array_equal(rec.events["y"], e["y"])
    np.testing.assert_array_equal(rec.events["p"], e["polarity"])
    imu = []
    while (b := r.getNextImuBatch()) is not None:
        imu += [
            (s.timestamp, s.accelerometerX, s.accelerometerY, s.accelerometerZ,
             s.gyroscopeX, s.gyroscopeY, s.gyroscopeZ, s.temperature)
            for s in b
        ]
    expected = np.array(imu, dtype=evtac.IMU_DTYPE)
    assert len(rec.imu) == 475
    assert rec.imu.tobytes() == expected.tobytes()


def test_read_matches_the_cli_convert_to_npy(cli, aedat, tmp_path):
    out = tmp_path / "e.npy"
    cli("convert", aedat, out)
    expected = np.load(out)
    got = evtac.read(aedat).events
    assert got.dtype == expected.dtype
    assert got.tobytes() == expected.tobytes()


def test_roi_matches_the_cli_convert_roi(cli, aedat, tmp_path):
    out = tmp_path / "crop.npy"
    cli("convert", aedat, out, "--roi", "240x200")
    rec = evtac.read(aedat, roi=(240, 200))
    assert rec.resolution == (240, 200)
    assert rec.events.tobytes() == np.load(out).tobytes()


def test_evt3_matches_the_expected_decoding(real):
    raw = real("prophesee_gen4_1280x720.evt3.raw")
    expected = np.load(real("prophesee_gen4_1280x720.evt3.expected.npy"))
    rec = evtac.read(raw)
    assert rec.format == "EVT3"
    assert rec.resolution == (1280, 720)
    for f in "txyp":
        np.testing.assert_array_equal(rec.events[f], expected[f])


def test_evt2_matches_the_cli(cli, real, tmp_path):
    raw = real("prophesee_gen3_640x480.evt2.raw")
    out = tmp_path / "e.npy"
    cli("convert", raw, out)
    rec = evtac.read(raw)
    assert (rec.format, rec.resolution, len(rec.events)) == ("EVT2", (640, 480), 521252)
    assert rec.events.tobytes() == np.load(out).tobytes()


@pytest.mark.parametrize("chunk_events", [1, 5000, 1 << 20])
def test_open_in_chunks_gives_the_whole_recording(aedat, chunk_events):
    whole = evtac.read(aedat, roi=(240, 240))
    reader = evtac.open(aedat, roi=(240, 240), chunk_events=chunk_events)
    assert reader.resolution == (240, 240)
    chunks = list(reader)
    assert all(len(c.events) >= chunk_events for c in chunks[:-1])
    assert np.concatenate([c.events for c in chunks]).tobytes() == whole.events.tobytes()
    assert np.concatenate([c.imu for c in chunks]).tobytes() == whole.imu.tobytes()


@pytest.mark.parametrize("ext", ["aedat4", "npy", "csv"])
def test_write_then_read_round_trips(aedat, tmp_path, ext):
    rec = evtac.read(aedat)
    path = tmp_path / f"out.{ext}"
    evtac.write(path, rec.events, imu=rec.imu, resolution=rec.resolution, source="cam")
    back = evtac.read(path, resolution=rec.resolution)
    assert back.events.tobytes() == rec.events.tobytes()
    if ext == "aedat4":
        assert back.imu.tobytes() == rec.imu.tobytes()
        assert back.source == "cam"


def test_written_npy_is_numpy_readable_and_other_dtypes_convert(tmp_path):
    events = np.zeros(3, dtype=[("p", "?"), ("x", "<u2"), ("y", "<i4"), ("t", "<i8")])
    events["t"] = [5, 6, 9]
    events["x"] = [1, 2, 3]
    events["p"] = [True, False, True]
    path = tmp_path / "e.npy"
    evtac.write(path, events)
    loaded = np.load(path)
    assert loaded.dtype == evtac.EVENT_DTYPE
    assert loaded["t"].tolist() == [5, 6, 9] and loaded["p"].tolist() == [1, 0, 1]


def test_missing_and_corrupt_files_are_os_errors(tmp_path, aedat):
    with pytest.raises(FileNotFoundError, match="nothing-here.aedat4"):
        evtac.read(tmp_path / "nothing-here.aedat4")
    broken = tmp_path / "broken.aedat4"
    broken.write_bytes(aedat.read_bytes()[:5000])
    with pytest.raises(OSError, match="broken.aedat4"):
        evtac.read(broken)
    with pytest.raises(OSError):
        evtac.write(tmp_path / "no" / "such" / "dir.npy", evtac.read(aedat).events[:10])


def test_bad_arguments_are_value_errors(aedat, tmp_path):
    events = evtac.read(aedat).events[:100]
    with pytest.raises(ValueError, match="roi 400x400 does not fit"):
        evtac.read(aedat, roi=(400, 400))
    with pytest.raises(ValueError, match="320x240"):
        evtac.read(aedat, resolution=(640, 480))
    with pytest.raises(ValueError, match="cannot write"):
        evtac.write(tmp_path / "e.raw", events)
    with pytest.raises(ValueError, match="backwards"):
        evtac.write(tmp_path / "e.npy", events[::-1])
    with pytest.raises(ValueError, match="sensor resolution"):
        evtac.write(tmp_path / "e.aedat4", events)
    with pytest.raises(ValueError, match="fields t, x, y, p"):
        evtac.write(tmp_path / "e.npy", np.zeros(3))
    bad = events.copy()
    bad["p"][7] = 2
    with pytest.raises(ValueError, match="event 7 .* polarity 2"):
        evtac.write(tmp_path / "e.npy", bad)
    with pytest.raises(ValueError, match="chunk_events"):
        evtac.open(aedat, chunk_events=0)


def test_a_failed_write_leaves_no_file_and_an_earlier_one_untouched(aedat, tmp_path):
    events = evtac.read(aedat).events[:100]
    out = tmp_path / "e.npy"
    out.write_bytes(b"earlier")
    with pytest.raises(ValueError, match="backwards"):
        evtac.write(out, events[::-1])
    assert out.read_bytes() == b"earlier"
    with pytest.raises(ValueError, match="backwards"):
        evtac.write(tmp_path / "new.aedat4", events[::-1], resolution=(320, 240))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.npy"]


def test_a_two_camera_file_is_read_one_camera_at_a_time(tmp_path):
    dv = pytest.importorskip("dv_processing")

    def config(name, size):
        c = dv.io.MonoCameraWriter.Config(name)
        c.addEventStream(size)
        return c

    path = tmp_path / "stereo.aedat4"
    w = dv.io.StereoCameraWriter(str(path), config("L", (640, 480)), config("R", (346, 260)))
    expected = {}
    for name, writer, size, offset in (("L", w.left, (640, 480), 0), ("R", w.right, (346, 260), 2)):
        s = dv.EventStore()
        for i in range(1000):
            s.push_back(1_000_000 + offset + 4 * i, i % size[0], i % size[1], i % 3 == 0)
        writer.writeEvents(s)
        expected[name] = (s.numpy(), size)
    del writer, w  # the file is complete once every reference to the writer is gone
    gc.collect()
    with pytest.raises(ValueError, match="2 event streams"):
        evtac.read(path)
    for stream, name in (("L", "L"), (1, "R"), ("R/events", "R")):
        rec = evtac.read(path, stream=stream)
        e, size = expected[name]
        assert rec.resolution == size and rec.source == name
        np.testing.assert_array_equal(rec.events["t"], e["timestamp"])
        np.testing.assert_array_equal(rec.events["x"], e["x"])
        np.testing.assert_array_equal(rec.events["p"], e["polarity"])
        chunks = list(evtac.open(path, stream=stream, chunk_events=300))
        assert sum(len(c.events) for c in chunks) == 1000
    with pytest.raises(ValueError, match="no event stream"):
        evtac.read(path, stream=9)
