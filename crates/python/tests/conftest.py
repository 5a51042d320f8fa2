"""Shared fixtures of the package's tests: the real recordings, the `evtac` command built by cargo
(the tests compare the package with it), and helpers to run it.

Fixtures live in `../shared/fixtures/real` beside the checkout, or under `$EVTAC_SHARED`. The
command is `$EVTAC_BIN`, else `evtac` in cargo's target folder (`$CARGO_TARGET_DIR` or `target/`,
dev profile). Under CI (`CI` set) a missing one fails the tests; elsewhere they are skipped.
"""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]


def _in_ci() -> bool:
    return os.environ.get("CI", "") not in ("", "false")


def _missing(what: str):
    if _in_ci():
        pytest.fail(f"{what} is required under CI but was not found")
    pytest.skip(f"{what} not found")


@pytest.fixture(scope="session")
def real():
    """A function: the path of a file under `shared/fixtures/real/`."""
    shared = Path(os.environ.get("EVTAC_SHARED", ROOT.parent / "shared"))

    def path(name: str) -> Path:
        p = shared / "fixtures" / "real" / name
        if not p.is_file():
            _missing(f"the fixture {p}")
        return p

    return path


@pytest.fixture(scope="session")
def cli():
    """A function running the `evtac` command with arguments; returns its stdout."""
    exe = os.environ.get("EVTAC_BIN")
    if exe is None:
        target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
        exe = target / "debug" / "evtac"
    if not Path(exe).is_file():
        _missing(f"the evtac command ({exe}; build it with `cargo build -p evtac`)")

    def run(*args) -> str:
        out = subprocess.run(
            [str(exe), *map(str, args)], capture_output=True, text=True, check=False
        )
        if out.returncode != 0:
            raise AssertionError(f"evtac {' '.join(map(str, args))} failed:\n{out.stderr}")
        return out.stdout

    return run


@pytest.fixture(scope="session")
def torch():
    """The torch module (`.ci/python-env` installs a CPU-only torch into .venv)."""
    try:
        import torch
    except ImportError:
        _missing("torch (`bash .ci/python-env` installs it)")
    return torch


@pytest.fixture(scope="session")
def aedat(real):
    """The DVXplorer 320x240 recording with IMU."""
    return real("dvxplorer_320x240_imu.aedat4")
