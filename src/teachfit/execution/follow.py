"""Running a set-point trajectory (a search, a replay, a teacher's motion) through the engine."""

from __future__ import annotations

import numpy as np

from teachfit.core.control import ControllerSpec
from teachfit.core.geometry import Pose
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.engine import ExecConfig, ExecutionResult, execute
from teachfit.robot.interface import Robot
from teachfit.skills.follow import FollowConfig, follow_skill
from teachfit.tasks.base import Task

WORLD = Pose(np.zeros(3))


def run_trajectory(
    robot: Robot,
    task: Task,
    trajectory: SetpointTrajectory,
    start: Pose,
    config: FollowConfig | None = None,
    *,
    command_rate: float = 100.0,
    log_rate: float = 100.0,
    controller: ControllerSpec | None = None,
) -> ExecutionResult:
    """Reset ``robot`` at ``start`` and follow ``trajectory`` (world frame) until the task's
    success detector fires, the time budget (duration + settle time) runs out, or the force
    limit is hit: a one-node skill (:func:`~teachfit.skills.follow.follow_skill`) run by the
    engine. Never raises for a fault: the result says what happened."""
    cfg = config or FollowConfig()
    budget = trajectory.duration + cfg.settle_time + cfg.extra_time + 2.0
    exec_cfg = ExecConfig(
        command_rate=command_rate, log_rate=log_rate, max_time=budget, recovery_time=0.0
    )
    skill = follow_skill(trajectory, cfg)
    return execute(skill, robot, start, WORLD, task=task, config=exec_cfg, controller=controller)
