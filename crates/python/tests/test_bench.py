"""The package README's benchmark still runs and its three pipelines agree (no timing is
checked: that is the benchmark's job, not a test's)."""

import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benches" / "features.py"


def test_the_benchmark_runs_and_its_pipelines_give_the_same_features(aedat):
    pytest.importorskip("dv_processing")  # .ci/python-env installs it
    out = subprocess.run([sys.executable, str(BENCH), str(aedat), "--repeat", "1"],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "all three give the same features" in out.stdout, out.stdout
    assert out.stdout.count("\n| ") == 5  # the table: header, rule, three pipelines
