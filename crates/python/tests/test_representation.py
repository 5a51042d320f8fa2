"""Representations: bit for bit `evtac represent`, incremental == batch, errors."""

import numpy as np
import pytest

import evtac

# (kind, Python settings, the same as `evtac represent` options)
CASES = [
    ("combined", {}, []),
    ("static", {}, []),
    ("dynamic", {}, []),
    (
        "static",
        {"tau_ms": 250, "threshold": 1.5, "polarity": "ignore", "threshold_space": "u8"},
        ["--tau-ms", "250", "--threshold", "1.5", "--polarity", "ignore", "--threshold-space", "u8"],
    ),
    (
        "combined",
        {"decay": "linear", "eta": 0.2, "comparison": "ge", "window_ms": 50, "count_threshold": 1},
        ["--decay", "linear", "--eta", "0.2", "--cmp", "ge", "--window-ms", "50",
         "--count-threshold", "1"],
    ),
]


@pytest.fixture(scope="module")
def recording(aedat):
    return evtac.read(aedat)


@pytest.fixture(scope="module")
def times(recording):
    t = recording.events["t"]
    # Before the first event, a repeated time, a 1 ms grid, and past the last event.
    grid = np.arange(t[0], t[-1], 7919)
    return np.concatenate([[t[0] - 5], grid[:3], grid[2:3], grid[3:], [t[-1] + 10]])


def _cli_output(cli, tmp_path, aedat, times, kind, options, what, extra=()):
    samples = tmp_path / "samples.txt"
    samples.write_text("\n".join(map(str, times)) + "\n")
    out = tmp_path / f"{kind}-{what}.npy"
    cli("represent", aedat, "--samples", samples, "--repr", kind, "--what", what,
        "--output", out, *options, *extra)
    return np.load(out)


@pytest.mark.parametrize("kind,settings,options", CASES)
def test_features_and_frames_are_the_clis(cli, tmp_path, aedat, recording, times, kind, settings,
                                          options):
    rep = evtac.Representation(kind, sensor=recording.resolution, **settings)
    features = rep.features(recording.events, times)
    expected = _cli_output(cli, tmp_path, aedat, times, kind, options, "features")
    assert features.dtype == np.float32 and features.shape == (len(times), 900)
    assert features.tobytes() == expected.tobytes()
    assert features.any(), "a test on all-zero features could not tell much"
    # Handed over from Rust without a copy: numpy does not own the buffer.
    assert not features.flags["OWNDATA"] and features.flags["C_CONTIGUOUS"]
    frames = rep.frames(recording.events, times)
    expected = _cli_output(cli, tmp_path, aedat, times, kind, options, "frames")
    assert frames.dtype == np.uint8 and frames.shape == (len(times), 240, 240)
    assert frames.tobytes() == expected.tobytes()


def test_potentials_and_the_whole_sensor_are_the_clis(cli, tmp_path, aedat, recording, times):
    rep = evtac.Representation("static", sensor=recording.resolution, roi=None, tau_ms=300)
    got = rep.potentials(recording.events, times)
    expected = _cli_output(cli, tmp_path, aedat, times, "static", ["--tau-ms", "300"],
                           "potential", ["--roi", "none"])
    assert got.shape == (len(times), 240, 320)
    assert got.tobytes() == expected.tobytes()


def test_masks_are_the_clis(cli, tmp_path, aedat, recording, times):
    pixels = np.zeros((240, 240), np.uint8)
    pixels[100:140, 50:200] = 1
    np.save(tmp_path / "mask.npy", pixels)
    rep = evtac.Representation("static", sensor=recording.resolution, mask=pixels)
    expected = _cli_output(cli, tmp_path, aedat, times, "static", [], "features",
                           ["--mask", tmp_path / "mask.npy"])
    assert rep.features(recording.events, times).tobytes() == expected.tobytes()
    assert rep.mask.tobytes() == pixels.tobytes()
    # A no-contact recording (here the same file) run through the static settings.
    rep = evtac.Representation("combined", sensor=recording.resolution, mask=aedat)
    expected = _cli_output(cli, tmp_path, aedat, times, "combined", [], "features",
                           ["--mask", aedat])
    assert rep.mask.any()
    assert rep.features(recording.events, times).tobytes() == expected.tobytes()


@pytest.mark.parametrize("chunk", [1, 777, 50000])
def test_incremental_matches_batch_for_any_chunking(recording, times, chunk):
    rep = evtac.Representation("combined", sensor=recording.resolution)
    batch = rep.features(recording.events, times)
    events = recording.events
    pushed = 0
    rows = []
    for t in times:
        end = max(pushed, int(np.searchsorted(events["t"], t, side="right")))
        while pushed < end:
            rep.push(events[pushed:min(end, pushed + chunk)])
            pushed = min(end, pushed + chunk)
        rows.append(rep.advance_to(t))
    assert rep.time_us == times[-1]
    assert np.stack(rows).tobytes() == batch.tobytes()
    assert rep.frame().shape == (240, 240)
    rep.reset()
    assert rep.time_us is None


def test_events_already_cropped(recording, times):
    full = evtac.Representation("dynamic", sensor=recording.resolution)
    cropped = evtac.Representation("dynamic")
    crop = evtac.Representation("dynamic", sensor=recording.resolution).roi
    x0, y0, w, h = crop
    e = recording.events
    inside = (e["x"] >= x0) & (e["x"] < x0 + w) & (e["y"] >= y0) & (e["y"] < y0 + h)
    moved = e[inside].copy()
    moved["x"] -= x0
    moved["y"] -= y0
    assert cropped.features(moved, times).tobytes() == full.features(e, times).tobytes()


def test_config_has_the_defaults():
    rep = evtac.Representation("combined", tau_ms=500)
    assert rep.kind == "combined"
    assert rep.config["static_part"]["tau_ms"] == 500
    assert rep.config["static_part"]["threshold"] == 2
    assert rep.config["dynamic_part"]["window_ms"] == 640
    assert rep.feature_len == 900


def test_bad_arguments_are_value_errors(recording):
    with pytest.raises(ValueError, match="unknown representation kind `fancy`"):
        evtac.Representation("fancy")
    with pytest.raises(ValueError, match="unknown setting `tau`"):
        evtac.Representation("static", tau=3)
    with pytest.raises(ValueError, match="`tau_ms` is not a setting of a dynamic"):
        evtac.Representation("dynamic", tau_ms=3)
    with pytest.raises(ValueError, match="tau_ms"):
        evtac.Representation("static", tau_ms=-1)
    with pytest.raises(ValueError, match="unknown variant `exp`"):
        evtac.Representation("static", decay="exp")
    with pytest.raises(ValueError, match="does not fit inside the 320x240 sensor"):
        evtac.Representation(sensor=(320, 240), roi=(320, 320))
    rep = evtac.Representation(sensor=recording.resolution)
    e = recording.events[:1000]
    with pytest.raises(ValueError, match="before the previous sample"):
        rep.features(e, [e["t"][10], e["t"][5]])
    with pytest.raises(ValueError, match="backwards"):
        rep.features(e[::-1], [e["t"][0]])
    outside = e.copy()
    outside["x"][3] = 320
    with pytest.raises(ValueError, match="x=320"):
        rep.features(outside, [e["t"][0]])
    with pytest.raises(ValueError, match="whole microseconds"):
        rep.features(e, [1.5])
    with pytest.raises(ValueError, match="dynamic representation has no potentials"):
        evtac.Representation("dynamic").potentials(e[:0], [0])
    rep.push(e[500:])
    with pytest.raises(ValueError, match="out of time order"):
        rep.push(e[:10])
    with pytest.raises(ValueError, match="mask is 10x10 but the frame is 240x240"):
        evtac.Representation("static", mask=np.zeros((10, 10)))


# The kinds the paper did not choose: (kind, Python settings, `evtac represent` options, channels)
DENSE_CASES = [
    ("time-surface", {"tau_ms": 20}, ["--tau-ms", "20"], 2),
    ("time-surface", {"tau_ms": 20, "threshold": 0.4},
     ["--tau-ms", "20", "--threshold", "0.4"], 2),
    ("histogram", {"window_ms": 15}, ["--window-ms", "15"], 2),
    ("voxel-grid", {"window_ms": 15, "bins": 3}, ["--window-ms", "15", "--bins", "3"], 3),
]


@pytest.mark.parametrize("kind,settings,options,channels", DENSE_CASES)
def test_time_surfaces_histograms_and_voxel_grids_are_the_clis(
        cli, tmp_path, aedat, recording, times, kind, settings, options, channels):
    rep = evtac.Representation(kind, sensor=recording.resolution, **settings)
    assert rep.kind == kind and rep.feature_len == channels * 900
    features = rep.features(recording.events, times)
    expected = _cli_output(cli, tmp_path, aedat, times, kind, options, "features")
    assert features.dtype == np.float32 and features.shape == (len(times), channels * 900)
    assert features.tobytes() == expected.tobytes()
    assert features.any()
    frames = rep.frames(recording.events, times)
    expected = _cli_output(cli, tmp_path, aedat, times, kind, options, "frames")
    assert frames.dtype == np.float32 and frames.shape == (len(times), channels, 240, 240)
    assert frames.tobytes() == expected.tobytes()
    # The features are each channel's 8x8 means of the frame.
    pooled = frames.reshape(len(times), channels, 30, 8, 30, 8).mean(axis=(3, 5))
    np.testing.assert_allclose(features, pooled.reshape(len(times), -1), atol=1e-6)
    # Incremental: the same numbers, and the current frame with its channels.
    events = recording.events
    rows, pushed = [], 0
    for t in times:
        end = max(pushed, int(np.searchsorted(events["t"], t, side="left")))
        rep.push(events[pushed:end])
        pushed = end
        rows.append(rep.advance_to(t))
    assert np.stack(rows).tobytes() == features.tobytes()
    assert rep.frame().tobytes() == frames[-1].tobytes()


def test_real_valued_kinds_refuse_settings_and_masks_they_do_not_take(recording):
    with pytest.raises(ValueError, match="unknown setting `eta` of a time-surface"):
        evtac.Representation("time-surface", eta=0.2)
    with pytest.raises(ValueError, match="bins"):
        evtac.Representation("histogram", bins=3)
    with pytest.raises(ValueError, match="`bins` must be a positive whole number"):
        evtac.Representation("voxel-grid", bins=2.5)
    with pytest.raises(ValueError, match="threshold"):
        evtac.Representation("time-surface", threshold=1.5)
    with pytest.raises(ValueError, match="static part: a histogram representation has none"):
        evtac.Representation("histogram", mask=np.zeros((240, 240), np.uint8))
    rep = evtac.Representation("voxel-grid", bins=4)
    assert rep.config == {"kind": "voxel-grid", "window_ms": 640.0, "bins": 4}
