"""``teachfit robot check`` and ``bench robot`` through the real protocol (franky-sim)."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")

from teachfit.cli import app  # noqa: E402


def test_robot_check_prints_state_limits_and_timing(franka_sim: object) -> None:
    res = CliRunner().invoke(
        app, ["robot", "check", "--host", "127.0.0.1", "--no-realtime", "--seconds", "0.3"]
    )
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "robot at 127.0.0.1: mode" in text
    assert "max commanded wrench: 60 N" in text and "torque rate limit: 1000" in text
    assert "ticks: 300 (0.3 s at 1000 Hz)" in text


def test_bench_robot_reports_tick_percentiles(franka_sim: object) -> None:
    res = CliRunner().invoke(
        app, ["bench", "robot", "--host", "127.0.0.1", "--no-realtime", "--seconds", "0.5"]
    )
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "ticks: 500" in text and "p50" in text and "p99" in text and "missed deadlines" in text
