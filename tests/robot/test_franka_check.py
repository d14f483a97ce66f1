"""``check_robot`` and the loop benchmark through the protocol (figures, not wall-clock tests)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")

from teachfit.robot.franka.check import bench_loop, check_robot  # noqa: E402
from teachfit.robot.franka.priority import probe  # noqa: E402
from teachfit.robot.franka.safety import FrankaLimits  # noqa: E402


def test_check_robot_reads_state_limits_and_timing(franka_sim: object) -> None:
    import pylibfranka as pf

    raw = pf.Robot("127.0.0.1", pf.RealtimeConfig.kIgnore)
    q = np.asarray(raw.read_once().q)
    del raw
    check = check_robot("127.0.0.1", FrankaLimits(max_force=40.0), seconds=0.3, realtime=False)
    assert check.robot_mode in {"Idle", "kIdle", "Move", "kMove"}
    np.testing.assert_allclose(check.q, q, atol=0.01)  # it holds where it was
    assert dict(check.limits)["max commanded wrench"] == "40 N, 6 N·m"
    assert check.timing.ticks == 300
    assert 0 < check.timing.compute_p50 <= check.timing.compute_p99 <= check.timing.compute_max
    text = "\n".join(check.lines())
    assert "workspace box" in text and "tick compute time" in text


def test_bench_loop_prints_figures(franka_sim: object) -> None:
    lines: list[str] = []
    timing = bench_loop("127.0.0.1", seconds=0.5, realtime=False, out=lines.append)
    assert timing.ticks == 500
    assert timing.overruns <= timing.ticks and timing.missed_packets >= 0
    assert len(lines) == 5 and lines[0].startswith("ticks: 500")
    assert timing.wall_rate > 0 and lines[3].startswith("wall-clock rate")
    assert lines[4] == f"control thread: {probe().describe()}"  # SCHED_FIFO where allowed
