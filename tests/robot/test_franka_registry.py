"""The Franka is registered as a real robot and built for a task's cell."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from teachfit.core.errors import TeachfitError
from teachfit.robot.registry import ROBOTS, make_robot
from teachfit.tasks import get_task


def test_franka_is_registered_as_real() -> None:
    entry = ROBOTS["franka"]
    assert entry.simulated is False
    assert "libfranka" in entry.description


def test_franka_needs_a_host() -> None:
    with pytest.raises(TeachfitError, match="host"):
        make_robot("franka", get_task("peg"))


def test_make_robot_connects_with_the_tasks_tcp(expected_tcp: Callable) -> None:
    from teachfit.robot.franka import FrankaFrames, ee2tcp_for_part

    task = get_task("peg")
    want = expected_tcp(FrankaFrames(ee2tcp=ee2tcp_for_part(task.scene.held_part_length)))
    robot = make_robot("franka", task, host="127.0.0.1", realtime=False)
    try:
        assert robot.name == "franka"
        ee2tcp = robot.params.frames.ee2tcp  # type: ignore[attr-defined]
        np.testing.assert_allclose(ee2tcp.pos, [0, 0, task.scene.held_part_length])
        s = robot.step(5)
        np.testing.assert_allclose(s.pos, want[:, 3], atol=2e-3)
    finally:
        robot.close()
