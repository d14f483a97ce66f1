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


def test_hold_depth_presses_a_dropped_peg_in_instead_of_dragging_it():
    # sharp edges, 0.2 mm clearance, friction 0.8: dragged on, a peg that dropped in wedges
    import pytest

    from teachfit.core.errors import SkillError
    from teachfit.robot.registry import make_robot

    task = get_task("peg2d", peg_chamfer=0.0, hole_chamfer=0.0, clearance=0.0002, friction=0.8)
    robot = make_robot("floating", task, seed=0)
    n = 250  # 2.5 s, 30 mm at 12 mm/s across the hole's centre
    pos = np.column_stack([np.linspace(-0.008, 0.022, n), np.zeros(n), np.full(n, task.surface_z)])
    plan = SetpointTrajectory.from_path(np.arange(n) / 100, pos, np.tile([1.0, 0, 0, 0], (n, 1)))
    cfg = FollowConfig(stiffness_along=600, stiffness_across=600, aligned=False, settle_time=0.0,
                       hold_depth=task.hold_depth)  # fmt: skip
    out = run_trajectory(robot, task, plan, task.contact_pose(pos[0, :2]), cfg)
    assert out.success, out.reason
    with pytest.raises(SkillError, match="hold_depth"):
        FollowConfig(hold_depth=0.0)
