"""FrankaLimits and the torque limiting of the Franka driver (no robot needed)."""

from __future__ import annotations

import numpy as np
import pytest

from teachfit.core.errors import ControlError, LimitViolation
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.franka.safety import FrankaLimits


def test_limits_validate() -> None:
    with pytest.raises(ControlError):
        FrankaLimits(max_tcp_speed=0.0)
    with pytest.raises(ControlError):
        FrankaLimits(workspace_lo=(0.0, 0.0, 0.5), workspace_hi=(1.0, 1.0, 0.4))
    with pytest.raises(ControlError):
        FrankaLimits(joint_torque_limits=(1.0,) * 6)  # type: ignore[arg-type]


def test_command_checks_wrench_and_workspace() -> None:
    lim = FrankaLimits(max_force=20.0, max_torque=2.0)
    lim.check_command(ImpedanceCommand(pos=[0, 0, 0.1], wrench_ff=[0, 0, -19.9, 0, 0, 1.9]))
    with pytest.raises(LimitViolation, match="20 N"):
        lim.check_command(ImpedanceCommand(pos=[0, 0, 0.1], wrench_ff=[15, 0, -15, 0, 0, 0]))
    with pytest.raises(LimitViolation):
        lim.check_command(ImpedanceCommand(pos=[0, 0, 0.1], wrench_ff=[0, 0, 0, 0, 2.1, 0]))
    with pytest.raises(LimitViolation, match="workspace"):
        lim.check_command(ImpedanceCommand(pos=[0, 0.31, 0.1]))


def test_motion_check_names_the_broken_limit() -> None:
    lim = FrankaLimits()
    z = np.zeros(3)
    assert lim.check_motion(np.array([0, 0, 0.1]), z, z) == ""
    assert "speed" in lim.check_motion(np.array([0, 0, 0.1]), np.array([0.6, 0, 0]), z)
    assert "angular" in lim.check_motion(np.array([0, 0, 0.1]), z, np.array([0, 0, 2.5]))
    inside_margin = np.array([0.31, 0.0, 0.1])
    assert lim.check_motion(inside_margin, z, z) == ""
    assert "workspace" in lim.check_motion(np.array([0.33, 0.0, 0.1]), z, z)


def test_the_limits_rows_name_the_torque_rate() -> None:
    assert FrankaLimits().rows()[3] == ("torque rate limit", "1000 N·m/s")


def test_approach_waypoints_respect_the_reset_speeds() -> None:
    from teachfit.core.geometry import Pose, quat_from_rz
    from teachfit.robot.franka.frames import approach_waypoints

    start = Pose(np.zeros(3))
    goal = Pose(np.array([0.1, 0.0, 0.0]), quat_from_rz(0.2))
    way = approach_waypoints(start, goal, speed=0.05, ang_speed=0.3, dt=0.01)
    pos = np.array([start.pos] + [w.pos for w in way])
    assert np.max(np.linalg.norm(np.diff(pos, axis=0), axis=1)) <= 0.05 * 0.01 + 1e-12
    np.testing.assert_allclose(way[-1].pos, goal.pos)
    np.testing.assert_allclose(way[-1].quat, goal.quat, atol=1e-12)
    rz = np.array([w.rz for w in way])
    assert np.max(np.abs(np.diff(rz))) <= 0.3 * 0.01 + 1e-12
