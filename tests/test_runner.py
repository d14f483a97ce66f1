import numpy as np

from teachfit.core.errors import SimulationDiverged
from teachfit.execution.runner import ExecutionConfig, run_trajectory
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.robot.floating import FloatingToolRobot
from teachfit.tasks import get_task


def straight(task, start, goal_xy, duration):
    t = np.linspace(0.0, duration, 50)
    a = (t / duration)[:, None]
    xy = (1 - a) * start.pos[:2] + a * np.asarray(goal_xy)
    pos = np.column_stack([xy, np.full(t.size, task.surface_z)])
    return SetpointTrajectory.from_path(t, pos)


def test_success_outcome():
    task = get_task("peg2d")
    robot = FloatingToolRobot(task)
    start = task.contact_pose([0.01, 0.0])
    outcome, log = run_trajectory(robot, task, straight(task, start, [0, 0], 1.0), start)
    assert outcome.success and outcome.reason == "inserted"
    assert 0.3 < outcome.time_to_insertion < 2.0
    assert 0.009 < outcome.path_length < 0.04
    assert outcome.peak_force > 3.0
    assert log.t.size == log.pos.shape[0] > 10
    assert task.ground_truth_inserted(type(start)(log.pos[-1], log.quat[-1]))


def test_failure_outcome_when_the_path_misses():
    task = get_task("peg2d")
    robot = FloatingToolRobot(task)
    start = task.contact_pose([0.01, 0.01])
    cfg = ExecutionConfig(settle_time=0.2)
    outcome, _ = run_trajectory(robot, task, straight(task, start, [0.02, 0.02], 0.5), start, cfg)
    assert not outcome.success and outcome.reason == "timeout"
    assert np.isnan(outcome.time_to_insertion)
    assert outcome.duration >= 0.7 - 1e-9


class ExplodingRobot(FloatingToolRobot):
    def step(self, n=1):
        if self.time > 0.05:
            raise SimulationDiverged("NaN in the state at t=0.05 s")
        return super().step(n)


def test_divergence_ends_the_episode_as_failed():
    task = get_task("peg2d")
    robot = ExplodingRobot(task)
    start = task.contact_pose([0.01, 0.0])
    outcome, _ = run_trajectory(robot, task, straight(task, start, [0, 0], 1.0), start)
    assert not outcome.success
    assert outcome.reason.startswith("diverged")
