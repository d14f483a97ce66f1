"""Import demonstrations from a robot's CSV log.

Which column holds which quantity is described by a
:class:`~teachfit.demonstrations.column_map.ColumnMap` (a TOML file; ``examples/columns.toml``
documents every key). The CSV file must have one header line; other columns are ignored.

Times are shifted so that the log starts at t = 0; the original first time stamp (s) is kept in
``meta["time_offset_s"]``. A log without a time column needs ``rate_hz``.

A last line cut short while the log was being written (no newline at the end of the file and
fewer cells than the header, or a last number with fewer digits than that column has in every
other row) is dropped, with a note saying so.

Errors name the file, the line (1-based, the header is line 1) and the CSV column.
"""

from __future__ import annotations

import csv
import io
from collections import Counter
from dataclasses import replace
from decimal import Decimal, InvalidOperation
from functools import partial
from pathlib import Path

import numpy as np

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.column_map import ColumnMap
from teachfit.demonstrations.dataset import MIN_SAMPLES, QUAT_NORM_TOL, Demonstration
from teachfit.demonstrations.frames import to_wxyz
from teachfit.demonstrations.importing import ImportOptions, build_demos
from teachfit.demonstrations.rawlog import RawLog

__all__ = ["ColumnMap", "import_csv", "read_csv_log"]


def _decimals(cell: str) -> int | None:
    """Digits after the decimal point of a plain number, or None if ``cell`` is not one."""
    text = cell.strip()
    if not _is_float(text) or "e" in text.lower():
        return None
    return len(text.partition(".")[2])


def _is_float(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _truncated(rows: list[list[str]], header: list[str]) -> str | None:
    """Why the last row looks cut short, or None (only called without a final newline)."""
    last = rows[-1]
    if len(last) < len(header):
        return f"it has {len(last)} of {len(header)} cells"
    col = len(last) - 1
    digits = [_decimals(r[col]) for r in rows[:-1] if len(r) > col]
    counts = Counter(d for d in digits if d is not None)
    if not counts or len(digits) < 2:
        return None
    typical, count = counts.most_common(1)[0]
    here = _decimals(last[col])
    if count == len(digits) and (here is None or here < typical):
        return (
            f"its last number {last[col].strip()!r} has fewer decimals than the {typical} of "
            f"every other row in column {header[col]!r}"
        )
    return None


def _read_rows(csv_path: Path, delimiter: str) -> tuple[list[str], list[list[str]], list[int], str]:
    """Header, non-blank data rows, their line numbers, and a note if the last row was cut."""
    fail = partial(DatasetError, path=str(csv_path))
    try:
        text = csv_path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise fail(f"cannot read ({exc.strerror})") from exc
    except UnicodeDecodeError as exc:
        raise fail(f"not a UTF-8 text file ({exc.reason} at byte {exc.start})") from exc
    reader = csv.reader(io.StringIO(text, newline=""), delimiter=delimiter)
    header = [h.strip() for h in next((row for row in reader if row), [])]
    if not header:
        raise fail("empty file, expected a header line", row=1)
    rows: list[list[str]] = []
    lines: list[int] = []
    for row in reader:
        if row and not (len(row) == 1 and not row[0].strip()):
            rows.append(row)
            lines.append(reader.line_num)
    note = ""
    if rows and not text.endswith(("\n", "\r")):
        why = _truncated(rows, header)
        if why is not None:
            note = (
                f"file {csv_path}, row {lines[-1]}: the last line is cut short (no newline at "
                f"the end of the file and {why}); dropped it"
            )
            rows, lines = rows[:-1], lines[:-1]
    return header, rows, lines, note


def _parse(csv_path: Path, columns: ColumnMap) -> tuple[np.ndarray, list[int], list[str], dict]:
    """Values (N, K) of the mapped numeric columns, their line numbers, the CSV column names
    (K,) and extras: raw time cells, marker cells, note."""
    names = list(columns.mapped().values())
    fail = partial(DatasetError, path=str(csv_path))
    header, rows, lines, note = _read_rows(csv_path, columns.delimiter)
    wanted = names + ([columns.marker] if columns.marker else [])
    for name in wanted:
        if header.count(name) != 1:
            problem = "appears more than once in" if name in header else "is not in"
            raise fail(f"column {problem} the header {header}", row=1, column=name)
    index = [header.index(name) for name in names]
    values: list[list[float]] = []
    for row, line in zip(rows, lines, strict=True):
        try:
            values.append([float(row[i]) for i in index])
        except (ValueError, IndexError):
            for i, name in zip(index, names, strict=True):
                cell = row[i] if i < len(row) else None
                if cell is None or not _is_float(cell):
                    problem = (
                        f"line has only {len(row)} cells"
                        if cell is None
                        else f"not a number: {cell!r}"
                    )
                    raise fail(problem, row=line, column=name) from None
            raise
    extras: dict = {"note": note, "times": None, "marker": None}
    if columns.time is not None:
        extras["times"] = [row[index[0]] for row in rows]
    if columns.marker is not None:
        m = header.index(columns.marker)
        short = next((ln for r, ln in zip(rows, lines, strict=True) if len(r) <= m), None)
        if short is not None:
            raise fail("line has no marker cell", row=short, column=columns.marker)
        extras["marker"] = tuple(r[m].strip() for r in rows)
    data = np.array(values, dtype=np.float64).reshape(len(values), len(index))
    return data, lines, names, extras


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
    data, lines, names, extras = _parse(csv_path, columns)
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
    k = 0
    step_units = None
    if columns.time is not None:
        times = extras["times"]
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
        step_units = float(np.median(np.diff(raw_t)))
        meta["time_offset_s"] = float(data[0, 0] * columns.time_scale)
        k = 1
    else:
        t = np.arange(n) / float(columns.rate_hz)  # type: ignore[arg-type]
        meta["rate_hz_given"] = float(columns.rate_hz)  # type: ignore[arg-type]
    pos = data[:, k : k + 3] * columns.length_scale
    k += 3
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    if columns.has_quat:
        norms = np.linalg.norm(data[:, k : k + 4], axis=1)
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
        quat = to_wxyz(data[:, k : k + 4], columns.quat_order)
        meta["quat_order"] = columns.quat_order
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
        marker=extras["marker"],
        notes=(extras["note"],) if extras["note"] else (),
        meta=meta,
        fix_in=columns.source,
        quat_order=columns.quat_order,
        time_step_units=step_units,
    )


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
