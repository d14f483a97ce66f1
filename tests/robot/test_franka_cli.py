"""``teachfit robot check`` and ``bench robot`` through the real protocol (franky-sim)."""

from __future__ import annotations

from pathlib import Path

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


def test_bench_robot_reports_tick_percentiles(franka_sim: object, tmp_path: Path) -> None:
    md = tmp_path / "loop.md"
    arm = ["--host", "127.0.0.1", "--no-realtime", "--seconds", "0.5"]
    res = CliRunner().invoke(
        app, ["bench", "robot", *arm, "--controller", "adaptive", "--markdown", str(md)]
    )
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "ticks: 500" in text and "p50" in text and "p99" in text and "missed deadlines" in text
    assert "through the robot's protocol, adaptive law" in md.read_text()


def test_assemble_runs_its_trials_on_the_arm_one_at_a_time(franka_sim: object) -> None:
    arm = ["--robot", "franka", "--host", "127.0.0.1", "--no-realtime"]
    res = CliRunner().invoke(
        app, ["assemble", "--task", "peg2d", "--trials", "2", *arm, "--workers", "2"]
    )
    assert res.exit_code == 2 and "one at a time" in res.output
    res = CliRunner().invoke(
        app, ["assemble", "--task", "peg2d", "--trials", "1", "--hole-error", "0mm", *arm]
    )
    assert res.exit_code in (0, 1), res.output  # 1: the arm stopped the trial (printed)
    assert "peg2d: peg-in-hole alone (no --search)" in res.output
    assert "1/1" in res.output or "0/1" in res.output
