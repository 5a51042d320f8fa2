"""Models and the online estimator: bit for bit `evtac predict` and `evtac online`, errors."""

import csv

import numpy as np
import pytest

import evtac


@pytest.fixture(scope="module")
def model_dir(tmp_path_factory):
    """A bundle with seeded initial weights (prediction does not care whether they were trained)."""
    d = tmp_path_factory.mktemp("model") / "bundle"
    evtac.Model.untrained(21, evtac.Representation("combined", tau_ms=800)).save(d)
    return d


@pytest.fixture(scope="module")
def recording(aedat):
    return evtac.read(aedat)


def test_predict_is_the_clis(cli, tmp_path, model_dir, recording):
    model = evtac.Model.load(model_dir)
    assert model.config["representation"]["config"]["static_part"]["tau_ms"] == 800
    rep = model.representation(sensor=recording.resolution)
    assert rep.cache_key == evtac.Representation("combined", tau_ms=800).cache_key
    t = recording.events["t"]
    features = rep.features(recording.events, np.arange(t[0], t[-1], 5000))
    np.save(tmp_path / "x.npy", features)
    (tmp_path / "x.npy.json").write_text(features.provenance)
    cli("predict", "--model", model_dir, "--features", tmp_path / "x.npy",
        "--output", tmp_path / "y.npy")
    expected = np.load(tmp_path / "y.npy")
    got = model.predict(features)
    assert got.dtype == np.float32 and got.shape == (len(features), 2)
    assert got.tobytes() == expected.tobytes()
    assert len(np.unique(got[:, 0])) > 1, "predictions should follow the features"


def _cli_online(cli, tmp_path, model_dir, aedat, interval_ms):
    out = tmp_path / "online.csv"
    cli("online", "--model", model_dir, "--input", aedat, "--interval-ms", interval_ms,
        "--output", out)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    return (
        np.array([int(r["t_us"]) for r in rows], np.int64),
        np.array([[float(r["pitch_deg"]), float(r["roll_deg"])] for r in rows], np.float32),
    )


@pytest.mark.parametrize("chunk", [1000, 65536])
def test_estimator_is_the_clis_online(cli, tmp_path, model_dir, aedat, recording, chunk):
    t_cli, angles_cli = _cli_online(cli, tmp_path, model_dir, aedat, 2)
    est = evtac.Estimator(evtac.Model.load(model_dir), recording.resolution, interval_us=2000)
    parts = [est.push(recording.events[i:i + chunk])
             for i in range(0, len(recording.events), chunk)]
    parts.append(est.finish())
    got = np.concatenate(parts)
    assert got.dtype == evtac.ESTIMATE_DTYPE
    assert len(got) == len(t_cli) > 100
    np.testing.assert_array_equal(got["t_us"], t_cli)
    assert np.stack([got["pitch_deg"], got["roll_deg"]], 1).tobytes() == angles_cli.tobytes()
    assert (got["latency_us"] >= 0).all()
    counters = est.counters
    assert counters["events"] == len(recording.events)
    assert 0 < counters["events_in_roi"] < counters["events"]


def test_estimates_match_predictions_on_the_same_grid(model_dir, recording):
    model = evtac.Model.load(model_dir)
    est = evtac.Estimator(model, recording.resolution, interval_us=1000)
    got = np.concatenate([est.push(recording.events), est.finish()])
    rep = model.representation(sensor=recording.resolution)
    expected = model.predict(rep.features(recording.events, got["t_us"]))
    assert np.stack([got["pitch_deg"], got["roll_deg"]], 1).tobytes() == expected.tobytes()


def test_errors(tmp_path, model_dir):
    with pytest.raises(OSError, match="no-model"):
        evtac.Model.load(tmp_path / "no-model")
    model = evtac.Model.load(model_dir)
    with pytest.raises(ValueError, match=r"shape \(N, 900\), got \(2, 899\)"):
        model.predict(np.zeros((2, 899), np.float32), check=False)
    with pytest.raises(ValueError, match="float"):
        model.predict(np.zeros((2, 900), np.int32), check=False)
    with pytest.raises(ValueError, match="carry no record of what made them"):
        model.predict(np.zeros((2, 900), np.float32))
    with pytest.raises(ValueError, match="smaller than the 240x240"):
        evtac.Estimator(model, (200, 200))
    with pytest.raises(ValueError, match="240x240 crop"):
        evtac.Model.untrained(1, evtac.Representation(roi=(160, 160)))


@pytest.mark.parametrize("kind", ["combined", "stacked", "late"])
def test_torch_module_loads_the_bundle_and_predicts_what_evtac_does(torch, tmp_path, recording,
                                                                    kind):
    """`evtac.torch.load_module` builds the module of each network (late fusion's branches and
    head by their saved names, strictly) and its forward pass is evtac's prediction."""
    import evtac.torch

    d = tmp_path / kind
    evtac.Model.untrained(5, evtac.Representation(kind, tau_ms=800)).save(d)
    model = evtac.Model.load(d)
    rep = model.representation(sensor=recording.resolution)
    assert rep.kind == kind
    t = recording.events["t"]
    x = rep.features(recording.events, np.arange(t[0], t[-1], 20_000))
    assert x.shape[1] == (900 if kind == "combined" else 1800)
    assert np.count_nonzero(x[:, :900]) > 0
    net = evtac.torch.load_module(d)
    assert isinstance(net, evtac.torch.LateFusion if kind == "late" else evtac.torch.Mlp)
    with torch.no_grad():
        got = net(torch.from_numpy(x)).numpy()
    np.testing.assert_allclose(got, model.predict(x), rtol=1e-4, atol=1e-4)
    with pytest.raises(ValueError, match="shape"):
        model.predict(np.zeros((2, 1800 if kind == "combined" else 900), np.float32), check=False)


def test_features_made_otherwise_are_refused_naming_both(model_dir, recording):
    """The README's chain with the wrong representation: combined features have a static
    model's 900 columns, and would give confident wrong angles."""
    model = evtac.Model.load(model_dir)
    t = recording.events["t"]
    times = np.arange(t[0], t[-1], 50_000)
    sensor = recording.resolution
    for other, why in [
        (evtac.Representation("static", sensor=sensor), "the features are v1_static"),
        (evtac.Representation("combined", sensor=sensor), "the model reads v1_combined"),
        (evtac.Representation("combined", sensor=sensor, tau_ms=800, roi=None), "pooled from"),
    ]:
        features = other.features(recording.events, times)
        with pytest.raises(ValueError, match=why):
            model.predict(features)
    own = model.representation(sensor=sensor).features(recording.events, times)
    assert isinstance(own, evtac.Features) and own.provenance
    assert model.predict(own[2:5]).shape == (3, 2), "rows keep what made them"
    np.testing.assert_array_equal(model.predict(np.asarray(own), check=False), model.predict(own))
