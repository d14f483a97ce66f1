"""Segmenting: contact phases with hysteresis and a minimum duration, windows, marker runs."""

from __future__ import annotations

import numpy as np
import pytest

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.rawlog import RawLog
from teachfit.demonstrations.segment import Segmenter, contact_phases


def log_with(fz: np.ndarray | None = None, marker: tuple[str, ...] | None = None, n: int = 0):
    n = n or (fz.size if fz is not None else len(marker or ()))
    wrench = None if fz is None else np.column_stack([np.zeros((n, 2)), fz, np.zeros((n, 3))])
    return RawLog(
        path="log.csv",
        t=np.arange(n) / 10.0,
        pos=np.zeros((n, 3)),
        quat=np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)),
        wrench=wrench,
        frame="base",
        rows=np.arange(n) + 2,
        marker=marker,
    )


def test_hysteresis_keeps_a_phase_whole_through_dips() -> None:
    force = np.array([0, 6, 4, 3, 6, 2, 0, 0, 7, 7, 1, 9], dtype=float)
    # 4 and 3 N dip below the 5 N start but not below the 2.5 N end: one phase, 1..5
    assert contact_phases(force, 5.0, 2.5) == [(1, 5), (8, 10), (11, 12)]
    assert contact_phases(force, 5.0, 5.0) == [(1, 2), (4, 5), (8, 10), (11, 12)]


def test_contact_pieces_shorter_than_the_minimum_are_dropped() -> None:
    fz = np.zeros(100)
    fz[10:40] = 8.0  # 2.9 s
    fz[60:65] = 8.0  # 0.4 s: a brief touch
    pieces = Segmenter("contact", force_on_n=5.0, min_duration_s=1.0).split(log_with(fz))
    assert pieces == [(10, 40)]
    assert len(Segmenter("contact", min_duration_s=0.2).split(log_with(fz))) == 2


def test_windows_and_markers() -> None:
    log = log_with(np.zeros(95))  # 9.4 s at 10 Hz
    assert Segmenter("window", window_s=3.0, min_duration_s=0.0).split(log) == [
        (0, 30),
        (30, 60),
        (60, 90),
        (90, 95),
    ]
    assert Segmenter("window", window_s=3.0, min_duration_s=1.0).split(log)[-1] == (60, 90)
    marker = ("a",) * 20 + ("",) * 5 + ("b",) * 20 + ("a",) * 20
    log = log_with(marker=marker)
    assert Segmenter("marker").split(log) == [(0, 20), (25, 45), (45, 65)]
    assert Segmenter("marker", marker_value="a").split(log) == [(0, 20), (45, 65)]


def test_bad_settings_and_missing_data() -> None:
    with pytest.raises(DatasetError, match="segment by one of"):
        Segmenter("time")
    with pytest.raises(DatasetError, match="must not exceed the start force") as info:
        Segmenter("contact", force_on_n=2.0, force_off_n=3.0)
    assert info.value.column == "force_off_n"
    with pytest.raises(DatasetError, match="needs a wrench") as info:
        Segmenter("contact").split(log_with(marker=("a",) * 10))
    assert info.value.path == "log.csv"
    with pytest.raises(DatasetError, match="needs a marker column"):
        Segmenter("marker").split(log_with(np.zeros(10)))
