"""Type stub of the native module ``evtac._evtac`` (use the ``evtac`` package, which wraps it).

Events, IMU samples and estimates cross as packed records viewed as ``uint8`` (see
``evtac.EVENT_DTYPE`` and friends); representation settings as a JSON object.
"""

import os
from typing import Iterator, List, Optional, Tuple, Union, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "__version__",
    "read",
    "write",
    "filter",
    "simulate",
    "labels",
    "label_trial",
    "dataset_features",
    "Recording",
    "Reader",
    "Representation",
    "Model",
    "Estimator",
]

__version__: str

_Path = Union[str, os.PathLike[str]]
_Size = Tuple[int, int]
_Bytes = npt.NDArray[np.uint8]

@final
class Recording:
    """A recording or one chunk of it."""

    events: np.ndarray
    imu: np.ndarray
    triggers: np.ndarray
    resolution: Optional[_Size]
    format: str
    source: Optional[str]
    def filter(self, specs: List[str]) -> Tuple[Recording, List[Tuple[str, int]]]: ...

@final
class Reader:
    """A large event file read chunk by chunk."""

    format: str
    source: Optional[str]
    resolution: Optional[_Size]
    def __new__(
        cls,
        path: _Path,
        roi: Optional[_Size] = None,
        resolution: Optional[_Size] = None,
        chunk_events: int = 65536,
        stream: Optional[str] = None,
    ) -> Reader: ...
    def __iter__(self) -> Iterator[Recording]: ...
    def __next__(self) -> Recording: ...

def read(
    path: _Path,
    roi: Optional[_Size] = None,
    resolution: Optional[_Size] = None,
    stream: Optional[str] = None,
) -> Recording: ...
def filter(
    events: _Bytes, resolution: _Size, specs: List[str]
) -> Tuple[np.ndarray, List[Tuple[str, int]]]: ...
def write(
    path: _Path,
    events: _Bytes,
    imu: Optional[_Bytes] = None,
    resolution: Optional[_Size] = None,
    source: Optional[str] = None,
) -> None: ...

@final
class Representation:
    kind: str
    config_json: str
    cache_key: str
    sensor: Optional[_Size]
    roi: Tuple[int, int, int, int]
    mask: Optional[npt.NDArray[np.uint8]]
    feature_len: int
    provenance: str
    time_us: Optional[int]
    def __new__(
        cls,
        kind: str,
        settings: str,
        sensor: Optional[_Size] = None,
        roi: Optional[_Size] = None,
        mask: Optional[npt.NDArray[np.uint8]] = None,
        mask_events: Optional[_Bytes] = None,
    ) -> Representation: ...
    def features(self, events: _Bytes, times: npt.NDArray[np.int64]) -> npt.NDArray[np.float32]: ...
    def frames(
        self, events: _Bytes, times: npt.NDArray[np.int64]
    ) -> npt.NDArray[np.uint8] | npt.NDArray[np.float32]: ...
    def potentials(
        self, events: _Bytes, times: npt.NDArray[np.int64]
    ) -> npt.NDArray[np.float32]: ...
    def push(self, events: _Bytes) -> None: ...
    def advance_to(self, t_us: int) -> npt.NDArray[np.float32]: ...
    def frame(self) -> npt.NDArray[np.uint8] | npt.NDArray[np.float32]: ...
    def reset(self) -> None: ...

@final
class Model:
    config_json: str
    dir: str
    @staticmethod
    def load(dir: _Path) -> Model: ...
    @staticmethod
    def untrained(seed: int, representation: Representation) -> Model: ...
    def save(self, dir: _Path) -> None: ...
    def predict(self, features: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]: ...
    def check_features(self, provenance: Optional[str] = None) -> None: ...
    def representation(self, sensor: Optional[_Size] = None) -> Representation: ...

@final
class Estimator:
    counters: Tuple[int, int, int]
    def __new__(cls, model: Model, sensor: _Size, interval_us: int) -> Estimator: ...
    def push(self, events: _Bytes, horizon_us: Optional[int] = None) -> np.ndarray: ...
    def finish(self) -> np.ndarray: ...

def simulate(
    protocol: str,
    out: _Path,
    scale: str = "small",
    seed: int = 0,
    limit: Optional[int] = None,
    params_json: Optional[str] = None,
) -> int: ...
def labels(dataset_dir: _Path, config_json: str = "{}") -> str: ...
def label_trial(
    dataset_dir: _Path, trial: str, config_json: str = "{}"
) -> Tuple[
    npt.NDArray[np.int64], npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]
]: ...
def dataset_features(
    dataset_dir: _Path,
    representation: Representation,
    trials: Optional[list[str]] = None,
    motion_points: int = 50,
    stop_points: int = 10,
) -> Tuple[
    npt.NDArray[np.float32],
    npt.NDArray[np.float32],
    npt.NDArray[np.int64],
    npt.NDArray[np.int64],
    npt.NDArray[np.bool_],
    list[str],
]: ...
