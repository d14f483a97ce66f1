"""A robot log as read from a file, before checks, frame transform and segmentation.

Both readers (:mod:`~teachfit.demonstrations.csv_import` and
:mod:`~teachfit.demonstrations.rosbag_import`) produce a :class:`RawLog`;
:mod:`~teachfit.demonstrations.importing` turns it into checked demonstrations.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import numpy as np

#: how closely a stated sampling rate reproduces the median time step (relative)
RATE_TOL = 1e-5


def sampling_rate(t: np.ndarray) -> float:
    """Sampling rate (Hz) of time stamps ``t`` (T,) s: the median step, as the rate with the
    fewest significant digits whose period is within :data:`RATE_TOL` of it (a 20 Hz log whose
    float time stamps step by 0.050000000000011 s is 20.0 Hz, one at 999.97 Hz stays so)."""
    period = float(np.median(np.diff(t)))
    rate = 1.0 / period
    if not np.isfinite(rate) or rate <= 0:
        return rate
    for digits in range(1, 16):
        snapped = float(f"{rate:.{digits}g}")
        if abs(1.0 / snapped - period) <= RATE_TOL * period:
            return snapped
    return rate


@dataclass(frozen=True, eq=False)
class RawLog:
    """Samples of one log file in the log's own frame and units converted to SI.

    Parameters
    ----------
    path : str
        The file (or bag directory) read, for messages.
    t : ndarray
        (T,) s, strictly increasing, ``t[0] = 0``.
    pos : ndarray
        (T, 3) m, tool position in ``frame``.
    quat : ndarray
        (T, 4) unit quaternions, w-x-y-z, tool orientation in ``frame``.
    wrench : ndarray or None
        (T, 6) N and N*m, the wrench the environment exerts on the tool, in ``frame``.
    marker : tuple of str or None
        (T,) values of a marker column (e.g. a phase or trial label), if one was read.
    frame : str
        Frame the poses are expressed in (e.g. ``panda_link0``).
    rows : ndarray
        (T,) int, where each sample is in the file (CSV line, 1-based; or message index).
    notes : tuple of str
        What the reader noticed and fixed (e.g. a dropped truncated last line).
    meta : Mapping
        Source metadata stored with each demonstration (``source_file``, ``time_offset_s``...).
    fix_in : str or None
        The column map a setting is changed in (``key = value``), or None when settings are
        command-line options (``--key value``).
    quat_order : str
        Component order the quaternion columns were read in (for messages).
    time_step_units : float or None
        Median step of the raw time column in its own units, or None without a time column.
    """

    path: str
    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    wrench: np.ndarray | None
    frame: str
    rows: np.ndarray
    marker: tuple[str, ...] | None = None
    notes: tuple[str, ...] = ()
    meta: Mapping[str, Any] = field(default_factory=dict)
    fix_in: str | None = None
    quat_order: str = "w,x,y,z"
    time_step_units: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "meta", MappingProxyType(dict(self.meta)))

    @property
    def n_samples(self) -> int:
        """Number of samples T."""
        return int(self.t.shape[0])

    @property
    def row_word(self) -> str:
        """What :attr:`rows` count, for messages: CSV "rows" or bag "messages"."""
        return "messages" if str(self.meta.get("source_format", "")).startswith("ros") else "rows"

    def hint(self, key: str, value: object) -> str:
        """How the user changes setting ``key`` to ``value`` for this log."""
        if self.fix_in is not None:
            return f"set {key} = {value} in {self.fix_in}"
        option = {"rate_hz": "rate"}.get(key, key).replace("_", "-")
        return f"pass --{option} {value}"

    def sliced(self, start: int, stop: int) -> RawLog:
        """Samples ``start:stop`` (time not re-zeroed)."""
        marker = None if self.marker is None else self.marker[start:stop]
        wrench = None if self.wrench is None else self.wrench[start:stop]
        return replace(
            self,
            t=self.t[start:stop],
            pos=self.pos[start:stop],
            quat=self.quat[start:stop],
            wrench=wrench,
            rows=self.rows[start:stop],
            marker=marker,
        )
