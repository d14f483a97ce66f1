"""Demonstrations and the HDF5 file format that stores many of them.

A :class:`Demonstration` is one recorded motion of a tool: time stamps, poses and (optionally)
the contact wrench. It validates itself when constructed, so every instance in memory is usable.

File layout (``format="teachfit-demos"``, ``format_version=1``)::

    /                       attrs: format, format_version, units (JSON)
    /demos/000              attrs: task, source, frame, child_frame, name, meta (JSON)
    /demos/000/t            (T,)   float64, s
    /demos/000/pos          (T, 3) float64, m
    /demos/000/quat         (T, 4) float64, w x y z
    /demos/000/wrench       (T, 6) float64, N and N*m (absent when not recorded)
    /demos/001 ...

Files are built in memory and written atomically (temporary file in the same directory, then
``os.replace``), so a failed write (a full disk, ``ulimit -f``) never leaves a half-written file
behind. Reading refuses links to other files and checks each dataset's kind, value type and
declared size before reading it (:mod:`teachfit.core.h5file`); text attributes must be text.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import h5py
import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation, Slerp

from teachfit.core.errors import DatasetError
from teachfit.core.geometry import Pose, rotation_to_wxyz, wxyz_to_rotation
from teachfit.core.h5file import H5Reader, open_hdf5, shown, write_hdf5
from teachfit.demonstrations.rawlog import sampling_rate

SOURCES: tuple[str, ...] = (
    "simulated-teacher",
    "imported",
    "captured",
    "synthetic",
    "kinesthetic",
)
MIN_SAMPLES = 2
QUAT_NORM_TOL = 1e-3
FORMAT = "teachfit-demos"
FORMAT_VERSION = 1
UNITS: dict[str, str] = {"t": "s", "pos": "m", "quat": "1 (w,x,y,z)", "wrench": "N, N*m"}
WHAT = "demonstration file"
#: a demonstration group's text attributes and their defaults (None: required)
TEXT_ATTRS: tuple[tuple[str, str | None], ...] = (
    ("task", None), ("source", None), ("frame", "world"), ("child_frame", "tool"), ("name", ""),
    ("meta", "{}"),
)  # fmt: skip

MetaValue = str | int | float | bool | list[float]


def _first_row(bad: npt.ArrayLike) -> int | None:
    """Index of the first True entry of a boolean (T,) mask, or None."""
    rows = np.flatnonzero(bad)
    return int(rows[0]) if rows.size else None


def _rot(quat: np.ndarray) -> Rotation:
    """Rotation from (T, 4) or (4,) quaternions in w, x, y, z order."""
    return wxyz_to_rotation(quat)


def _quat_wxyz(rot: Rotation) -> np.ndarray:
    """Quaternions of a rotation in w, x, y, z order, shape (T, 4) or (4,) (scipy's sign)."""
    return rotation_to_wxyz(rot, canonical=False)


def _array(value: Any, column: str, width: int | None, n: int | None) -> np.ndarray:
    """Validated read-only float64 copy with shape (n,) or (n, width); NaN/inf rejected."""
    try:
        probe = np.asarray(value)
        kind = probe.dtype.kind
    except (TypeError, ValueError) as exc:
        raise DatasetError(f"not a numeric array ({exc})", column=column) from exc
    if kind not in "iuf":  # strings, complex numbers, booleans, objects: no silent conversion
        raise DatasetError(f"holds {probe.dtype} values, not real numbers", column=column)
    arr = np.array(probe, dtype=np.float64, copy=True)
    want = "(T,)" if width is None else f"(T, {width})"
    if (width is None and arr.ndim != 1) or (width is not None and arr.shape[1:] != (width,)):
        raise DatasetError(f"shape {arr.shape}, expected {want}", column=column)
    if n is not None and arr.shape[0] != n:
        raise DatasetError(f"{arr.shape[0]} samples but t has {n}", column=column)
    finite = np.isfinite(arr) if width is None else np.isfinite(arr).all(axis=1)
    row = _first_row(~finite)
    if row is not None:
        raise DatasetError(f"non-finite value {arr[row]}", row=row, column=column)
    return arr


@dataclass(frozen=True, eq=False)
class Demonstration:
    """One demonstrated tool motion.

    Parameters
    ----------
    t : ndarray, shape (T,)
        Time stamps in seconds, finite and strictly increasing; ``T >= MIN_SAMPLES``.
    pos : ndarray, shape (T, 3)
        Position of the ``child_frame`` origin expressed in ``frame``, metres.
    quat : ndarray, shape (T, 4)
        Orientation of ``child_frame`` in ``frame`` as unit quaternions (w, x, y, z). Norms must
        be within 1e-3 of 1; normalised copies are stored.
    wrench : ndarray, shape (T, 6), or None
        ``[fx fy fz tx ty tz]`` in N and N*m: the wrench the environment exerts on the tool,
        expressed in ``frame``. None when not recorded (e.g. captured from video).
    task : str
        Task name, e.g. ``"peg2d"``, ``"socket3d"``, ``"l-groove"``.
    source : str
        One of :data:`SOURCES`.
    frame, child_frame : str
        Reference frame of the poses and the frame whose pose is recorded.
    name : str
        Free-form label.
    meta : mapping
        JSON-serialisable extra information (string keys).

    Raises
    ------
    DatasetError
        Naming the offending field (``column``) and the first offending sample (``row``).

    Notes
    -----
    All arrays are stored as read-only float64 copies. Equality (``==``) compares all fields
    exactly.
    """

    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    wrench: np.ndarray | None
    task: str
    source: str
    frame: str = "world"
    child_frame: str = "tool"
    name: str = ""
    meta: Mapping[str, MetaValue] = field(default_factory=dict)

    def __post_init__(self) -> None:
        t = _array(self.t, "t", None, None)
        n = t.shape[0]
        if n < MIN_SAMPLES:
            raise DatasetError(f"{n} samples, need at least {MIN_SAMPLES}", column="t")
        row = _first_row(np.diff(t) <= 0.0)
        if row is not None:
            raise DatasetError(
                f"time not strictly increasing ({t[row]} then {t[row + 1]})",
                row=row + 1,
                column="t",
            )
        pos = _array(self.pos, "pos", 3, n)
        quat = _array(self.quat, "quat", 4, n)
        norms = np.linalg.norm(quat, axis=1)
        row = _first_row(np.abs(norms - 1.0) > QUAT_NORM_TOL)
        if row is not None:
            raise DatasetError(
                f"quaternion norm {norms[row]:.6g} is not 1 (tolerance {QUAT_NORM_TOL})",
                row=row,
                column="quat",
            )
        # normalise, leaving rows already unit to round-off alone so that re-validating a
        # stored demonstration (e.g. after a file round trip) does not change its bits
        quat = np.where(np.abs(norms - 1.0)[:, None] > 1e-14, quat / norms[:, None], quat)
        wrench = None if self.wrench is None else _array(self.wrench, "wrench", 6, n)
        for label in ("task", "frame", "child_frame"):
            value = getattr(self, label)
            if not isinstance(value, str) or not value:
                raise DatasetError(f"must be a non-empty string, got {value!r}", column=label)
        if not isinstance(self.name, str):
            raise DatasetError(f"must be a string, got {self.name!r}", column="name")
        if self.source not in SOURCES:
            raise DatasetError(f"{self.source!r} is not one of {SOURCES}", column="source")
        meta = _checked_meta(self.meta)
        for arr in (t, pos, quat, wrench):
            if arr is not None:
                arr.setflags(write=False)
        for label, value in (("t", t), ("pos", pos), ("quat", quat), ("wrench", wrench)):
            object.__setattr__(self, label, value)
        object.__setattr__(self, "meta", meta)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Demonstration):
            return NotImplemented
        if (self.wrench is None) != (other.wrench is None):
            return False
        arrays = [(self.t, other.t), (self.pos, other.pos), (self.quat, other.quat)]
        if self.wrench is not None and other.wrench is not None:
            arrays.append((self.wrench, other.wrench))
        labels = ("task", "source", "frame", "child_frame", "name", "meta")
        return all(np.array_equal(a, b) for a, b in arrays) and all(
            getattr(self, k) == getattr(other, k) for k in labels
        )

    __hash__ = None  # type: ignore[assignment]  # mutable-by-content semantics, like ndarray

    @property
    def n_samples(self) -> int:
        """Number of samples T."""
        return int(self.t.shape[0])

    @property
    def start_pose(self) -> Pose:
        """The first pose as a world pose (``tool2world``); a demonstration stored in another
        frame (e.g. a robot base) raises :class:`DatasetError` saying how to import it."""
        if self.frame != "world":
            raise DatasetError(
                f"demonstration {self.name!r} is stored in frame {self.frame!r}, not the "
                "simulation world: its start is no world pose; import it with the log-to-world "
                "transform (--transform world:x,y,z,qw,qx,qy,qz)"
            )
        return Pose(self.pos[0], self.quat[0])

    @property
    def duration(self) -> float:
        """``t[-1] - t[0]`` in seconds."""
        return float(self.t[-1] - self.t[0])

    @property
    def rate_hz(self) -> float:
        """Sampling rate in Hz from the median time step."""
        return float(1.0 / np.median(np.diff(self.t)))

    def rotvec(self) -> np.ndarray:
        """Orientations as rotation vectors (axis * angle, rad), shape (T, 3), in ``frame``."""
        return _rot(self.quat).as_rotvec()

    def in_search_frame(self) -> Demonstration:
        """The same motion expressed in the "search" frame, whose origin is the first pose.

        ``pos' = R0^T (pos - pos0)``, ``quat' = q0^-1 * quat``, forces and torques rotated by
        ``R0^T`` (the torque reference point is unchanged). The first pose becomes the identity.
        ``meta["search2<frame>"]`` records the origin pose ``[x, y, z, qw, qx, qy, qz]``.
        """
        r0_inv = _rot(self.quat[0]).inv()
        pos = r0_inv.apply(self.pos - self.pos[0])
        quat = np.array(_quat_wxyz(r0_inv * _rot(self.quat)))
        quat[0] = (1.0, 0.0, 0.0, 0.0)  # exactly, rather than to round-off
        wrench = None
        if self.wrench is not None:
            force, torque = self.wrench[:, :3].copy(), self.wrench[:, 3:].copy()
            wrench = np.hstack([r0_inv.apply(force), r0_inv.apply(torque)])
        origin = [float(v) for v in (*self.pos[0], *self.quat[0])]
        meta = {**self.meta, f"search2{self.frame}": origin}
        return replace(self, pos=pos, quat=quat, wrench=wrench, frame="search", meta=meta)

    def resampled(self, rate_hz: float) -> Demonstration:
        """Resample at a constant rate from ``t[0]`` up to ``t[-1]`` (inclusive, within 1e-9 s).

        Positions and wrenches are interpolated linearly, orientations by slerp.

        Raises
        ------
        DatasetError
            If ``rate_hz`` is not positive and finite or gives fewer than ``MIN_SAMPLES``.
        """
        if not (np.isfinite(rate_hz) and rate_hz > 0):
            raise DatasetError(f"rate must be positive and finite, got {rate_hz}", column="t")
        n = int(np.floor(self.duration * rate_hz + 1e-9)) + 1
        t = self.t[0] + np.arange(n) / rate_hz
        t[-1] = min(t[-1], self.t[-1])  # guard against round-off beyond the last sample
        pos = np.column_stack([np.interp(t, self.t, self.pos[:, k]) for k in range(3)])
        quat = _quat_wxyz(Slerp(self.t, _rot(self.quat))(t))
        # keep the sign of each quaternion on the hemisphere of the original sample before it
        left = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, self.n_samples - 1)
        quat[np.einsum("ij,ij->i", quat, self.quat[left]) < 0] *= -1.0
        wrench = None
        if self.wrench is not None:
            wrench = np.column_stack([np.interp(t, self.t, self.wrench[:, k]) for k in range(6)])
        return replace(self, t=t, pos=pos, quat=quat, wrench=wrench)


def _checked_meta(meta: Any) -> Mapping[str, MetaValue]:
    """Read-only JSON round-tripped copy of ``meta`` (string keys, no NaN), or DatasetError."""
    if not isinstance(meta, Mapping) or not all(isinstance(k, str) for k in meta):
        raise DatasetError("must be a mapping with string keys", column="meta")
    try:
        return MappingProxyType(json.loads(json.dumps(dict(meta), allow_nan=False)))
    except (TypeError, ValueError) as exc:
        raise DatasetError(f"not JSON-serialisable ({exc})", column="meta") from exc


def _located(err: DatasetError, path: Path, context: str = "") -> DatasetError:
    """Copy of ``err`` that also names ``path`` (and an optional context such as a demo key)."""
    prefix = str(DatasetError("", path=err.path, row=err.row, column=err.column))
    message = str(err)
    message = message[len(prefix) :] if message.startswith(prefix) else message
    return DatasetError(context + message, path=str(path), row=err.row, column=err.column)


def _write_demo(group: h5py.Group, demo: Demonstration) -> None:
    """Write one demonstration into an (empty) HDF5 group."""
    for label in ("t", "pos", "quat", "wrench"):
        value = getattr(demo, label)
        if value is not None:
            group.create_dataset(label, data=value)
    for label in ("task", "source", "frame", "child_frame", "name"):
        group.attrs[label] = getattr(demo, label)
    group.attrs["meta"] = json.dumps(dict(demo.meta), sort_keys=True)


def _checked_demos(demos: Sequence[Demonstration], path: Path) -> list[Demonstration]:
    items = list(demos)
    if not items:
        raise DatasetError("no demonstrations to write", path=str(path))
    for i, demo in enumerate(items):
        if not isinstance(demo, Demonstration):
            raise DatasetError(
                f"item {i} is a {type(demo).__name__}, not a Demonstration", path=str(path)
            )
    return items


def write_dataset(
    path: str | Path, demos: Sequence[Demonstration], *, overwrite: bool = False
) -> Path:
    """Write demonstrations to a new HDF5 file atomically; returns the path written.

    Raises
    ------
    DatasetError
        If the file exists and ``overwrite`` is False, ``demos`` is empty or holds something that
        is not a :class:`Demonstration`.
    """
    path = Path(path)
    items = _checked_demos(demos, path)
    if path.exists() and not overwrite:
        raise DatasetError(
            "file exists (pass --overwrite, or overwrite=True in Python, to replace it)",
            path=str(path),
        )

    def fill(f: h5py.File) -> None:
        f.attrs["format"] = FORMAT
        f.attrs["format_version"] = FORMAT_VERSION
        f.attrs["units"] = json.dumps(UNITS)
        group = f.create_group("demos")
        for i, demo in enumerate(items):
            _write_demo(group.create_group(f"{i:03d}"), demo)

    return write_hdf5(path, fill, WHAT)


def append_dataset(path: str | Path, demos: Sequence[Demonstration]) -> Path:
    """Append demonstrations to a dataset file (created if missing), atomically."""
    path = Path(path)
    if not path.exists():
        return write_dataset(path, demos)
    items = _checked_demos(demos, path)
    with _open(path) as (reader, group, keys):
        for key in keys:  # the old demonstrations must be readable: no damage is carried on
            _read_group(reader, group, key)
        start = int(keys[-1]) + 1

    def fill(f: h5py.File) -> None:
        for i, demo in enumerate(items, start=start):
            _write_demo(f["demos"].create_group(f"{i:03d}"), demo)

    return write_hdf5(path, fill, WHAT, base=path)


def check_appendable(path: str | Path) -> None:
    """Refuse, before any work, an existing file that demonstrations cannot be appended to
    (not a demonstration file, links to other files, damaged); a missing file is fine."""
    path = Path(path)
    if path.exists():
        read_dataset(path)


@contextmanager
def _open(path: Path) -> Iterator[tuple[H5Reader, h5py.Group, list[str]]]:
    """Open and check a dataset file (:func:`~teachfit.core.h5file.open_hdf5`: no links to
    other files, sizes checked before reading); yields its reader, its ``/demos`` group and the
    sorted demo keys."""
    with open_hdf5(path) as reader:
        f = reader.file
        fmt = f.attrs.get("format")
        fmt = fmt.decode(errors="replace") if isinstance(fmt, bytes) else fmt
        if not isinstance(fmt, str) or fmt != FORMAT:
            raise DatasetError(
                f"format attribute is {shown(fmt)}, expected {FORMAT!r}", path=str(path)
            )
        reader.check_version(FORMAT_VERSION)
        group = reader.group(f, "demos")
        keys = sorted((k for k in group if re.fullmatch(r"\d+", k)), key=int)
        if not keys:
            raise DatasetError("the /demos group holds no demonstrations", path=str(path))
        yield reader, group, keys


def _read_group(reader: H5Reader, parent: h5py.Group, key: str) -> Demonstration:
    """The demonstration in group ``key`` of ``parent`` (kinds, types and sizes checked before
    anything is read)."""
    path = reader.path
    group = reader.group(parent, key)
    arrays = {label: reader.dataset(group, label) for label in ("t", "pos", "quat")}
    wrench = reader.dataset(group, "wrench", required=False)
    labels = {label: reader.text(group, label, default) for label, default in TEXT_ATTRS}
    try:
        meta = json.loads(labels["meta"])
        return Demonstration(
            t=arrays["t"],
            pos=arrays["pos"],
            quat=arrays["quat"],
            wrench=wrench,
            task=labels["task"],
            source=labels["source"],
            frame=labels["frame"],
            child_frame=labels["child_frame"],
            name=labels["name"],
            meta=meta,
        )
    except json.JSONDecodeError as exc:
        raise DatasetError(
            f"{group.name}: bad meta JSON ({exc})", path=str(path), column="meta"
        ) from exc
    except DatasetError as exc:
        raise _located(exc, path, f"{group.name}: ") from exc


def read_dataset(path: str | Path) -> list[Demonstration]:
    """Read every demonstration of a dataset file, in index order.

    Raises
    ------
    DatasetError
        Naming the file, for a missing or non-HDF5 file, a wrong ``format`` attribute, an
        unsupported version, missing datasets or invalid data (NaN, bad quaternions, ...).
    """
    path = Path(path)
    with _open(path) as (reader, group, keys):
        return [_read_group(reader, group, k) for k in keys]


def read_demo(spec: str | Path) -> Demonstration:
    """Read one demonstration from ``"file.h5:INDEX"`` or the first one from ``"file.h5"``.

    Raises
    ------
    DatasetError
        For an out-of-range index (the message says how many demos exist) or an unreadable file.
    """
    index = 0
    match = re.fullmatch(r"(.+):(-?\d+)", str(spec)) if isinstance(spec, str) else None
    path = Path(match.group(1)) if match else Path(spec)
    if match:
        index = int(match.group(2))
    with _open(path) as (reader, group, keys):
        if not 0 <= index < len(keys):
            raise DatasetError(
                f"index {index} out of range: the file holds {len(keys)} demos"
                + (f" (0..{len(keys) - 1})" if keys else ""),
                path=str(path),
            )
        return _read_group(reader, group, keys[index])


def read_demos(spec: str | Path) -> list[Demonstration]:
    """Every demonstration of ``"file.h5"``, or those picked by ``"file.h5:INDEX[,INDEX...]"``
    (in the order given).

    Raises
    ------
    DatasetError
        For an out-of-range index, a repeated index or an unreadable file.
    """
    match = re.fullmatch(r"(.+):(\d+(?:,\d+)*)", str(spec)) if isinstance(spec, str) else None
    if not match:
        return read_dataset(spec)
    path, picks = Path(match.group(1)), [int(i) for i in match.group(2).split(",")]
    if len(set(picks)) != len(picks):
        raise DatasetError(f"index repeated in {match.group(2)!r}", path=str(path))
    demos = read_dataset(path)
    bad = [i for i in picks if i >= len(demos)]
    if bad:
        raise DatasetError(
            f"index {bad[0]} out of range: the file holds {len(demos)} demos"
            + (f" (0..{len(demos) - 1})" if demos else ""),
            path=str(path),
        )
    return [demos[i] for i in picks]


def _rate_hz(d: Demonstration) -> float:
    """The stored ``meta["rate_hz"]`` of an import, else the nearest plain rate of ``d.t``."""
    rate = d.meta.get("rate_hz")
    return sampling_rate(d.t) if rate is None or isinstance(rate, list) else float(rate)


def dataset_summary(path: str | Path) -> list[dict[str, Any]]:
    """One row per demonstration for a table: index, name, task, source, samples, duration (s),
    rate (Hz: the stored ``meta["rate_hz"]`` of an import, else the nearest plain rate that
    the time steps support, :func:`~teachfit.demonstrations.rawlog.sampling_rate`)."""

    return [
        {
            "index": i,
            "name": d.name,
            "task": d.task,
            "source": d.source,
            "samples": d.n_samples,
            "duration": d.duration,
            "rate": _rate_hz(d),
        }
        for i, d in enumerate(read_dataset(path))
    ]
