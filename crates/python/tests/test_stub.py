"""The type stub `_evtac.pyi` matches the compiled module: mypy's stubtest imports `evtac._evtac`
and compares every class, function and signature with the stub."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import evtac


def test_the_stub_matches_the_native_module(tmp_path):
    if os.environ.get("CI", "") in ("", "false"):
        pytest.importorskip("mypy.stubtest")  # under CI, .ci/python-env installed it
    package = Path(evtac.__file__).parent
    out = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "evtac._evtac"],
        cwd=tmp_path,  # mypy's cache goes there
        env={**os.environ, "PYTHONPATH": str(package.parent)},
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stdout + out.stderr
