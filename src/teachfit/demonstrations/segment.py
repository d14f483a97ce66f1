"""Cut a long log into demonstrations: by time window, by contact phase or by a marker column.

Each method returns index ranges ``(start, stop)`` (``stop`` exclusive) into the log's samples,
in time order and not overlapping.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.rawlog import RawLog

MODES: tuple[str, ...] = ("window", "contact", "marker")


@dataclass(frozen=True)
class Segmenter:
    """How to cut a log into demonstrations.

    Parameters
    ----------
    mode : str
        ``"window"`` (consecutive windows of ``window_s``), ``"contact"`` (phases where the
        contact force magnitude exceeds ``force_on_n``, ending when it drops below
        ``force_off_n``: hysteresis) or ``"marker"`` (runs of one value of the marker column).
    window_s : float
        Window length (s).
    force_on_n, force_off_n : float
        Force magnitudes (N) that start and end a contact phase; ``force_off_n`` defaults to
        half of ``force_on_n`` and must not exceed it.
    min_duration_s : float
        Pieces shorter than this (s) are dropped (a last partial window, a brief touch).
    marker_value : str or None
        Keep only the runs with this marker value; None keeps every run with a non-empty value.
    """

    mode: str
    window_s: float = 30.0
    force_on_n: float = 5.0
    force_off_n: float | None = None
    min_duration_s: float = 1.0
    marker_value: str | None = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise DatasetError(f"segment by one of {MODES}, got {self.mode!r}", column="segment")
        off = self.force_on_n / 2.0 if self.force_off_n is None else self.force_off_n
        for label, value in (
            ("window_s", self.window_s),
            ("force_on_n", self.force_on_n),
            ("force_off_n", off),
        ):
            if not (math.isfinite(value) and value > 0):
                raise DatasetError(f"must be positive, got {value!r}", column=label)
        if off > self.force_on_n:
            raise DatasetError(
                f"the end force must not exceed the start force ({self.force_on_n} N), got {off} N",
                column="force_off_n",
            )
        if not (math.isfinite(self.min_duration_s) and self.min_duration_s >= 0):
            raise DatasetError(
                f"must be >= 0, got {self.min_duration_s!r}", column="min_duration_s"
            )
        object.__setattr__(self, "force_off_n", float(off))

    def split(self, log: RawLog) -> list[tuple[int, int]]:
        """Index ranges of the pieces of ``log`` (may be empty).

        Raises
        ------
        DatasetError
            Naming the log for contact segmentation without a wrench or marker segmentation
            without a marker column.
        """
        if self.mode == "window":
            pieces = _windows(log.t, self.window_s)
        elif self.mode == "contact":
            if log.wrench is None:
                raise DatasetError(
                    "--segment contact needs a wrench (map fx..tz or give --wrench-topic)",
                    path=log.path,
                )
            force = np.linalg.norm(log.wrench[:, :3], axis=1)
            assert self.force_off_n is not None  # set by __post_init__
            pieces = contact_phases(force, self.force_on_n, float(self.force_off_n))
        else:
            if log.marker is None:
                raise DatasetError(
                    "--segment marker needs a marker column ([columns] marker = ...)",
                    path=log.path,
                )
            pieces = _runs(log.marker, self.marker_value)
        return [(a, b) for a, b in pieces if log.t[b - 1] - log.t[a] >= self.min_duration_s]


def contact_phases(force: np.ndarray, on: float, off: float) -> list[tuple[int, int]]:
    """Ranges where ``force`` (T,) N rises above ``on`` until it falls below ``off``."""
    pieces = []
    start = None
    for i, f in enumerate(force):
        if start is None and f > on:
            start = i
        elif start is not None and f < off:
            pieces.append((start, i))
            start = None
    if start is not None:
        pieces.append((start, len(force)))
    return pieces


def _windows(t: np.ndarray, window_s: float) -> list[tuple[int, int]]:
    edges = np.searchsorted(t, t[0] + window_s * np.arange(1, int((t[-1] - t[0]) / window_s) + 2))
    starts = np.concatenate([[0], edges[:-1]])
    return [(int(a), int(b)) for a, b in zip(starts, edges, strict=True) if b - a >= 2]


def _runs(marker: tuple[str, ...], value: str | None) -> list[tuple[int, int]]:
    pieces = []
    start = 0
    for i in range(1, len(marker) + 1):
        if i == len(marker) or marker[i] != marker[start]:
            label = marker[start]
            if (label == value if value is not None else label != "") and i - start >= 2:
                pieces.append((start, i))
            start = i
    return pieces
