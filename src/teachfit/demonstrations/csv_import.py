"""Import demonstrations from a robot's CSV log.

Which column holds which quantity is described by a
:class:`~teachfit.demonstrations.column_map.ColumnMap` (a TOML file; ``examples/columns.toml``
documents every key). The CSV file must have one header line; other columns are ignored.

Times are shifted so that the log starts at t = 0; the original first time stamp (s) is kept in
``meta["time_offset_s"]``. A log without a time column needs ``rate_hz``.

The file is read in bounded memory by :mod:`~teachfit.demonstrations.csv_table`, which also
drops a last line cut short while the log was being written (with a note) and refuses what is not
a CSV log (binary, UTF-16, NUL bytes, over-long lines, unclosed quotes, ragged rows).

Errors name the file, the line (1-based, the header is line 1) and the CSV column.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from decimal import Decimal, InvalidOperation
from pathlib import Path

import numpy as np

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.column_map import ColumnMap
from teachfit.demonstrations.csv_table import read_table
from teachfit.demonstrations.dataset import MIN_SAMPLES, QUAT_NORM_TOL, Demonstration
from teachfit.demonstrations.frames import to_wxyz
from teachfit.demonstrations.importing import ImportOptions, build_demos
from teachfit.demonstrations.rawlog import RawLog

__all__ = ["ColumnMap", "import_csv", "read_csv_log"]


def _offsets(times: list[str], fallback: np.ndarray) -> np.ndarray:
    """Time cells minus the first one, computed exactly in decimal (epoch time stamps lose
    microseconds in float64); the float difference if a cell is not a plain decimal."""
    try:
        d0 = Decimal(times[0])
        return np.array([float(Decimal(cell) - d0) for cell in times])
    except InvalidOperation:
        return fallback - fallback[0]


def read_csv_log(csv_path: str | Path, columns: ColumnMap) -> RawLog:
    """Read a CSV robot log into a :class:`RawLog` (SI units, w-x-y-z, environment wrench).

    Raises
    ------
    DatasetError
        Naming the file, the line (header = line 1) and the CSV column for a missing column,
        a non-numeric or non-finite cell, non-increasing time, fewer than ``MIN_SAMPLES`` rows or
        a quaternion whose norm is off by more than 1e-3.
    """
    csv_path = Path(csv_path)
    where = str(csv_path)
    names = list(columns.mapped().values())
    table = read_table(
        csv_path, names, columns.delimiter, time=columns.time is not None, marker=columns.marker
    )
    data, lines = table.values, [int(v) for v in table.lines]
    n = data.shape[0]
    if n < MIN_SAMPLES:
        raise DatasetError(f"{n} data rows, need at least {MIN_SAMPLES}", path=where)
    bad = np.argwhere(~np.isfinite(data))
    if bad.size:
        r, c = bad[0]
        raise DatasetError(
            f"non-finite value {data[r, c]}", path=where, row=lines[r], column=names[c]
        )
    meta: dict = {"source_file": csv_path.name, "source_format": "csv"}
    cells = _Cells(data, lines, names, where)
    t, step_units, k = _time_axis(cells, table.times, columns, meta)
    pos = data[:, k : k + 3] * columns.length_scale
    k += 3
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    if columns.has_quat:
        quat = _orientation(cells, k, columns, meta)
        k += 4
    wrench = data[:, k : k + 6] * columns.wrench_sign if columns.has_wrench else None
    if wrench is not None:
        meta["wrench_sign"] = columns.wrench_sign
    return RawLog(
        path=where,
        t=t,
        pos=pos,
        quat=quat,
        wrench=wrench,
        frame=columns.frame,
        rows=np.array(lines),
        marker=table.marker,
        notes=(table.note,) if table.note else (),
        meta=meta,
        fix_in=columns.source,
        quat_order=columns.quat_order,
        time_step_units=step_units,
    )


@dataclass(frozen=True)
class _Cells:
    """The log's numbers (rows, mapped columns), each row's line (1-based) and each column's
    CSV name, and the file for error messages."""

    data: np.ndarray
    lines: list[int]
    names: list[str]
    where: str


def _time_axis(
    cells: _Cells, times: list[str] | None, columns: ColumnMap, meta: dict
) -> tuple[np.ndarray, float | None, int]:
    """Times (s from 0), the median time step in the log's units (None without a time
    column) and the index of the first column after the time; notes the time offset (or the
    given rate) in ``meta``."""
    data = cells.data
    if columns.time is None:
        t = np.arange(data.shape[0]) / float(columns.rate_hz)  # type: ignore[arg-type]
        meta["rate_hz_given"] = float(columns.rate_hz)  # type: ignore[arg-type]
        return t, None, 0
    times = times or []
    raw_t = _offsets(times, data[:, 0])
    steps = np.flatnonzero(np.diff(raw_t) <= 0)
    if steps.size:
        r = int(steps[0]) + 1
        raise DatasetError(
            f"time not strictly increasing ({times[r - 1].strip()} then {times[r].strip()})",
            path=cells.where,
            row=cells.lines[r],
            column=cells.names[0],
        )
    t = raw_t * columns.time_scale
    step_units = float(np.median(np.diff(raw_t)))
    meta["time_offset_s"] = float(data[0, 0] * columns.time_scale)
    return t, step_units, 1


def _orientation(cells: _Cells, k: int, columns: ColumnMap, meta: dict) -> np.ndarray:
    """The quaternions in columns ``k .. k + 3`` as w-x-y-z, each of norm 1 within
    ``QUAT_NORM_TOL``; notes their order in ``meta``."""
    names = cells.names
    norms = np.linalg.norm(cells.data[:, k : k + 4], axis=1)
    off = np.flatnonzero(np.abs(norms - 1.0) > QUAT_NORM_TOL)
    if off.size:
        r = int(off[0])
        raise DatasetError(
            f"quaternion ({', '.join(names[k : k + 4])}) has norm {norms[r]:.6g}, not 1 "
            f"(tolerance {QUAT_NORM_TOL})",
            path=cells.where,
            row=cells.lines[r],
            column=names[k],
        )
    quat = to_wxyz(cells.data[:, k : k + 4], columns.quat_order)
    meta["quat_order"] = columns.quat_order
    return quat


def import_csv(
    csv_path: str | Path,
    columns: ColumnMap,
    *,
    task: str,
    name: str | None = None,
    options: ImportOptions | None = None,
) -> Demonstration:
    """Read one checked demonstration (``source="imported"``) from a CSV robot log.

    Parameters
    ----------
    csv_path : str or Path
        The log: one header line, then one sample per line.
    columns : ColumnMap
        Which columns to read, their units and conventions; its ``transform`` is applied unless
        ``options`` gives another.
    task : str
        Task name stored in the demonstration.
    name : str, optional
        Demonstration name; the file stem by default.
    options : ImportOptions, optional
        Plausibility limits and accepted checks (no segmentation here: see
        :func:`teachfit.demonstrations.importing.build_demos`).

    Returns
    -------
    Demonstration
        ``t`` (T,) s from 0, ``pos`` (T, 3) m, ``quat`` (T, 4) w-x-y-z and ``wrench`` (T, 6)
        N, N*m (environment on tool) or None, in ``columns.frame`` or the transform's frame.

    Raises
    ------
    DatasetError
        For unreadable input (see :func:`read_csv_log`) or a failed plausibility check.
    """
    log = read_csv_log(csv_path, columns)
    options = options or ImportOptions()
    if options.transform is None:
        options = replace(options, transform=columns.transform)
    result = build_demos(log, task=task, name=name or Path(csv_path).stem, options=options)
    return result.demos[0]
