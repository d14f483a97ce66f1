"""Following set-point trajectories through the engine: success, timeout, force limit, faults."""

import numpy as np

from teachfit.core.errors import ConnectionLost, SimulationDiverged
from teachfit.core.outcome import Outcome
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.follow import run_trajectory
from teachfit.robot.floating import FloatingToolRobot
from teachfit.skills.follow import FollowConfig
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
    outcome = run_trajectory(robot, task, straight(task, start, [0, 0], 1.0), start)
    log = outcome.log
    assert outcome.success and outcome.outcome is Outcome.SUCCESS
    assert outcome.detected and outcome.ground_truth_inserted  # detector agrees with truth
    assert 0.3 < outcome.time_to_success < 2.0
    assert 0.009 < outcome.path_length < 0.04
    assert outcome.peak_force > 3.0
    assert log.t.size == log.pos.shape[0] > 10
    assert task.ground_truth_inserted(type(start)(log.pos[-1], log.quat[-1]))
    # the log holds the commanded set-points: they start at the start and end over the hole
    assert np.allclose(log.setpoint_pos[0], start.pos, atol=1e-9)
    assert np.linalg.norm(log.setpoint_pos[-1][:2]) < 0.005
    assert np.all(log.wrench_ff[1:, 2] == -6.0)  # the push into the surface


def test_failure_outcome_when_the_path_misses():
    task = get_task("peg2d")
    robot = FloatingToolRobot(task)
    start = task.contact_pose([0.01, 0.01])
    cfg = FollowConfig(settle_time=0.2)
    outcome = run_trajectory(robot, task, straight(task, start, [0.02, 0.02], 0.5), start, cfg)
    assert not outcome.success and outcome.outcome is Outcome.TIMEOUT
    assert np.isnan(outcome.time_to_success)
    assert outcome.duration >= 0.7 - 1e-9
    assert outcome.detected is False and outcome.ground_truth_inserted is False


def test_force_limit_ends_the_run():
    task = get_task("peg2d")
    robot = FloatingToolRobot(task)
    start = task.contact_pose([0.01, 0.01])
    cfg = FollowConfig(push_force=30.0, max_force=20.0)
    outcome = run_trajectory(robot, task, straight(task, start, [0.02, 0.02], 0.5), start, cfg)
    assert outcome.outcome is Outcome.FORCE_LIMIT and outcome.peak_force >= 20.0


class ExplodingRobot(FloatingToolRobot):
    def step(self, n=1):
        if self.time > 0.05:
            raise SimulationDiverged("NaN in the state at t=0.05 s")
        return super().step(n)


def test_divergence_ends_the_episode_as_failed():
    task = get_task("peg2d")
    robot = ExplodingRobot(task)
    start = task.contact_pose([0.01, 0.0])
    outcome = run_trajectory(robot, task, straight(task, start, [0, 0], 1.0), start)
    assert not outcome.success and outcome.outcome is Outcome.DIVERGED
    assert "NaN" in outcome.reason and outcome.log.t[-1] <= 0.06  # recorded data kept
    assert outcome.ground_truth_inserted is None


class DisconnectingRobot(FloatingToolRobot):
    def step(self, n=1):
        if self.time > 0.1:
            raise ConnectionLost("robot at 127.0.0.1 stopped answering")
        return super().step(n)


def test_a_robot_fault_is_its_own_outcome():
    task = get_task("peg2d")
    start = task.contact_pose([0.01, 0.0])
    outcome = run_trajectory(
        DisconnectingRobot(task), task, straight(task, start, [0, 0], 1.0), start
    )
    assert outcome.outcome is Outcome.FAULT and "stopped answering" in outcome.reason
    assert outcome.log.n_samples >= 10
