"""Export a demonstration as a CSV log (and the column map that reads it back).

Columns ``time,x,y,z,qw,qx,qy,qz`` and, with a wrench, ``fx,fy,fz,tx,ty,tz``: s, m, w-x-y-z,
N and N*m (the wrench the environment exerts on the tool), in the demonstration's frame.
Numbers are written as Python's shortest round-trip ``repr``, so reading the file back with the
map gives the same float64 values. Both files are written atomically (temporary file, then rename).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from teachfit.core.atomic import atomic_write_text
from teachfit.core.errors import DatasetError
from teachfit.demonstrations.dataset import Demonstration

POSE_COLUMNS = ("time", "x", "y", "z", "qw", "qx", "qy", "qz")
WRENCH_COLUMNS = ("fx", "fy", "fz", "tx", "ty", "tz")


def _write_atomic(path: Path, text: str) -> None:
    atomic_write_text(path, text, "CSV file" if path.suffix == ".csv" else "file")


def columns_toml(demo: Demonstration) -> str:
    """A column map (TOML) that reads the CSV written by :func:`export_csv` for ``demo``."""
    cols = POSE_COLUMNS + (WRENCH_COLUMNS if demo.wrench is not None else ())
    lines = [
        f"# column map for an exported teachfit demonstration ({demo.name or 'unnamed'})",
        "time_scale = 1.0",
        "length_scale = 1.0",
        f'frame = "{demo.frame}"',
        "wrench_sign = 1",
        "",
        "[columns]",
        *(f'{c} = "{c}"' for c in cols),
    ]
    return "\n".join(lines) + "\n"


def export_csv(
    demo: Demonstration, path: str | Path, *, columns: str | Path | None = None, overwrite=False
) -> Path:
    """Write ``demo`` as CSV to ``path`` (and its column map to ``columns``); returns ``path``.

    Raises
    ------
    DatasetError
        If a file exists and ``overwrite`` is False, or it cannot be written.
    """
    path = Path(path)
    targets = [path] + ([Path(columns)] if columns is not None else [])
    for target in targets:
        if target.exists() and not overwrite:
            raise DatasetError("file exists (pass --overwrite to replace it)", path=str(target))
    parts = [demo.t[:, None], demo.pos, demo.quat]
    header = list(POSE_COLUMNS)
    if demo.wrench is not None:
        parts.append(demo.wrench)
        header += WRENCH_COLUMNS
    rows = [",".join(map(repr, row)) for row in np.hstack(parts).tolist()]
    _write_atomic(path, "\n".join([",".join(header), *rows]) + "\n")
    if columns is not None:
        _write_atomic(Path(columns), columns_toml(demo))
    return path
