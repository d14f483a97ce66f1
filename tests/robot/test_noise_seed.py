"""A simulated robot's sensor noise restarted per trial: a trial's readings are its own."""

import numpy as np
import pytest

from teachfit.robot.interface import NoiseSeeded
from teachfit.robot.registry import make_robot
from teachfit.tasks import get_task


@pytest.mark.parametrize("name", ["floating", "fr3"])
def test_a_reseeded_robot_reads_the_same_noise_whatever_ran_before(name):
    task = get_task("peg2d")
    robot = make_robot(name, task)
    assert isinstance(robot, NoiseSeeded)
    start = task.contact_pose([0.02, 0.0]).translated([0.0, 0.0, 0.01])

    def readings(seed: int, history: int) -> np.ndarray:
        robot.reset(start)
        robot.step(history)  # whatever ran before draws noise of its own
        robot.seed_noise(seed)
        robot.reset(start)
        return np.array([robot.step(1).wrench for _ in range(40)])

    first = readings(3, 7)
    np.testing.assert_array_equal(first, readings(3, 1234))
    other = readings(4, 7)
    assert not np.array_equal(first, other)
    assert np.abs(first - other).max() < 0.5  # noise, not a different motion
    robot.close()
