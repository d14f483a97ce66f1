"""The compiled FR3 tick: the same torques as the Python path, a replay that matches."""

import dataclasses

import mujoco
import numpy as np
import pytest

from teachfit.control import compiled
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.fr3 import FR3Robot, kernel
from teachfit.tasks import get_task


@pytest.fixture(scope="module")
def task():
    return get_task("peg2d")


def _sliding(task, compiled: bool) -> tuple[np.ndarray, FR3Robot]:
    robot = FR3Robot(task)
    start = task.protocol.teacher_start(np.random.default_rng(0))
    robot.reset(start)
    # a spinning set-point, extrapolated in the law, that expires half-way (then it is held)
    cmd = dataclasses.replace(
        ImpedanceCommand.hold(start),
        lin_vel=np.array([0.01, 0.0, 0.0]),
        ang_vel=np.array([0.0, 0.0, 0.05]),
        wrench_ff=np.array([0, 0, -6.0, 0, 0, 0]),
        expires_after=0.08,
    )
    robot.command(cmd)
    robot.ctl.compiled = compiled  # False: the Python law between the compiled half-ticks
    rows = []
    for _ in range(16):
        s = robot.step(10)
        rows.append(np.concatenate([s.pos, s.wrench, robot.joint_torques]))
    return np.array(rows), robot


def test_compiled_fixed_gain_tick_equals_the_python_law(task):
    fast, fast_robot = _sliding(task, compiled=True)
    slow, slow_robot = _sliding(task, compiled=False)
    np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-9)
    assert fast_robot.law._error.lapsed and slow_robot.law._error.lapsed
    np.testing.assert_allclose(fast_robot.law.last_wrench, slow_robot.law.last_wrench, atol=1e-9)
    assert np.ptp(fast[:, 0]) > 1e-5  # it did move along x


def test_replaying_the_torques_through_the_physics_gives_the_same_run(task):
    robot = FR3Robot(task)
    robot.reset(task.protocol.teacher_start(np.random.default_rng(0)))
    m, d = robot.model, robot.data
    snapshot = (d.qpos.copy(), d.qvel.copy(), d.qacc_warmstart.copy(), d.time)
    ticks, log = robot.step_timed(200)
    end = d.qpos.copy()
    assert ticks.shape == (200,) and np.all(ticks > 0)
    d.qpos[:], d.qvel[:], d.qacc_warmstart[:], d.time = snapshot
    mujoco.mj_forward(m, d)
    robot.replay(log)
    np.testing.assert_allclose(d.qpos, end, atol=1e-12)


def test_the_robot_keeps_each_executions_joint_torques(task):
    robot = FR3Robot(task)
    start = task.protocol.teacher_start(np.random.default_rng(0))
    for n in (3, 5):
        robot.reset(start)
        for _ in range(n):
            robot.step(10)
    first, second = robot.recent_torque_traces(2)
    assert first[1].shape == (3, 7) and second[1].shape == (5, 7)
    np.testing.assert_allclose(second[0], np.arange(1, 6) * 0.01, atol=1e-9)
    np.testing.assert_allclose(second[1][-1], robot.joint_torques)


def test_the_routines_sit_where_the_compiled_law_calls_them():
    fns = kernel.routines()
    assert fns[compiled.SUB_QUAT].__name__ == "mju_subQuat"
    assert fns[compiled.ROT_VEC_QUAT].__name__ == "mju_rotVecQuat"
    assert fns[compiled.QUAT_INTEGRATE].__name__ == "mju_quatIntegrate"
