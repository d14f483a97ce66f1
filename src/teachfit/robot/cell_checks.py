"""The checks every cell must pass in simulation: the aligned part enters, an offset one is
blocked.

Each check starts the floating tool ``start_height`` above the hole entry at a lateral offset
(hole frame) and pushes it straight down with a soft impedance (the stiffness below) for
``steps`` 1 ms steps; it reports how deep the TCP got below the entry. The aligned part must
be inserted (:meth:`~teachfit.tasks.base.Task.ground_truth_inserted`) and, where the task
knows the depth at which its geometry stops the aligned part (a ``stop_depth``: the hole's
bottom, the table under a through hole, a shoulder of the part), get no deeper than that plus
:data:`STOP_TOLERANCE`; a part ``offset`` off in x or y must stay above 0.2 mm depth. Lengths
in metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot
from teachfit.tasks.base import Task

#: translational and rotational stiffness of the push (N/m, N m/rad)
STIFFNESS = (300.0, 300.0, 300.0, 50.0, 50.0, 50.0)
#: an offset part deeper than this (m) below the entry is not blocked
BLOCKED_DEPTH = 2e-4
#: how far (m) past the geometry's stop the aligned part may get (soft contact, sampling)
STOP_TOLERANCE = 2e-4


@dataclass(frozen=True)
class CellCheck:
    """One check: its name, whether it passed, the depth reached (m) and what was expected."""

    name: str
    passed: bool
    depth: float
    expected: str


def push(
    robot: FloatingToolRobot,
    task: Task,
    x: float,
    y: float,
    steps: int = 1000,
    start_height: float = 0.002,
) -> Pose:
    """Start ``start_height`` above the entry at ``(x, y)`` (hole frame, m), push 30 mm down;
    the TCP pose after ``steps`` steps."""
    start = task.hole2world.compose(Pose.from_xyz_rz(x, y, start_height, 0.0))
    robot.reset(start)
    target = start.pos - [0.0, 0.0, 0.03]
    robot.command(ImpedanceCommand(pos=target, quat=start.quat, stiffness=np.array(STIFFNESS)))
    return robot.step(steps).pose


def run_cell_checks(task: Task, offset: float = 0.001, steps: int = 1000) -> list[CellCheck]:
    """The aligned push and the pushes ``offset`` (m) off along the hole frame's +x and +y."""
    robot = FloatingToolRobot(task)
    pose = push(robot, task, 0.0, 0.0, steps)
    depth = task.insertion_depth(pose)
    stop: float | None = getattr(task, "stop_depth", None)
    expected = f">= {1e3 * task.success_depth:.1f} mm"
    passed = task.ground_truth_inserted(pose)
    if stop is not None:
        expected += f", <= {1e3 * stop:.2f} mm where the geometry stops it"
        passed = passed and depth <= stop + STOP_TOLERANCE
    out = [CellCheck("aligned part enters", passed, depth, expected)]
    for axis, (dx, dy) in (("x", (offset, 0.0)), ("y", (0.0, offset))):
        pose = push(robot, task, dx, dy, steps)
        depth = task.insertion_depth(pose)
        out.append(
            CellCheck(
                f"part {1e3 * offset:g} mm off in {axis} is blocked",
                depth < BLOCKED_DEPTH and not task.ground_truth_inserted(pose),
                depth,
                f"< {1e3 * BLOCKED_DEPTH:.1f} mm",
            )
        )
    return out
