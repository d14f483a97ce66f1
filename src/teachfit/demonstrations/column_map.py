"""Which CSV column holds which quantity, and the units and conventions of a log.

Loaded from a small TOML file; options at the top level, column names in ``[columns]``.
``examples/columns.toml`` documents every key; in short::

    time_scale = 1.0          # s per unit of the time column (1e-3: ms, 1e-9: ns)
    rate_hz = 20.0            # logs WITHOUT a time column: samples are 1/rate_hz apart
    length_scale = 1.0        # m per unit of the position columns (1e-3: mm)
    delimiter = ","
    frame = "panda_link0"     # frame the poses and wrenches are logged in (default "world")
    wrench_sign = 1           # +1: wrench the environment exerts on the tool; -1: the robot's
    quat_order = "x,y,z,w"    # order of the columns in [columns] quat (default "w,x,y,z")
    transform = "first-pose"  # or a [transform] table: to = "world", pos = [..], quat = [..]

    [columns]
    time = "timestamp"        # or omit it and give rate_hz
    x = "x"                   # x, y, z required
    y = "y"
    z = "z"
    quat = ["qx", "qy", "qz", "qw"]  # four columns in quat_order; or qw, qx, qy, qz keys
    fx = "fx"                 # fx ... tz: optional as a group, N and N*m
    ...
    marker = "phase"          # optional: a label column for --segment marker

Unknown keys are an error; every error names the file and the key.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.frames import QUAT_ORDERS, FrameTransform

POSITION_KEYS = ("x", "y", "z")
QUAT_KEYS = ("qw", "qx", "qy", "qz")
WRENCH_KEYS = ("fx", "fy", "fz", "tx", "ty", "tz")
COLUMN_KEYS = ("time", *POSITION_KEYS, "quat", *QUAT_KEYS, *WRENCH_KEYS, "marker")
OPTION_KEYS = (
    "time_scale",
    "rate_hz",
    "length_scale",
    "delimiter",
    "frame",
    "wrench_sign",
    "quat_order",
    "transform",
)


def bare(err: DatasetError) -> str:
    """The message of ``err`` without its "file ..., row ..., column ...: " prefix."""
    prefix = str(DatasetError("", path=err.path, row=err.row, column=err.column))
    message = str(err)
    return message[len(prefix) :] if message.startswith(prefix) else message


def _positive(value: Any) -> bool:
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    return ok and math.isfinite(value) and value > 0


@dataclass(frozen=True)
class ColumnMap:
    """Where each quantity is in a CSV log, and the units and conventions of that log.

    Parameters
    ----------
    x, y, z : str
        CSV header names of the position columns.
    time : str or None
        Time column; None for a log without one (then ``rate_hz`` is required).
    quat : tuple of str or None
        Four orientation columns in the order ``quat_order``; None: identity orientation.
    fx, fy, fz, tx, ty, tz : str or None
        Force (N) and torque (N*m) columns, expressed in ``frame``: all six or none.
    marker : str or None
        A label column (any text) for segmenting by marker.
    time_scale : float
        Seconds per unit of the time column (positive).
    rate_hz : float or None
        Sampling rate (Hz) of a log without a time column.
    length_scale : float
        Metres per unit of the position columns (positive).
    delimiter : str
        One-character field separator.
    frame : str
        Frame the logged poses and wrenches are expressed in.
    wrench_sign : int
        +1 if the log records the wrench the environment exerts on the tool, -1 if it records the
        wrench the robot applies (negated on import).
    quat_order : str
        ``"w,x,y,z"`` or ``"x,y,z,w"``: the component order of ``quat``.
    transform : FrameTransform or None
        Applied on import (see :mod:`teachfit.demonstrations.frames`).
    source : str or None
        The TOML file this map came from (for messages naming where to fix a setting).

    Raises
    ------
    DatasetError
        Naming the offending key (``column``) for an incomplete group or a bad option.
    """

    x: str
    y: str
    z: str
    time: str | None = None
    quat: tuple[str, ...] | None = None
    fx: str | None = None
    fy: str | None = None
    fz: str | None = None
    tx: str | None = None
    ty: str | None = None
    tz: str | None = None
    marker: str | None = None
    time_scale: float = 1.0
    rate_hz: float | None = None
    length_scale: float = 1.0
    delimiter: str = ","
    frame: str = "world"
    wrench_sign: int = 1
    quat_order: str = "w,x,y,z"
    transform: FrameTransform | None = None
    source: str | None = None

    def __post_init__(self) -> None:
        for key in ("time", *POSITION_KEYS, *WRENCH_KEYS, "marker"):
            value = getattr(self, key)
            if (value is not None or key in POSITION_KEYS) and (
                not isinstance(value, str) or not value
            ):
                raise DatasetError(
                    f"column name must be a non-empty string, got {value!r}", column=key
                )
        if self.quat is not None:
            names = self.quat
            if not isinstance(names, list | tuple) or len(names) != 4:
                raise DatasetError(f"must list 4 column names, got {names!r}", column="quat")
            if not all(isinstance(n, str) and n for n in names):
                raise DatasetError(f"column names must be non-empty, got {names!r}", column="quat")
            object.__setattr__(self, "quat", tuple(names))
        given = [k for k in WRENCH_KEYS if getattr(self, k) is not None]
        if given and len(given) != len(WRENCH_KEYS):
            missing = next(k for k in WRENCH_KEYS if getattr(self, k) is None)
            raise DatasetError(f"give all of {WRENCH_KEYS} or none", column=missing)
        columns = list(self.mapped().values()) + ([self.marker] if self.marker else [])
        dup = next((n for n in columns if columns.count(n) > 1), None)
        if dup is not None:
            raise DatasetError(f"CSV column {dup!r} is mapped to more than one field", column=dup)
        for key in ("time_scale", "length_scale"):
            if not _positive(getattr(self, key)):
                raise DatasetError(
                    f"must be a positive number, got {getattr(self, key)!r}", column=key
                )
        if self.rate_hz is not None and not _positive(self.rate_hz):
            raise DatasetError(f"must be a positive number, got {self.rate_hz!r}", column="rate_hz")
        if (self.time is None) == (self.rate_hz is None):
            raise DatasetError(
                "give either a time column ([columns] time) or, for a log without one, its rate "
                "(rate_hz = ... in the map or --rate on the command line)"
                + (", not both" if self.time is not None else ""),
                column="rate_hz" if self.time is not None else "time",
            )
        if not isinstance(self.delimiter, str) or len(self.delimiter) != 1:
            raise DatasetError(f"must be one character, got {self.delimiter!r}", column="delimiter")
        if self.delimiter.isalnum() or self.delimiter in ".+-\"'\r\n\x00":
            raise DatasetError(
                f"{self.delimiter!r} cannot separate cells (it is part of a number, a quote or a "
                'line end): give the character between the cells, such as ",", ";" or "\\t"',
                column="delimiter",
            )
        if not isinstance(self.frame, str) or not self.frame:
            raise DatasetError(f"must be a non-empty string, got {self.frame!r}", column="frame")
        if self.wrench_sign not in (1, -1) or isinstance(self.wrench_sign, bool):
            raise DatasetError(f"must be +1 or -1, got {self.wrench_sign!r}", column="wrench_sign")
        if self.quat_order not in QUAT_ORDERS:
            raise DatasetError(
                f"must be one of {QUAT_ORDERS}, got {self.quat_order!r}", column="quat_order"
            )

    @property
    def has_quat(self) -> bool:
        """Whether the log has orientation columns."""
        return self.quat is not None

    @property
    def has_wrench(self) -> bool:
        """Whether the log has force/torque columns."""
        return self.fx is not None

    def mapped(self) -> dict[str, str]:
        """Our numeric field -> CSV column name, for the fields that are mapped, in order
        time, x, y, z, q0..q3 (in ``quat_order``), fx..tz."""
        out = {k: getattr(self, k) for k in ("time", *POSITION_KEYS) if getattr(self, k)}
        for i, name in enumerate(self.quat or ()):
            out[f"q{i}"] = name
        out.update({k: getattr(self, k) for k in WRENCH_KEYS if getattr(self, k) is not None})
        return out

    @classmethod
    def from_mapping(
        cls, data: Mapping[str, Any], *, path: str | None = None, rate_hz: float | None = None
    ) -> ColumnMap:
        """Build from the parsed TOML layout (options at top level, a ``columns`` table);
        ``rate_hz`` (the ``--rate`` option) overrides the map's for a log without time."""
        for key in data:
            if key not in (*OPTION_KEYS, "columns"):
                raise DatasetError(
                    f"unknown key {key!r} (known: {', '.join(OPTION_KEYS)}, [columns])",
                    path=path,
                    column=key,
                )
        columns = data.get("columns")
        if not isinstance(columns, Mapping):
            raise DatasetError("missing [columns] table", path=path, column="columns")
        for key in columns:
            if key not in COLUMN_KEYS:
                raise DatasetError(
                    f"unknown key {key!r} in [columns] (known: {', '.join(COLUMN_KEYS)})",
                    path=path,
                    column=key,
                )
        for key in POSITION_KEYS:
            if key not in columns:
                raise DatasetError(f"[columns] needs {key!r}", path=path, column=key)
        cols = {k: v for k, v in columns.items() if k not in QUAT_KEYS}
        named = [k for k in QUAT_KEYS if k in columns]
        if named:
            if len(named) != 4:
                missing = next(k for k in QUAT_KEYS if k not in columns)
                raise DatasetError(f"give all of {QUAT_KEYS} or none", path=path, column=missing)
            if "quat" in columns or "quat_order" in data:
                raise DatasetError(
                    "qw, qx, qy, qz name each component already: use them or "
                    "quat = [four columns] with quat_order, not both",
                    path=path,
                    column="quat",
                )
            cols["quat"] = tuple(columns[k] for k in QUAT_KEYS)
        options = {k: data[k] for k in OPTION_KEYS if k in data}
        if rate_hz is not None:
            if "time" in columns:
                raise DatasetError(
                    f"--rate is for a log without a time column, but the map reads time from "
                    f"{columns['time']!r} (drop --rate, or drop [columns] time)",
                    path=path,
                    column="time",
                )
            options["rate_hz"] = rate_hz
        try:
            if "transform" in options:
                options["transform"] = FrameTransform.parse(options["transform"])
            return cls(**cols, **options, source=path)
        except DatasetError as exc:
            raise DatasetError(bare(exc), path=path, column=exc.column) from exc
        except TypeError as exc:  # a column given a non-string value of the wrong kind
            raise DatasetError(f"bad value ({exc})", path=path) from exc

    @classmethod
    def from_toml(cls, path: str | Path, *, rate_hz: float | None = None) -> ColumnMap:
        """Load from a TOML file (format in the module docstring); ``rate_hz`` as in
        :meth:`from_mapping`."""
        path = Path(path)
        try:
            with path.open("rb") as f:
                data = tomllib.load(f)
        except FileNotFoundError as exc:
            raise DatasetError(
                "no such column map: write one naming the log's columns (examples/columns.toml "
                "documents every key)",
                path=str(path),
            ) from exc
        except OSError as exc:
            raise DatasetError(f"cannot read ({exc.strerror})", path=str(path)) from exc
        except UnicodeDecodeError as exc:
            raise DatasetError(f"not a text (TOML) file ({exc.reason})", path=str(path)) from exc
        except tomllib.TOMLDecodeError as exc:
            raise DatasetError(f"invalid TOML ({exc})", path=str(path)) from exc
        return cls.from_mapping(data, path=str(path), rate_hz=rate_hz)
