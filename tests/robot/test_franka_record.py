"""Kinesthetic recording on the Franka driver (franky-sim pushed through its hand) and on the
simulated floating tool."""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from teachfit.core.geometry import Pose
from teachfit.robot.floating import FloatingToolRobot
from teachfit.robot.franka.record import record_kinesthetic
from teachfit.tasks import get_task

HOME = Pose(np.array([0.0, 0.0, 0.15]))


def _at_robot_time(robot: object, t: float, action: object) -> threading.Thread:
    """Run ``action()`` once the recording's own reset is done and ``t`` s of robot time (its
    control ticks) have passed since: scheduled in robot time, not wall-clock time."""
    before = robot.resets  # type: ignore[attr-defined]

    def wait() -> None:
        while robot.resets == before or robot.time < t:  # type: ignore[attr-defined]
            time.sleep(0.002)
        action()  # type: ignore[operator]

    thread = threading.Thread(target=wait, daemon=True)
    thread.start()
    return thread


def test_floating_tool_records_at_the_rate_and_stays_put() -> None:
    robot = FloatingToolRobot(get_task("peg"))
    robot.reset(HOME)
    rec = record_kinesthetic(robot, duration=0.2, rate_hz=50.0)
    assert len(rec) == 11  # the start sample + 10 at 20 ms
    np.testing.assert_allclose(np.diff(rec.t), 0.02, atol=1e-9)
    assert rec.pos.shape == (11, 3) and rec.quat.shape == (11, 4) and rec.wrench.shape == (11, 6)
    assert np.abs(rec.pos - HOME.pos).max() < 1e-3  # nobody pushed: zero stiffness, no drift
    assert not rec.interrupted and rec.fault == ""


@pytest.fixture
def franka(franka_sim: object) -> object:
    pytest.importorskip("pylibfranka")
    from teachfit.robot.franka import FrankaFrames, FrankaLimits, ee2tcp_for_part
    from teachfit.robot.franka.driver import FrankaParams, FrankaRobot

    # the reset only places the arm: at 3x the default reset speed (franky-sim runs in real time)
    params = FrankaParams(
        limits=FrankaLimits(reset_speed=0.15), frames=FrankaFrames(ee2tcp=ee2tcp_for_part(0.05))
    )
    robot = FrankaRobot("127.0.0.1", params=params, realtime=False)
    robot.reset(HOME)
    yield robot
    robot.close()


def test_pushed_arm_is_recorded_with_the_pushing_wrench(franka: object, push_file: Path) -> None:
    """The test pushes the simulated hand +x with 6 N (franky-sim's MuJoCo, via our launcher)."""
    push_file.unlink(missing_ok=True)
    on = _at_robot_time(franka, 0.3, lambda: push_file.write_text("6.0 0.0 0.0"))
    off = _at_robot_time(franka, 0.7, push_file.unlink)
    try:
        # the push ends at 0.7 s and the arm is at rest again by 0.8 s (54 mm further along x)
        rec = record_kinesthetic(franka, duration=1.2, rate_hz=100.0)  # type: ignore[arg-type]
    finally:
        on.join(), off.join()
        push_file.unlink(missing_ok=True)
    pushed = rec.wrench[:, 0] > 3.0
    assert 10 < pushed.sum() < len(rec) - 10  # pushed for a while, not throughout
    # environment on the tool: +6 N along world x (libfranka reports the opposite sign)
    np.testing.assert_allclose(rec.wrench[pushed, :3].mean(axis=0), [6.0, 0.0, 0.0], atol=0.2)
    assert np.abs(rec.wrench[: np.argmax(pushed)]).max() < 0.2  # nothing before the push
    first = int(np.argmax(pushed))
    assert rec.pos[-1, 0] - rec.pos[first, 0] > 0.01  # the compliant arm gave way along +x
    assert abs(rec.pos[-1, 1] - rec.pos[0, 1]) < 0.01
    assert not rec.interrupted
    assert rec.t[-1] >= 1.19
    np.testing.assert_allclose(np.diff(rec.t[1:]), 0.01, atol=1e-6)  # 100 Hz, none lost


def test_ctrl_c_ends_the_recording_and_keeps_every_sample(franka: object, ctrl_c: None) -> None:
    timer = _at_robot_time(franka, 0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    rec = record_kinesthetic(franka, duration=None, rate_hz=200.0)  # type: ignore[arg-type]
    timer.join()
    assert rec.interrupted
    assert len(rec) >= 10
    # sampled in the control thread: every 5 ticks exactly, however late the test thread ran
    np.testing.assert_allclose(np.diff(rec.t[1:]), 0.005, atol=1e-6)
    assert rec.t[-1] >= 0.45  # it ran until the interrupt (0.5 s after the reset)
