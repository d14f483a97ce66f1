"""The success detector (:meth:`Task.detect_success`) against the simulator's ground truth.

The detector sees only what a robot measures (its TCP pose) and the cell's drawing (nominal
entry height and hole axis); each task is pushed down in MuJoCo from its standard situations
(aligned, off the hole and blocked, beside the fixture) and the detector must agree with
``ground_truth_inserted``.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot
from teachfit.tasks import TASKS, Task, get_task

STIFF = [300, 300, 300, 50, 50, 50]

#: (task, overrides, start (x, y, rz) in the hole frame 2 mm above the entry, inserted?)
SITUATIONS = [
    ("peg2d", (), (0.0, 0.0, 0.0), True),
    ("peg2d", (("peg_chamfer", 0.0), ("hole_chamfer", 0.0)), (0.001, 0.0, 0.0), False),
    ("peg2d", (), (0.075, 0.0, 0.0), False),  # beside the cylinder: deep, not in the hole
    ("socket3d", (), (0.0, 0.0, 0.0), True),
    ("socket3d", (), (0.0, 0.0, np.pi), True),  # the pins swap holes
    ("socket3d", (), (0.0, 0.007, 0.0), False),  # pins on the flat floor, out of the valleys
    ("puzzle", (), (0.0, 0.0, 0.0), True),
    ("puzzle", (), (-0.001, 0.0, 0.0), False),
    ("puzzle", (), (0.0, 0.0, 0.2), False),  # turned: rests on the block
    ("key", (), (0.0, 0.0, 0.0), True),
    ("key", (), (0.0025, 0.0, 0.0), False),
    ("key", (), (0.0, 0.0, np.deg2rad(25.0)), False),
    ("peg", (), (0.0, 0.0, 0.0), True),
    ("peg", (), (0.0005, 0.0, 0.0), True),  # the chamfer guides it in
    ("peg", (), (0.002, 0.0, 0.0), False),  # blocked on the rim
    ("peg", (), (0.022, 0.0, 0.0), False),  # beside the boss: down to the plate
]


@cache
def robot(name: str, overrides: tuple[tuple[str, float], ...]) -> FloatingToolRobot:
    return FloatingToolRobot(get_task(name, **dict(overrides)))


def push(robot: FloatingToolRobot, x: float, y: float, rz: float, steps: int = 1200) -> Pose:
    """Start 2 mm above the entry at (x, y, rz) in the hole frame and push 3 cm down softly."""
    start = robot.task.hole2world.compose(Pose.from_xyz_rz(x, y, 0.002, rz))
    robot.reset(start)
    robot.command(ImpedanceCommand(pos=start.pos - [0, 0, 0.03], quat=start.quat, stiffness=STIFF))
    return robot.step(steps).pose


@pytest.mark.parametrize(("name", "overrides", "start", "inserted"), SITUATIONS)
def test_detector_agrees_with_ground_truth(name, overrides, start, inserted) -> None:
    rob = robot(name, overrides)
    task: Task = rob.task
    pose = push(rob, *start)
    assert task.ground_truth_inserted(pose) is inserted
    assert task.detect_success(pose) is inserted


@pytest.mark.parametrize(("name", "x"), [("peg2d", 0.075), ("peg", 0.022), ("peg", 0.03)])
def test_beside_the_fixture_is_deep_yet_no_success(name: str, x: float) -> None:
    task = robot(name, ()).task
    pose = push(robot(name, ()), x, 0.0, 0.0)
    assert task.entry_height - pose.pos[2] > task.success_depth  # depth alone would say yes
    assert task.lateral_error(pose) > task.detection_radius
    assert not task.detect_success(pose) and not task.ground_truth_inserted(pose)


@pytest.mark.parametrize("name", sorted(TASKS))
def test_detector_window_is_the_nominal_hole_axis(name: str) -> None:
    task = get_task(name)
    deep = task.nominal_hole2world.compose(Pose.from_xyz_rz(0.0, 0.0, -task.success_depth, 0.0))
    assert task.detect_success(deep) and task.ground_truth_inserted(deep)
    shallow = deep.translated([0.0, 0.0, 1e-4])
    assert not task.detect_success(shallow)
    beside = deep.translated([task.detection_radius + 1e-4, 0.0, 0.0])
    assert not task.detect_success(beside)
    assert 0 < task.capture_radius < task.detection_radius


def test_detector_follows_a_turned_hole() -> None:
    task = get_task("key", hole_yaw=0.7)
    deep = task.hole2world.compose(Pose.from_xyz_rz(0.0, 0.0, -0.015, 0.0))
    assert task.detect_success(deep) and task.ground_truth_inserted(deep)
