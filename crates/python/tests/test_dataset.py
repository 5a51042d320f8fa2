"""Datasets: `simulate`, `labels` and `label_trial` give the bytes and figures of the CLI."""

import csv
import json
import subprocess
import sys

import numpy as np
import pytest

import evtac


@pytest.fixture(scope="module")
def datasets(cli, tmp_path_factory):
    """Two Experiment 2 trials (each with a stop), simulated by the CLI and by the package."""
    root = tmp_path_factory.mktemp("datasets")
    by_cli, by_python = root / "cli", root / "python"
    cli("simulate", "--protocol", "exp2", "--scale", "tiny", "--seed", "11", "--out", by_cli,
        "--limit", "2")
    assert evtac.simulate("exp2", "tiny", 11, by_python, limit=2) == 2
    return by_cli, by_python


def test_simulate_writes_the_clis_bytes(datasets):
    by_cli, by_python = datasets
    files = sorted(p.relative_to(by_cli) for p in by_cli.rglob("*") if p.is_file())
    assert len(files) > 4
    assert files == sorted(p.relative_to(by_python) for p in by_python.rglob("*") if p.is_file())
    for f in files:
        assert (by_cli / f).read_bytes() == (by_python / f).read_bytes(), f


def test_labels_are_the_clis(cli, datasets):
    by_cli, by_python = datasets
    summary_cli = json.loads(cli("labels", by_cli, "--json"))
    summary = evtac.labels(by_python)
    assert len(summary["trials"]) == 2
    assert summary == summary_cli
    for report in summary["trials"]:
        f = report["labels_file"]
        assert (by_python / f).read_bytes() == (by_cli / f).read_bytes()


def test_label_trial_is_the_written_csv(cli, datasets):
    by_cli, _ = datasets
    cli("labels", by_cli)
    with open(by_cli / "trials.csv") as f:
        trial = next(csv.DictReader(f))["trial"]
    got = evtac.label_trial(by_cli, trial)
    with open(by_cli / "labels" / f"{trial}.csv") as f:
        rows = list(csv.DictReader(f))
    assert got.dtype == evtac.LABEL_DTYPE and len(got) == len(rows) > 100
    np.testing.assert_array_equal(got["t_us"], [int(r["t_us"]) for r in rows])
    for field in ("theta_deg", "pitch_deg", "roll_deg"):
        np.testing.assert_array_equal(got[field], [float(r[field]) for r in rows])


def test_errors(tmp_path, datasets):
    with pytest.raises(ValueError, match="exp9"):
        evtac.simulate("exp9", "tiny", 0, tmp_path / "x")
    with pytest.raises(ValueError, match="huge"):
        evtac.simulate("exp1", "huge", 0, tmp_path / "x")
    with pytest.raises(OSError, match="trials.csv"):
        evtac.labels(tmp_path / "empty")
    with pytest.raises(ValueError, match="no trial `nope`"):
        evtac.label_trial(datasets[0], "nope")
    with pytest.raises(ValueError, match="label settings"):
        evtac.labels(datasets[0], cutoff=3)


def test_dataset_features_are_the_representations(datasets):
    _, ds = datasets
    rep = evtac.Representation("combined", tau_ms=700)
    data = evtac.dataset_features(ds, rep)
    with open(ds / "trials.csv") as f:
        files = {r["trial"]: r["file"] for r in csv.DictReader(f)}
    assert data.trials == tuple(files)
    assert data.features.shape == (len(data.t_us), 900) and data.labels.shape == (len(data.t_us), 2)
    # 50 motion points and 10 stop points per trial (Experiment 2 trials stop).
    assert np.bincount(data.trial).tolist() == [60, 60]
    assert data.stop.sum() == 20
    assert np.isfinite(data.labels).all() and np.abs(data.labels).max() > 1
    no_contact = ds / "no_contact.aedat4"
    for i, name in enumerate(data.trials):
        rec = evtac.read(ds / files[name])
        own = evtac.Representation("combined", sensor=rec.resolution, tau_ms=700,
                                   mask=no_contact if no_contact.exists() else None)
        rows = data.trial == i
        assert own.features(rec.events, data.t_us[rows]).tobytes() == data.features[rows].tobytes()
    # From the cache the second time, the same.
    again = evtac.dataset_features(ds, rep, trials=[data.trials[1]])
    assert again.features.tobytes() == data.features[data.trial == 1].tobytes()


def test_torch_feature_dataset_serves_the_representations_features(torch, datasets):
    """Every item is the representation's features at the sample's time in the trial's own
    recording, and the trial's labels interpolated there: computed here without the dataset
    cache, so a wrong row, trial, order or dtype fails."""
    import evtac.torch

    _, ds = datasets
    rep = evtac.Representation("combined", tau_ms=700, window_ms=300)
    data = evtac.torch.FeatureDataset(ds, rep)
    assert isinstance(data, torch.utils.data.Dataset)
    meta = data.data
    assert len(data) == len(meta.t_us) == 120
    with open(ds / "trials.csv") as f:
        files = {r["trial"]: r["file"] for r in csv.DictReader(f)}
    no_contact = ds / "no_contact.aedat4"
    want_x, want_y = [], []
    for i, name in enumerate(meta.trials):
        rows = meta.trial == i
        t = meta.t_us[rows]
        rec = evtac.read(ds / files[name])
        own = evtac.Representation("combined", sensor=rec.resolution, tau_ms=700, window_ms=300,
                                   mask=no_contact if no_contact.exists() else None)
        want_x.append(own.features(rec.events, t))
        lab = evtac.label_trial(ds, name)
        angles = [np.interp(t, lab["t_us"], lab[k]) for k in ("pitch_deg", "roll_deg")]
        want_y.append(np.stack(angles, axis=1).astype(np.float32))
    want_x, want_y = np.concatenate(want_x), np.concatenate(want_y)
    assert np.count_nonzero(want_x) > 0
    for i in range(len(data)):
        x, y = data[i]
        assert x.dtype == torch.float32 and x.shape == (900,)
        assert y.dtype == torch.float32 and y.shape == (2,)
        assert x.numpy().tobytes() == want_x[i].tobytes(), i
        assert y.numpy().tobytes() == want_y[i].tobytes(), i
    # Batched through a DataLoader, as a training script reads it.
    loader = torch.utils.data.DataLoader(data, batch_size=32, shuffle=False)
    xs, ys = zip(*loader)
    assert [len(b) for b in xs] == [32, 32, 32, 24]
    assert torch.cat(xs).numpy().tobytes() == want_x.tobytes()
    assert torch.cat(ys).numpy().tobytes() == want_y.tobytes()
    # One trial, and another sampling: the same rows as evtac.dataset_features gives.
    one = evtac.torch.FeatureDataset(ds, rep, trials=[meta.trials[1]], motion_points=20,
                                     stop_points=5)
    ref = evtac.dataset_features(ds, rep, trials=[meta.trials[1]], motion_points=20,
                                 stop_points=5)
    assert len(one) == 25
    assert torch.stack([one[i][0] for i in range(25)]).numpy().tobytes() == ref.features.tobytes()


def test_dataset_feature_errors(datasets, tmp_path):
    _, ds = datasets
    with pytest.raises(ValueError, match="no trial `nope`"):
        evtac.dataset_features(ds, trials=["nope"])
    with pytest.raises(ValueError, match="crop"):
        evtac.dataset_features(ds, evtac.Representation(roi=(160, 160)))
    with pytest.raises(OSError):
        evtac.dataset_features(tmp_path / "none")


def test_torch_is_loaded_only_when_evtac_torch_is_used(torch):
    code = (
        "import sys, evtac\n"
        "assert 'torch' not in sys.modules\n"
        "assert evtac.torch.FeatureDataset.__module__ == 'evtac.torch'\n"
        "assert 'torch' in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
