"""Import a demonstration from a robot's CSV log.

Which CSV column holds which quantity is described by a :class:`ColumnMap`, usually loaded from
a small TOML file. Options go at the top level, column names in a ``[columns]`` table::

    # columns.toml: how to read robot_log.csv
    time_scale = 1.0      # seconds per unit of the time column (1e-3 when the log is in ms)
    length_scale = 1.0    # metres per unit of the position columns (1e-3 for mm)
    delimiter = ","       # one character
    frame = "base"        # frame the logged poses are expressed in (default "world")
    wrench_sign = -1      # +1: the log holds the wrench the environment exerts on the tool;
                          # -1: it holds the wrench the robot applies (it is negated on import)

    [columns]             # our field = CSV header name
    time = "timestamp"
    x = "tcp_x"
    y = "tcp_y"
    z = "tcp_z"
    qw = "tcp_qw"         # qw, qx, qy, qz: optional as a group (missing: identity orientation)
    qx = "tcp_qx"
    qy = "tcp_qy"
    qz = "tcp_qz"
    fx = "fx"             # fx ... tz: optional as a group (missing: no wrench), N and N*m
    fy = "fy"
    fz = "fz"
    tx = "tx"
    ty = "ty"
    tz = "tz"

``time``, ``x``, ``y`` and ``z`` are required; every option has the default shown above except
``frame`` ("world") and ``wrench_sign`` (+1). Unknown keys are an error. The CSV file must have
one header line; other columns are ignored. Times are shifted so that the demonstration starts at
t = 0; the original first time stamp (s) is kept in ``meta["time_offset_s"]``.

Errors name the file, the line (1-based, the header is line 1) and the CSV column.
"""

from __future__ import annotations

import csv
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.dataset import MIN_SAMPLES, QUAT_NORM_TOL, Demonstration

POSITION_KEYS = ("time", "x", "y", "z")
QUAT_KEYS = ("qw", "qx", "qy", "qz")
WRENCH_KEYS = ("fx", "fy", "fz", "tx", "ty", "tz")
OPTION_KEYS = ("time_scale", "length_scale", "delimiter", "frame", "wrench_sign")


def _bare(err: DatasetError) -> str:
    """The message of ``err`` without its "file ..., row ..., column ...: " prefix."""
    prefix = str(DatasetError("", path=err.path, row=err.row, column=err.column))
    message = str(err)
    return message[len(prefix) :] if message.startswith(prefix) else message


@dataclass(frozen=True)
class ColumnMap:
    """Where each quantity is in a CSV log, and the units and conventions of that log.

    Parameters
    ----------
    time, x, y, z : str
        CSV header names of the time and position columns.
    qw, qx, qy, qz : str or None
        Quaternion (w, x, y, z) columns: all four or none (identity orientation).
    fx, fy, fz, tx, ty, tz : str or None
        Force (N) and torque (N*m) columns, expressed in ``frame``: all six or none.
    time_scale : float
        Seconds per unit of the time column (positive).
    length_scale : float
        Metres per unit of the position columns (positive).
    delimiter : str
        One-character field separator.
    frame : str
        Frame the logged poses and wrenches are expressed in.
    wrench_sign : int
        +1 if the log records the wrench the environment exerts on the tool, -1 if it records the
        wrench the robot applies.

    Raises
    ------
    DatasetError
        Naming the offending key (``column``) for an incomplete group or a bad option.
    """

    time: str
    x: str
    y: str
    z: str
    qw: str | None = None
    qx: str | None = None
    qy: str | None = None
    qz: str | None = None
    fx: str | None = None
    fy: str | None = None
    fz: str | None = None
    tx: str | None = None
    ty: str | None = None
    tz: str | None = None
    time_scale: float = 1.0
    length_scale: float = 1.0
    delimiter: str = ","
    frame: str = "world"
    wrench_sign: int = 1

    def __post_init__(self) -> None:
        for key in (*POSITION_KEYS, *QUAT_KEYS, *WRENCH_KEYS):
            value = getattr(self, key)
            required = key in POSITION_KEYS
            if (value is not None or required) and (not isinstance(value, str) or not value):
                raise DatasetError(
                    f"column name must be a non-empty string, got {value!r}", column=key
                )
        for group in (QUAT_KEYS, WRENCH_KEYS):
            given = [k for k in group if getattr(self, k) is not None]
            if given and len(given) != len(group):
                missing = next(k for k in group if getattr(self, k) is None)
                raise DatasetError(f"give all of {group} or none", column=missing)
        names = [n for n in self.mapped().values()]
        dup = next((n for n in names if names.count(n) > 1), None)
        if dup is not None:
            raise DatasetError(f"CSV column {dup!r} is mapped to more than one field", column=dup)
        for key in ("time_scale", "length_scale"):
            value = getattr(self, key)
            ok = isinstance(value, int | float) and not isinstance(value, bool)
            if not ok or not (math.isfinite(value) and value > 0):
                raise DatasetError(f"must be a positive number, got {value!r}", column=key)
        if not isinstance(self.delimiter, str) or len(self.delimiter) != 1:
            raise DatasetError(f"must be one character, got {self.delimiter!r}", column="delimiter")
        if not isinstance(self.frame, str) or not self.frame:
            raise DatasetError(f"must be a non-empty string, got {self.frame!r}", column="frame")
        if self.wrench_sign not in (1, -1) or isinstance(self.wrench_sign, bool):
            raise DatasetError(f"must be +1 or -1, got {self.wrench_sign!r}", column="wrench_sign")

    @property
    def has_quat(self) -> bool:
        """Whether the log has orientation columns."""
        return self.qw is not None

    @property
    def has_wrench(self) -> bool:
        """Whether the log has force/torque columns."""
        return self.fx is not None

    def mapped(self) -> dict[str, str]:
        """Our field name -> CSV column name, for the fields that are mapped, in file order."""
        keys = (*POSITION_KEYS, *QUAT_KEYS, *WRENCH_KEYS)
        return {k: getattr(self, k) for k in keys if getattr(self, k) is not None}

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], *, path: str | None = None) -> ColumnMap:
        """Build from the parsed TOML layout (options at top level, a ``columns`` table)."""
        known_columns = {*POSITION_KEYS, *QUAT_KEYS, *WRENCH_KEYS}
        for key in data:
            if key not in (*OPTION_KEYS, "columns"):
                raise DatasetError(f"unknown key {key!r}", path=path, column=key)
        columns = data.get("columns")
        if not isinstance(columns, Mapping):
            raise DatasetError("missing [columns] table", path=path, column="columns")
        for key in columns:
            if key not in known_columns:
                raise DatasetError(
                    f"unknown key {key!r} in [columns] (known: {sorted(known_columns)})",
                    path=path,
                    column=key,
                )
        for key in POSITION_KEYS:
            if key not in columns:
                raise DatasetError(f"[columns] needs {key!r}", path=path, column=key)
        options = {k: data[k] for k in OPTION_KEYS if k in data}
        try:
            return cls(**dict(columns), **options)
        except DatasetError as exc:
            raise DatasetError(_bare(exc), path=path, column=exc.column) from exc

    @classmethod
    def from_toml(cls, path: str | Path) -> ColumnMap:
        """Load from a TOML file (format in the module docstring)."""
        path = Path(path)
        try:
            with path.open("rb") as f:
                data = tomllib.load(f)
        except OSError as exc:
            raise DatasetError(f"cannot read ({exc.strerror})", path=str(path)) from exc
        except tomllib.TOMLDecodeError as exc:
            raise DatasetError(f"invalid TOML ({exc})", path=str(path)) from exc
        return cls.from_mapping(data, path=str(path))


def _parse(
    csv_path: Path, columns: ColumnMap
) -> tuple[np.ndarray, list[int], list[str], list[str]]:
    """Values (N, K) of the mapped columns, their CSV line numbers, the CSV column names (K,)
    and the raw time cells (N,)."""
    names = list(columns.mapped().values())
    fail = partial(DatasetError, path=str(csv_path))
    try:
        f = csv_path.open(newline="", encoding="utf-8-sig")
    except OSError as exc:
        raise fail(f"cannot read ({exc.strerror})") from exc
    with f:
        reader = csv.reader(f, delimiter=columns.delimiter)
        header = [h.strip() for h in next((row for row in reader if row), [])]
        if not header:
            raise fail("empty file, expected a header line", row=1)
        for name in names:
            if header.count(name) != 1:
                problem = "appears more than once in" if name in header else "is not in"
                raise fail(
                    f"column {problem} the header {header}", row=reader.line_num, column=name
                )
        index = [header.index(name) for name in names]
        values: list[list[float]] = []
        lines: list[int] = []
        times: list[str] = []
        for row in reader:
            if not row or (len(row) == 1 and not row[0].strip()):
                continue  # blank line
            try:
                values.append([float(row[i]) for i in index])
            except (ValueError, IndexError):
                for i, name in zip(index, names, strict=True):
                    cell = row[i] if i < len(row) else None
                    if cell is None or not _is_float(cell):
                        problem = (
                            f"line has only {len(row)} cells"
                            if cell is None
                            else (f"not a number: {cell!r}")
                        )
                        raise fail(problem, row=reader.line_num, column=name) from None
                raise
            lines.append(reader.line_num)
            times.append(row[index[0]])
    data = np.array(values, dtype=np.float64).reshape(len(values), len(index))
    return data, lines, names, times


def _is_float(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _offsets(times: list[str], fallback: np.ndarray) -> np.ndarray:
    """Time cells minus the first one, computed exactly in decimal (epoch time stamps lose
    microseconds in float64); the float difference if a cell is not a plain decimal."""
    try:
        d0 = Decimal(times[0])
        return np.array([float(Decimal(cell) - d0) for cell in times])
    except InvalidOperation:
        return fallback - fallback[0]


def import_csv(
    csv_path: str | Path, columns: ColumnMap, *, task: str, name: str | None = None
) -> Demonstration:
    """Read a demonstration (``source="imported"``) from a CSV robot log.

    Parameters
    ----------
    csv_path : str or Path
        The log: one header line, then one sample per line.
    columns : ColumnMap
        Which columns to read, their units and conventions.
    task : str
        Task name stored in the demonstration.
    name : str, optional
        Demonstration name; the file stem by default.

    Returns
    -------
    Demonstration
        ``t`` (T,) s starting at 0, ``pos`` (T, 3) m, ``quat`` (T, 4) w-x-y-z and ``wrench``
        (T, 6) N, N*m (environment on tool) or None, all in ``columns.frame``.

    Raises
    ------
    DatasetError
        Naming the file, the line (header = line 1) and the CSV column for a missing column,
        a non-numeric or non-finite cell, non-increasing time, fewer than ``MIN_SAMPLES`` rows or
        a quaternion whose norm is off by more than 1e-3.
    """
    csv_path = Path(csv_path)
    where = str(csv_path)
    data, lines, names, times = _parse(csv_path, columns)
    n = data.shape[0]
    if n < MIN_SAMPLES:
        raise DatasetError(f"{n} data rows, need at least {MIN_SAMPLES}", path=where)
    bad = np.argwhere(~np.isfinite(data))
    if bad.size:
        r, c = bad[0]
        raise DatasetError(
            f"non-finite value {data[r, c]}", path=where, row=lines[r], column=names[c]
        )
    raw_t = _offsets(times, data[:, 0])
    steps = np.flatnonzero(np.diff(raw_t) <= 0)
    if steps.size:
        r = int(steps[0]) + 1
        raise DatasetError(
            f"time not strictly increasing ({times[r - 1].strip()} then {times[r].strip()})",
            path=where,
            row=lines[r],
            column=names[0],
        )
    t = raw_t * columns.time_scale
    pos = data[:, 1:4] * columns.length_scale
    k = 4
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    if columns.has_quat:
        quat = data[:, k : k + 4]
        norms = np.linalg.norm(quat, axis=1)
        off = np.flatnonzero(np.abs(norms - 1.0) > QUAT_NORM_TOL)
        if off.size:
            r = int(off[0])
            raise DatasetError(
                f"quaternion ({', '.join(names[k : k + 4])}) has norm {norms[r]:.6g}, not 1 "
                f"(tolerance {QUAT_NORM_TOL})",
                path=where,
                row=lines[r],
                column=names[k],
            )
        k += 4
    wrench = data[:, k : k + 6] * columns.wrench_sign if columns.has_wrench else None
    meta = {"source_file": csv_path.name, "time_offset_s": float(data[0, 0] * columns.time_scale)}
    try:
        return Demonstration(
            t=t,
            pos=pos,
            quat=quat,
            wrench=wrench,
            task=task,
            source="imported",
            frame=columns.frame,
            name=csv_path.stem if name is None else name,
            meta=meta,
        )
    except DatasetError as exc:  # not expected after the checks above; kept for safety
        row = None if exc.row is None else lines[exc.row]
        column = {"t": names[0], "pos": names[1], "quat": names[4] if columns.has_quat else None}
        raise DatasetError(
            _bare(exc), path=where, row=row, column=column.get(exc.column or "", exc.column)
        ) from exc
