"""evtac from Python: contact-angle estimation for event-based tactile sensors.

The functions and classes here call evtac's Rust library, the same code as the ``evtac``
command, so results are bit for bit the command's. Work on data runs with the interpreter
released; arrays come back as numpy arrays that own evtac's buffers (no copy).

Events are numpy structured arrays of :data:`EVENT_DTYPE` (``t`` int64 microseconds, ``x`` and
``y`` int16 pixel coordinates with ``x`` to the right and ``y`` down, ``p`` uint8 1 for ON), the
dtype of evtac's NPY files. Any structured array with integer fields ``t``, ``x``, ``y``, ``p``
is accepted (and converted).

Errors are ``OSError`` for files (missing, unreadable, corrupt) and ``ValueError`` for bad
arguments, with evtac's message naming the file, field or index at fault.

Example, a recording to pitch and roll::

    import numpy as np
    import evtac

    rec = evtac.read("trial.aedat4")
    model = evtac.Model.load("model/")
    rep = model.representation(sensor=rec.resolution)
    times = np.arange(rec.events["t"][0], rec.events["t"][-1], 1000)
    angles = model.predict(rep.features(rec.events, times))  # (N, 2): pitch, roll in degrees
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Any, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _evtac

__version__: str = _evtac.__version__

__all__ = [
    "EVENT_DTYPE",
    "IMU_DTYPE",
    "TRIGGER_DTYPE",
    "ESTIMATE_DTYPE",
    "Recording",
    "Reader",
    "read",
    "open",
    "write",
    "filter",
    "Representation",
    "Features",
    "Model",
    "Estimator",
    "LABEL_DTYPE",
    "simulate",
    "labels",
    "label_trial",
    "DatasetFeatures",
    "dataset_features",
]

#: Events: evtac's NPY event dtype (packed, 13 bytes).
EVENT_DTYPE = np.dtype([("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")])
#: IMU samples: time (us), acceleration (g), angular velocity (deg/s), temperature (deg C).
IMU_DTYPE = np.dtype(
    [("t", "<i8")] + [(k, "<f4") for k in ("ax", "ay", "az", "gx", "gy", "gz", "temperature")]
)
#: Triggers: time (us) and the AEDAT4 trigger type.
TRIGGER_DTYPE = np.dtype([("t", "<i8"), ("kind", "i1")])
#: Online estimates: grid time (us), pitch and roll (deg), processing latency (us).
ESTIMATE_DTYPE = np.dtype(
    [("t_us", "<i8"), ("pitch_deg", "<f4"), ("roll_deg", "<f4"), ("latency_us", "<f8")]
)

#: Labels: time (us), tilt magnitude, contact pitch and roll (deg), as `labels/<trial>.csv`.
LABEL_DTYPE = np.dtype(
    [("t_us", "<i8"), ("theta_deg", "<f8"), ("pitch_deg", "<f8"), ("roll_deg", "<f8")]
)

PathLike = Union[str, "os.PathLike[str]"]
Size = Tuple[int, int]

Recording = _evtac.Recording
Reader = _evtac.Reader


def _event_bytes(events: Any) -> np.ndarray:
    """``events`` as packed :data:`EVENT_DTYPE` records, viewed as bytes."""
    a = np.asarray(events)
    if a.ndim != 1:
        raise ValueError(f"events must be a one-dimensional structured array, not {a.ndim}-D")
    if a.dtype != EVENT_DTYPE:
        names = a.dtype.names or ()
        if not {"t", "x", "y", "p"} <= set(names):
            raise ValueError(
                f"events must have the fields t, x, y, p (evtac.EVENT_DTYPE); got dtype {a.dtype}"
            )
        out = np.empty(len(a), EVENT_DTYPE)
        for field in ("t", "x", "y", "p"):
            column = a[field]
            if column.dtype.kind not in "iub":
                raise ValueError(f"events field {field!r} must be integer, not {column.dtype}")
            if field in ("x", "y") and len(column) and (column.min() < 0 or column.max() > 32767):
                raise ValueError(f"events field {field!r} holds values outside 0..32767")
            out[field] = column
        a = out
    return np.ascontiguousarray(a).view(np.uint8)


def _imu_bytes(imu: Any) -> np.ndarray:
    a = np.asarray(imu)
    if a.ndim != 1 or a.dtype.names is None or set(a.dtype.names) != set(IMU_DTYPE.names):
        raise ValueError(f"imu must be a structured array of evtac.IMU_DTYPE; got dtype {a.dtype}")
    out = np.empty(len(a), IMU_DTYPE)
    for field in IMU_DTYPE.names:
        out[field] = a[field]
    return out.view(np.uint8)


def _times(times_us: Any) -> np.ndarray:
    """Sample times as a contiguous int64 array (whole microseconds)."""
    a = np.asarray(times_us)
    if a.ndim != 1:
        raise ValueError(f"sample times must be one-dimensional, not {a.ndim}-D")
    if a.dtype.kind == "f" and not np.all(np.isfinite(a) & (a == np.round(a))):
        raise ValueError("sample times must be whole microseconds")
    if a.dtype.kind not in "iuf":
        raise ValueError(f"sample times must be numbers, not {a.dtype}")
    return np.ascontiguousarray(a, dtype=np.int64)


def _size(value: Any, what: str) -> Optional[Size]:
    if value is None:
        return None
    try:
        w, h = value
        return int(w), int(h)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be (width, height), not {value!r}") from None


def read(
    path: PathLike,
    roi: Optional[Size] = None,
    resolution: Optional[Size] = None,
    stream: Optional[Union[str, int]] = None,
) -> Recording:
    """Reads a whole event file in any format ``evtac convert`` reads: AEDAT 4.0, 3.1 or 2.0,
    EVT 2.0/2.1/3.0 raw, CSV, NPY, NPZ, HDF5, the NeuroTac lab's pickles, ROS bags.

    ``roi=(w, h)`` keeps the centered ``w x h`` region (coordinates shifted into it; the
    recording's resolution is then the region's). ``resolution=(w, h)`` declares the sensor size
    of files that do not store it (CSV, NPY, NPZ, DSEC's HDF5) and checks every event against
    it. ``stream`` picks the event stream of an AEDAT4 file with several (two cameras): its id,
    name, camera name or ``CAMERA/NAME`` as ``evtac info`` lists them; that camera's IMU comes
    with it. For a ROS bag it names the event topic (``/dvs/events``).

    Returns a :class:`Recording` with ``events``, ``imu``, ``triggers`` (structured arrays),
    ``resolution``, ``format`` and ``source``.
    """
    return _evtac.read(
        os.fspath(path), _size(roi, "roi"), _size(resolution, "resolution"), _stream(stream)
    )


def _stream(stream: Optional[Union[str, int]]) -> Optional[str]:
    return None if stream is None else str(stream)


def open(
    path: PathLike,
    roi: Optional[Size] = None,
    resolution: Optional[Size] = None,
    chunk_events: int = 65536,
    stream: Optional[Union[str, int]] = None,
) -> Reader:
    """Opens a large event file for reading in chunks.

    Iterating the returned :class:`Reader` yields :class:`Recording` objects of at least
    ``chunk_events`` events each (the last may be shorter), with the IMU samples and triggers
    read alongside. ``roi``, ``resolution`` and ``stream`` are as for :func:`read`.
    """
    return _evtac.Reader(
        os.fspath(path),
        _size(roi, "roi"),
        _size(resolution, "resolution"),
        chunk_events,
        _stream(stream),
    )


def write(
    path: PathLike,
    events: Any,
    imu: Any = None,
    resolution: Optional[Size] = None,
    source: Optional[str] = None,
) -> None:
    """Writes events to ``path``; its extension picks the format: ``.aedat4``, ``.csv``, ``.npy``.

    AEDAT4 needs ``resolution=(w, h)`` and also stores ``imu`` (an :data:`IMU_DTYPE` array)
    and ``source`` (the camera name, default ``evtac``); CSV and NPY hold events only. Events
    must be in time order and, when ``resolution`` is given, inside it.
    """
    _evtac.write(
        os.fspath(path),
        _event_bytes(events),
        None if imu is None else _imu_bytes(imu),
        _size(resolution, "resolution"),
        source,
    )


def filter(
    events: Any,
    resolution: Size,
    specs: Union[str, Sequence[str]],
    counts: bool = False,
) -> Union[np.ndarray, Tuple[np.ndarray, List[Tuple[str, int]]]]:
    """The events kept by the filters ``specs``, applied in order, as ``evtac filter --filter
    SPEC`` applies them (the same events: dv-processing 2.0.4's where it has the filter).

    ``specs`` are the command line's SPECs: ``background-activity=10ms`` (the NeuroTac lab's
    capture filter), ``fast-decay=HALF_LIFE[,SUBDIVISION[,THRESHOLD]]``, ``k-noise=DURATION``,
    ``polarity=on|off``, ``region=X,Y,W,H``, ``refractory=DURATION``, ``circle=CX,CY,R``,
    ``mask=FILE``, ``hot-pixels=FILE`` and ``hot-pixels=auto`` (the hot pixels learned from
    ``events``' stretches at rest, as ``evtac stats`` finds them; a ValueError when there are
    none). ``events`` (an :data:`EVENT_DTYPE` array, in time
    order) lie on a ``resolution=(w, h)`` sensor. With ``counts=True`` also returns each
    filter's SPEC with the events it removed, ``[(spec, removed), ...]`` in order.

    >>> kept = evtac.filter(rec.events, rec.resolution, ["background-activity=10ms"])  # doctest: +SKIP

    A :class:`Recording` filters itself, IMU and triggers kept:
    ``filtered, removed = rec.filter(["background-activity=10ms"])``.
    """
    size = _size(resolution, "resolution")
    if size is None:
        raise ValueError("resolution=(width, height) is needed: the filters keep state per pixel")
    specs = [specs] if isinstance(specs, str) else list(specs)
    kept, removed = _evtac.filter(_event_bytes(events), size, specs)
    return (kept, removed) if counts else kept


class Representation:
    """A static, dynamic, combined, stacked or late representation, or a time surface, polarity
    histogram or voxel grid, as ``evtac represent`` builds it.

    ``kind`` is ``"static"`` (exponential-decay accumulator, masked and thresholded),
    ``"dynamic"`` (sliding-window event count, thresholded), ``"combined"`` (their pixel-wise
    OR), or one of evtac's learned fusions, ``"stacked"`` and ``"late"``: both frames pooled
    side by side (1800 features, the static frame's first), for a network that learns how to
    fuse them (a dense one, or one branch per frame). ``settings`` are the CLI's, with its defaults: static ``decay`` (``"exponential"``,
    ``"linear"``, ``"none"``), ``tau_ms`` (1000), ``eta`` (0.15), ``threshold`` (2),
    ``threshold_space`` (``"potential"``, ``"u8"``), ``comparison`` (``"gt"``, ``"ge"``),
    ``min_potential`` (0), ``max_potential`` (1), ``neutral_potential`` (0), ``polarity``
    (``"signed"``, ``"ignore"``), ``synchronous_decay`` (False); dynamic ``window_ms`` (640)
    and ``count_threshold`` (0).

    The real-valued kinds the paper did not choose are tonic 1.7's transforms, evaluated at each
    sample time with the events before it: ``"time-surface"`` (per polarity
    ``exp(-(t - t_last) / tau)``; ``tau_ms`` (100), ``threshold`` in (0, 1) to binarize
    (default: continuous)), ``"histogram"`` (event counts per polarity over ``window_ms``
    (640)) and ``"voxel-grid"`` (``bins`` (5) signed bins over ``window_ms`` (640)). Their
    features are each channel's 30x30 pooled cells, one channel after the other, e.g.::

        rep = evtac.Representation("voxel-grid", sensor=(640, 480), window_ms=320, bins=3)
        rep.frames(events, times).shape   # (N, 3, 240, 240), float32
        rep.features(events, times).shape  # (N, 2700)

    Events are in full-sensor coordinates of a ``sensor=(w, h)`` sensor and cropped to its
    centered ``roi`` (default 240x240, the paper's; ``None``: the whole sensor). Without
    ``sensor``, events are taken as already cropped to a ``roi``-sized frame.

    ``mask`` is a no-contact mask: a 2-D array of the crop's size (non-zero = masked), or a
    no-contact recording (a path or an events array) run through the same static settings.

    :meth:`features`, :meth:`frames` and :meth:`potentials` compute from scratch at the given
    sample times; :meth:`push` and :meth:`advance_to` keep an incremental state, which gives
    the same numbers for any chunking of the events.
    """

    def __init__(
        self,
        kind: str = "combined",
        sensor: Optional[Size] = None,
        roi: Optional[Size] = (240, 240),
        mask: Any = None,
        **settings: Any,
    ) -> None:
        sensor = _size(sensor, "sensor")
        roi = _size(roi, "roi")
        pixels = mask_events = None
        if isinstance(mask, (str, os.PathLike)):
            mask_events = _event_bytes(read(mask, roi=roi if sensor is None else None).events)
        elif mask is not None:
            m = np.asarray(mask)
            if m.dtype.names is not None:
                mask_events = _event_bytes(m)
            elif m.ndim == 2:
                pixels = np.ascontiguousarray(m != 0, dtype=np.uint8)
            else:
                raise ValueError(f"mask must be a 2-D array, a path or events, not {m.ndim}-D")
        self._inner = _evtac.Representation(
            kind, json.dumps(settings), sensor, roi, pixels, mask_events
        )

    @classmethod
    def _wrap(cls, inner: _evtac.Representation) -> "Representation":
        self = cls.__new__(cls)
        self._inner = inner
        return self

    def features(self, events: Any, times_us: Any) -> "Features":
        """Pooled features at each sample time: float32 ``(N, 900)`` on a 240x240 crop
        (``(N, 1800)`` for stacked and late), as :class:`Features` that remember what made
        them, so that :meth:`Model.predict` refuses them for a model that reads other ones."""
        array = self._inner.features(_event_bytes(events), _times(times_us))
        return Features._made_by(array, self._inner.provenance)

    def frames(self, events: Any, times_us: Any) -> np.ndarray:
        """Binary frames at each sample time: uint8 ``(N, height, width)``, 0 or 1 (stacked and
        late: ``(N, 2 * height, width)``, the static frame above the dynamic one). For a time
        surface, histogram or voxel grid: float32 ``(N, channels, height, width)``, channels in
        tonic's order (OFF then ON; voxel bins in time order)."""
        return self._inner.frames(_event_bytes(events), _times(times_us))

    def potentials(self, events: Any, times_us: Any) -> np.ndarray:
        """The static accumulator's potentials: float32 ``(N, height, width)``."""
        return self._inner.potentials(_event_bytes(events), _times(times_us))

    def push(self, events: Any) -> None:
        """Queues events (time order, also across calls) for the incremental state."""
        self._inner.push(_event_bytes(events))

    def advance_to(self, t_us: int) -> np.ndarray:
        """Applies the queued events with ``t <= t_us``; returns the features then (float32)."""
        return self._inner.advance_to(int(t_us))

    def frame(self) -> np.ndarray:
        """The incremental state's binary frame: uint8 ``(height, width)`` (a real-valued
        kind's: float32 ``(channels, height, width)``)."""
        return self._inner.frame()

    def reset(self) -> None:
        """Forgets the incremental state."""
        self._inner.reset()

    @property
    def kind(self) -> str:
        """``"static"``, ``"dynamic"``, ``"combined"``, ``"stacked"``, ``"late"``,
        ``"time-surface"``, ``"histogram"`` or ``"voxel-grid"``."""
        return self._inner.kind

    @property
    def config(self) -> Mapping[str, Any]:
        """The full config with every default filled in (evtac's JSON form)."""
        return json.loads(self._inner.config_json)

    @property
    def cache_key(self) -> str:
        """The name evtac's feature caches give this config."""
        return self._inner.cache_key

    @property
    def sensor(self) -> Optional[Size]:
        return self._inner.sensor

    @property
    def roi(self) -> Tuple[int, int, int, int]:
        """The crop: ``(x0, y0, width, height)``."""
        return self._inner.roi

    @property
    def mask(self) -> Optional[np.ndarray]:
        return self._inner.mask

    @property
    def feature_len(self) -> int:
        return self._inner.feature_len

    @property
    def time_us(self) -> Optional[int]:
        """The latest time given to :meth:`advance_to`."""
        return self._inner.time_us

    def __repr__(self) -> str:
        return f"evtac.Representation({self.cache_key}, roi={self.roi})"


class Features(np.ndarray):
    """Pooled features (a float32 ``(N, 900)`` or ``(N, 1800)`` array) that remember what made
    them: ``provenance`` is the JSON of the representation with its settings, the crop and the
    mask's digest, as ``evtac represent`` writes beside its NPY (``FEATURES.npy.json``). Rows
    taken from it keep it; ``np.asarray(features)`` is a plain array again."""

    provenance: Optional[str]

    @classmethod
    def _made_by(cls, array: np.ndarray, provenance: str) -> "Features":
        self = array.view(cls)
        self.provenance = provenance
        return self

    def __array_finalize__(self, obj: Any) -> None:
        self.provenance = getattr(obj, "provenance", None)


class Model:
    """A trained model bundle (``evtac train``'s output folder), as ``evtac predict`` loads it."""

    def __init__(self, inner: _evtac.Model) -> None:
        self._inner = inner

    @staticmethod
    def load(dir: PathLike) -> "Model":
        """Loads the bundle folder ``dir``."""
        return Model(_evtac.Model.load(os.fspath(dir)))

    @staticmethod
    def untrained(seed: int, representation: Optional[Representation] = None) -> "Model":
        """A model with seeded initial weights, for ``representation`` (default: combined)."""
        representation = representation or Representation()
        return Model(_evtac.Model.untrained(seed, representation._inner))

    def save(self, dir: PathLike) -> None:
        """Writes the bundle to the folder ``dir``."""
        self._inner.save(os.fspath(dir))

    def predict(self, features: Any, check: bool = True) -> np.ndarray:
        """(pitch, roll) in degrees for each row of float32 ``(N, 900)`` features: ``(N, 2)``.

        ``features`` must have been made as the model's own are (its representation, crop and
        mask): :class:`Features` from :meth:`Representation.features` say what made them, and
        a mismatch is a ``ValueError`` naming both. A plain array says nothing, so it is refused
        unless ``check=False``."""
        if check:
            self._inner.check_features(getattr(features, "provenance", None))
        f = np.asarray(features)
        if f.ndim != 2 or f.dtype.kind != "f":
            raise ValueError(f"features must be a 2-D float array (N, 900); got {f.dtype} {f.shape}")
        return self._inner.predict(np.ascontiguousarray(f, dtype=np.float32))

    def representation(self, sensor: Optional[Size] = None) -> Representation:
        """The representation (config and mask) the model's features are computed with."""
        return Representation._wrap(self._inner.representation(_size(sensor, "sensor")))

    @property
    def config(self) -> Mapping[str, Any]:
        """The bundle's ``config.json``."""
        return json.loads(self._inner.config_json)

    @property
    def dir(self) -> str:
        return os.fspath(self._inner.dir)


class Estimator:
    """The online estimator of ``evtac online``: one estimate every ``interval_us`` of event time.

    :meth:`push` takes chunks of events in full-sensor coordinates of ``sensor=(w, h)``, in
    time order, and returns the estimates they made final (:data:`ESTIMATE_DTYPE`);
    :meth:`finish` returns the rest up to the last event.
    """

    def __init__(self, model: Model, sensor: Size, interval_us: int = 1000) -> None:
        size = _size(sensor, "sensor")
        if size is None:
            raise ValueError("the estimator needs sensor=(width, height)")
        self._inner = _evtac.Estimator(model._inner, size, int(interval_us))

    def push(self, events: Any, horizon_us: Optional[int] = None) -> np.ndarray:
        """Processes a chunk; returns the estimates it made final."""
        return self._inner.push(_event_bytes(events), horizon_us)

    def finish(self) -> np.ndarray:
        """Ends the stream; returns the estimates up to the last event's time."""
        return self._inner.finish()

    @property
    def counters(self) -> Mapping[str, int]:
        """Events received, inside the crop, and skipped as out of order."""
        events, in_roi, out_of_order = self._inner.counters
        return {"events": events, "events_in_roi": in_roi, "events_out_of_order": out_of_order}


def simulate(
    protocol: str,
    scale: str,
    seed: int,
    out: PathLike,
    limit: Optional[int] = None,
    params: Optional[Mapping[str, Any]] = None,
) -> int:
    """Simulates a protocol into the dataset folder ``out``, as ``evtac simulate``.

    ``protocol``: ``exp1``, ``exp2``, ``exp3-speed``, ``exp3-depth`` or ``no-contact``;
    ``scale``: ``tiny``, ``small`` or ``paper``; the same seed gives the same bytes. ``limit``
    keeps the first trials only; ``params`` overrides simulator parameters (the ``params`` of a
    ``simulator.json``). Returns the number of trials written.
    """
    return _evtac.simulate(
        protocol, os.fspath(out), scale, int(seed), limit,
        None if params is None else json.dumps(params),
    )


def labels(dataset_dir: PathLike, **settings: Any) -> Mapping[str, Any]:
    """Labels every trial of a dataset, as ``evtac labels``: writes ``labels/<trial>.csv``.

    ``settings`` are ``evtac_labels::LabelConfig`` fields (e.g. ``cutoff_hz``, ``scale``).
    Returns the per-trial reports and summaries that ``evtac labels --json`` prints.
    """
    return json.loads(_evtac.labels(os.fspath(dataset_dir), json.dumps(settings)))


def label_trial(dataset_dir: PathLike, trial: str, **settings: Any) -> np.ndarray:
    """The labels of one trial of a dataset, in memory (:data:`LABEL_DTYPE`)."""
    t, theta, pitch, roll = _evtac.label_trial(os.fspath(dataset_dir), trial, json.dumps(settings))
    out = np.empty(len(t), LABEL_DTYPE)
    out["t_us"], out["theta_deg"], out["pitch_deg"], out["roll_deg"] = t, theta, pitch, roll
    return out


@dataclass(frozen=True)
class DatasetFeatures:
    """A dataset's samples as training sees them (see :func:`dataset_features`)."""

    #: float32 ``(N, 900)``.
    features: np.ndarray
    #: float32 ``(N, 2)``: pitch and roll in degrees.
    labels: np.ndarray
    #: int64 ``(N,)``: index of each sample's trial in :attr:`trials`.
    trial: np.ndarray
    #: int64 ``(N,)``: sample time in microseconds.
    t_us: np.ndarray
    #: bool ``(N,)``: whether the sample is from the stop phase.
    stop: np.ndarray
    #: The trial names.
    trials: Tuple[str, ...]


def dataset_features(
    dataset_dir: PathLike,
    representation: Optional[Representation] = None,
    trials: Optional[Sequence[str]] = None,
    motion_points: int = 50,
    stop_points: int = 10,
) -> DatasetFeatures:
    """The features and labels of a dataset's trials, through its feature cache, as training
    reads them: ``motion_points`` per trial's motion phase and ``stop_points`` per stop phase,
    computed and cached under ``cache/`` when missing. ``representation`` (default combined) gives
    the config; the mask comes from the dataset's ``no_contact.aedat4``. ``trials``: names
    (default: all, in manifest order).
    """
    representation = representation or Representation()
    features, labels, trial, t_us, stop, names = _evtac.dataset_features(
        os.fspath(dataset_dir), representation._inner,
        None if trials is None else list(trials), motion_points, stop_points,
    )
    return DatasetFeatures(features, labels, trial, t_us, stop, tuple(names))


def __getattr__(name: str) -> Any:
    """``evtac.torch`` after a plain ``import evtac``: imported on first use, so that torch is
    loaded only by code that uses it (an ``ImportError`` naming torch when it is missing)."""
    if name == "torch":
        import importlib

        return importlib.import_module(".torch", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
