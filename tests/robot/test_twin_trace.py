"""The twin's contact trace: the simulator's own contact force, written per contact tick."""

from __future__ import annotations

import csv

import numpy as np
import pytest

pytest.importorskip("franky_sim", reason="needs the franka extra (franky-sim)")

from teachfit.robot.franka.twin_cell import TwinParams, TwinSimulator  # noqa: E402
from teachfit.robot.franka.twin_trace import COLUMNS, ContactTrace  # noqa: E402
from teachfit.tasks import get_task  # noqa: E402

TASK = get_task("peg")


def _traced(tmp_path, start, ticks=5):
    sim = TwinSimulator(TASK, TwinParams(start=start))
    sim._start()
    with ContactTrace(tmp_path / "trace.csv") as trace:
        sim.trace = trace
        for _ in range(ticks):
            sim._step()
    with (tmp_path / "trace.csv").open(newline="") as f:
        rows = list(csv.reader(f))
    assert tuple(rows[0]) == COLUMNS
    return [dict(zip(COLUMNS, map(float, r), strict=True)) for r in rows[1:]]


def test_a_part_pressed_on_the_boss_is_traced_every_tick_pushing_down(tmp_path):
    # the tip 15 mm off the hole's axis, 0.5 mm into the boss top: touching from the first tick
    rows = _traced(tmp_path, (0.015, 0.0, -0.0005))
    assert len(rows) == 5
    assert all(r["fz"] < -1.0 and r["contacts"] >= 1 for r in rows)  # libfranka's sign: down < 0
    assert all(abs(r["deepest"] - TASK.surface_z) < 1e-3 for r in rows)
    tip = np.array([[r["x"], r["y"], r["z"]] for r in rows])
    np.testing.assert_allclose(tip[0], [0.015, 0.0, TASK.surface_z - 0.0005], atol=2e-4)


def test_a_part_in_the_air_leaves_only_the_header(tmp_path):
    assert _traced(tmp_path, (0.0, 0.0, 0.05)) == []
