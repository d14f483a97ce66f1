"""Small run logs for the recording tests: two real executions and one made by hand."""

from __future__ import annotations

import functools
import math

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.core.outcome import Outcome
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.engine import ExecutionResult, NodeVisit
from teachfit.execution.follow import run_trajectory
from teachfit.execution.log import ExecutionLog
from teachfit.execution.recording import Episode, RunInfo
from teachfit.robot.floating import FloatingToolRobot
from teachfit.skills.follow import FollowConfig
from teachfit.tasks import get_task


def _straight(start: Pose, goal_xy: tuple[float, float], z: float, s: float) -> SetpointTrajectory:
    t = np.linspace(0.0, s, 20)
    a = t[:, None]
    xy = (1 - a) * start.pos[:2] + a * np.asarray(goal_xy)
    return SetpointTrajectory.from_path(t, np.column_stack([xy, np.full(t.size, z)]))


@functools.cache
def real_run() -> tuple[tuple[Episode, ...], RunInfo]:
    """Two short executions on peg2d from 10 mm beside the hole: into it (1 s), and away from
    it (0.3 s, then a timeout)."""
    task = get_task("peg2d")
    robot = FloatingToolRobot(task)
    episodes = []
    for goal, s in (((0.0, 0.0), 1.0), ((0.012, 0.0), 0.3)):
        start = task.contact_pose([0.01, 0.0])
        planned = _straight(start, goal, task.surface_z, s)
        result = run_trajectory(robot, task, planned, start, FollowConfig(settle_time=0.2 + s))
        episodes.append(Episode(result, start=start, planned=planned, name=f"to {goal}"))
    info = RunInfo.here("search", task, "floating", 3, "straight", {"n": 20, "out": task.name})
    return tuple(episodes), info


def hand_made() -> ExecutionResult:
    """A result with what the engine rarely makes: a recovery node (-1), unknown detector and
    ground truth, no time to success."""
    n = 5
    t = np.arange(n) * 0.01
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    log = ExecutionLog(
        t=t,
        pos=np.column_stack([t, -t, np.full(n, 0.05)]),
        quat=quat,
        wrench=np.arange(6 * n, dtype=float).reshape(n, 6),
        setpoint_pos=np.zeros((n, 3)),
        wrench_ff=np.ones((n, 6)),
        depth=-t,
        node=np.array([0, 0, 1, -1, -1]),
        setpoint_quat=quat,
    )
    visits = (
        NodeVisit("push", 0.0, 0.015, "-> twist: F_z ≥ 3 N"),
        NodeVisit("twist", 0.015, 0.025, "twist error: t_node ≥ 0.01 s"),
        NodeVisit("back", 0.025, 0.04, "recovered"),
    )
    return ExecutionResult(
        skill="hand-made",
        outcome=Outcome.ERROR_CONDITION,
        reason="twist error: t_node ≥ 0.01 s",
        visits=visits,
        t_first_contact=0.01,
        t_end=0.025,
        time_to_success=math.nan,
        path_length=0.001,
        peak_force=7.5,
        remaining=0.02,
        detected=None,
        ground_truth_inserted=None,
        log=log,
        node_names=("push", "twist"),
        steps=40,
        wall_s=0.001,
    )


def assert_same_result(a: ExecutionResult, b: ExecutionResult) -> None:
    """Every field of two results equal (arrays element by element, NaN equal to NaN)."""
    for name in ExecutionResult.__dataclass_fields__:
        x, y = getattr(a, name), getattr(b, name)
        if name == "log":
            for f in ExecutionLog.__dataclass_fields__:
                np.testing.assert_array_equal(getattr(x, f), getattr(y, f), err_msg=f)
                assert getattr(x, f).dtype.kind == getattr(y, f).dtype.kind, f
        elif isinstance(x, float):
            assert x == y or (math.isnan(x) and math.isnan(y)), name
        else:
            assert x == y, name
