"""The run-log file format: its marks, and one episode <-> one HDF5 group (the layout is
in :mod:`.recording`)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import numpy.typing as npt

from teachfit.core.geometry import Pose
from teachfit.core.h5file import H5_ERRORS, H5Reader
from teachfit.core.outcome import Outcome
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.engine import ExecutionResult, NodeVisit
from teachfit.execution.episode import Episode
from teachfit.execution.log import ExecutionLog

#: the ExecutionLog arrays, in the order of its fields
LOG_FIELDS: tuple[str, ...] = tuple(ExecutionLog.__dataclass_fields__)
#: scalar summary attributes of an ExecutionResult
NUMBERS: tuple[str, ...] = (
    "t_first_contact",
    "t_end",
    "time_to_success",
    "path_length",
    "peak_force",
    "remaining",
    "wall_s",
)
_STR = h5py.string_dtype()

FORMAT = "teachfit-run"
FORMAT_VERSION = 1
UNITS: dict[str, str] = {
    "t": "s",
    "pos": "m",
    "quat": "1 (w,x,y,z)",
    "wrench": "N, N*m",
    "depth": "m",
    "path_length": "m",
    "peak_force": "N",
}


def _format(f: h5py.File) -> str | None:
    fmt = f.attrs.get("format")
    fmt = fmt.decode(errors="replace") if isinstance(fmt, bytes) else fmt
    return fmt if isinstance(fmt, str) else None


def is_run_log(path: str | Path) -> bool:
    """Whether ``path`` is an HDF5 file whose ``format`` attribute says run log."""
    path = Path(path)
    if not path.is_file() or not h5py.is_hdf5(path):
        return False
    try:
        with h5py.File(path, "r") as f:
            return _format(f) == FORMAT
    except H5_ERRORS:
        return False


def _tri(value: bool | None) -> int:
    return -1 if value is None else int(bool(value))


def _untri(value: Any) -> bool | None:
    return None if int(value) < 0 else bool(value)


def _put(group: h5py.Group, name: str, data: npt.ArrayLike, dtype: Any = np.float64) -> None:
    """A dataset, gzip-compressed when it holds anything (empty ones cannot be chunked)."""
    data = np.asarray(data, dtype=dtype)
    opts = {"compression": "gzip", "compression_opts": 4} if data.size else {}
    group.create_dataset(name, data=data, **opts)


def write_episode(group: h5py.Group, ep: Episode) -> None:
    """Fill ``group`` with one episode."""
    r = ep.result
    group.attrs["name"] = ep.name
    group.attrs["skill"] = r.skill
    group.attrs["outcome"] = r.outcome.value
    group.attrs["reason"] = r.reason
    for label in NUMBERS:
        group.attrs[label] = float(getattr(r, label))
    group.attrs["steps"] = int(r.steps)
    group.attrs["reflex"] = bool(r.reflex)
    group.attrs["detected"] = _tri(r.detected)
    group.attrs["ground_truth_inserted"] = _tri(r.ground_truth_inserted)
    group.attrs["nodes"] = json.dumps(list(r.node_names))
    group.attrs["primitives"] = json.dumps(dict(ep.primitives))
    if ep.start is not None:
        group.attrs["start"] = np.concatenate([ep.start.pos, ep.start.quat])
    for label in LOG_FIELDS:
        _put(group, label, getattr(r.log, label), np.int32 if label == "node" else np.float64)
    visits = group.create_group("visits")
    _put(visits, "node", [v.node for v in r.visits], _STR)
    _put(visits, "t_enter", [v.t_enter for v in r.visits])
    _put(visits, "t_exit", [v.t_exit for v in r.visits])
    _put(visits, "reason", [v.reason for v in r.visits], _STR)
    if ep.planned is not None:
        planned = group.create_group("planned")
        planned.attrs["name"] = ep.planned.name
        for label in ("t", "pos", "quat", "wrench_ff"):
            _put(planned, label, getattr(ep.planned, label))


def _arrays(reader: H5Reader, group: h5py.Group, labels: tuple[str, ...]) -> list[np.ndarray]:
    """Numeric datasets of ``group`` (each required; kinds and sizes checked first)."""
    return [np.asarray(reader.dataset(group, label)) for label in labels]


def _texts(reader: H5Reader, group: h5py.Group, label: str) -> list[str]:
    values = np.atleast_1d(np.asarray(reader.dataset(group, label, "OSU")))
    return [v.decode() if isinstance(v, bytes) else str(v) for v in values]


def read_episode(reader: H5Reader, parent: h5py.Group, key: str) -> Episode:
    """The episode stored in group ``key`` of ``parent`` (DatasetError for a group or dataset
    of the wrong kind or size; KeyError, TypeError or ValueError for a missing or wrong
    attribute)."""
    group = reader.group(parent, key)
    a = group.attrs
    log = ExecutionLog(
        **{
            k: v.astype(int if k == "node" else float)
            for k, v in zip(LOG_FIELDS, _arrays(reader, group, LOG_FIELDS), strict=True)
        }
    )
    vg = reader.group(group, "visits")
    t_enter, t_exit = _arrays(reader, vg, ("t_enter", "t_exit"))
    visits = tuple(
        NodeVisit(n, float(t0), float(t1), why)
        for n, t0, t1, why in zip(
            _texts(reader, vg, "node"), t_enter, t_exit, _texts(reader, vg, "reason"), strict=True
        )
    )
    result = ExecutionResult(
        skill=reader.text(group, "skill"),
        outcome=Outcome(reader.text(group, "outcome")),
        reason=reader.text(group, "reason"),
        visits=visits,
        log=log,
        node_names=tuple(json.loads(reader.text(group, "nodes"))),
        steps=int(a["steps"]),
        reflex=bool(a.get("reflex", False)),  # logs written before it was kept: no reflex
        detected=_untri(a["detected"]),
        ground_truth_inserted=_untri(a["ground_truth_inserted"]),
        **{k: float(a[k]) for k in NUMBERS},
    )
    start = None
    if "start" in a:
        raw = np.asarray(a["start"], dtype=float)
        start = Pose(raw[:3], raw[3:])
    planned = None
    if "planned" in group:
        p = reader.group(group, "planned")
        t, pos, quat, wrench_ff = _arrays(reader, p, ("t", "pos", "quat", "wrench_ff"))
        planned = SetpointTrajectory(t, pos, quat, wrench_ff, name=reader.text(p, "name"))
    primitives = json.loads(reader.text(group, "primitives"))
    return Episode(result, start, planned, primitives, reader.text(group, "name"))
