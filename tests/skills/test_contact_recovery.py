"""Retract along a planned path and try its end again, shifted across the insertion."""

import numpy as np
import pytest

from teachfit.core.errors import SkillError
from teachfit.core.geometry import Pose
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.contact_recovery import (
    RING,
    RetryPath,
    SpiralPush,
    retry_poses,
    time_poses,
)
from teachfit.skills.percept import MPCommand, Percept


def _path() -> SetpointTrajectory:
    """Down 30 mm along -z, level (task frame)."""
    z = np.linspace(0.03, 0.0, 31)
    pos = np.column_stack([np.zeros(31), np.zeros(31), z])
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (31, 1))
    return SetpointTrajectory.from_path(time_poses(pos, quat, 0.01, 0.5), pos, quat)


def test_time_poses_takes_the_slower_of_speed_and_turn():
    pos = np.array([[0.0, 0, 0], [0.01, 0, 0], [0.01, 0, 0]])
    half = np.array([np.cos(0.25), 0.0, 0.0, np.sin(0.25)])  # 0.5 rad about z
    quat = np.array([[1.0, 0, 0, 0], [1.0, 0, 0, 0], half])
    assert time_poses(pos, quat, 0.01, 0.5) == pytest.approx([0.0, 1.0, 2.0])


def test_a_retry_backs_out_along_the_path_and_ends_shifted_at_its_end():
    path = _path()
    here = np.array([0.0, 0.0, 0.01])  # stuck 10 mm short of the end
    setpoint = (np.array([0.0, 0.0, -0.005]), np.array([1.0, 0.0, 0.0, 0.0]))
    offset = np.array([0.002, 0.0])
    pos, quat = retry_poses(path, here, setpoint, 0.015, offset)
    assert pos[0] == pytest.approx(setpoint[0])
    assert pos[:, 2].max() == pytest.approx(0.025)  # backed out 15 mm from where it stuck
    assert pos[-1] == pytest.approx([0.002, 0.0, 0.0])  # the end, shifted across
    assert np.allclose(np.linalg.norm(quat, axis=1), 1.0)
    # the ring tries the centre first, then opposite directions in turn
    assert RING[0] == (0.0, 0.0) and np.allclose(np.add(RING[1], RING[2]), 0.0)
    assert len(set(RING)) == 9


def test_retry_path_checks_its_values():
    with pytest.raises(SkillError, match="retry_path"):
        RetryPath(_path()).compile({"retry_back": -1.0, "retry_radius": 0.0, "retry_speed": 0.01})
    assert RetryPath(_path()).refs() == {"retry_back", "retry_radius", "retry_speed"}


def test_spiral_push_spirals_out_presses_and_ends_when_the_part_advanced():
    values = {"spiral_pitch": 0.001, "spiral_speed": 0.01, "spiral_radius": 0.003}
    values |= {"spiral_push": 8.0, "spiral_advance": 0.002}
    run = SpiralPush().compile(values)
    pc, out = Percept(Pose(np.zeros(3)), 0.001), MPCommand()
    run.enter(pc)
    radii = []
    for k in range(3500):  # 3.5 s: 35 mm of spiral, out to 3 mm (28 mm) and again
        pc.t_node = k * pc.dt
        run.command(pc, out)
        pc.p_d[:2] += out.twist[:2] * pc.dt
        radii.append(float(np.hypot(*pc.p_d[:2])))
        assert out.wrench[2] == -8.0 and not pc.done
    assert max(radii) == pytest.approx(0.003, abs=2e-4) and min(radii[2000:]) < 5e-4
    pc.p[2] = -0.0025  # the hole caught it
    run.command(pc, out)
    assert pc.done
    with pytest.raises(SkillError, match="spiral_push"):
        SpiralPush().compile(values | {"spiral_pitch": 0.0})
