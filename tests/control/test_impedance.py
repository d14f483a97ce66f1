import numpy as np
import pytest

from teachfit.control.impedance import (
    CartesianImpedance,
    DampingMemo,
    ImpedanceLimits,
    aligned_stiffness,
    critical_damping,
)
from teachfit.core.errors import ControlError
from teachfit.core.geometry import quat_from_rz
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot
from teachfit.tasks import get_task


def test_aligned_stiffness_is_high_along_and_low_across():
    k = aligned_stiffness([1.0, 1.0], along=2000, across=100, z=300, rotational=40)
    u = np.array([1.0, 1.0]) / np.sqrt(2)
    v = np.array([-1.0, 1.0]) / np.sqrt(2)
    assert u @ k[:2, :2] @ u == pytest.approx(2000)
    assert v @ k[:2, :2] @ v == pytest.approx(100)
    assert k[2, 2] == 300 and np.allclose(np.diag(k)[3:], 40)


def test_critical_damping_matches_scalar_formula():
    k = np.diag([400.0, 100.0, 900.0, 4.0, 9.0, 16.0])
    m = np.array([1.0, 1.0, 4.0, 0.01, 0.01, 0.04])
    d = critical_damping(k, m, 1.0)
    assert np.allclose(np.diag(d), 2 * np.sqrt(np.diag(k) * m))


def test_remembered_damping_is_the_computed_one():
    """DampingMemo returns critical_damping's bits, recomputed when the gains change."""
    rng = np.random.default_rng(2)
    m = np.array([1.0, 1.0, 1.0, 0.004, 0.004, 0.004])
    memo = DampingMemo(m)
    for _ in range(20):
        a = rng.normal(size=(6, 6))
        k = a @ a.T * 100.0
        for ratio in (1.0, 0.7):
            want = critical_damping(k, m, ratio)
            assert np.array_equal(memo(k, ratio), want)
            assert np.array_equal(memo(k.copy(), ratio), want)  # same values: remembered
    diag = np.diag([100.0, 200.0, 300.0, 1.0, 2.0, 3.0])
    assert np.array_equal(memo(diag, 1.0), critical_damping(diag, m, 1.0))


def test_wrench_limits_hold():
    ctrl = CartesianImpedance(np.ones(6), ImpedanceLimits(max_force=10, max_torque=1))
    cmd = ImpedanceCommand(pos=[1.0, 0, 0], quat=quat_from_rz(1.0), stiffness=[1e4] * 6)
    ctrl.set_command(cmd, 0.0)
    w = ctrl.compute(0.0, np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros(3), np.zeros(3))
    assert np.linalg.norm(w[:3]) == pytest.approx(10)
    assert np.linalg.norm(w[3:]) == pytest.approx(1)
    assert w[0] > 0 and w[5] > 0  # pulls towards the set-point


def test_command_validation():
    with pytest.raises(ControlError, match="NaN"):
        ImpedanceCommand(pos=[np.nan, 0, 0])
    with pytest.raises(ControlError, match="positive semi-definite"):
        ImpedanceCommand(pos=[0, 0, 0], stiffness=[-1, 1, 1, 1, 1, 1])
    with pytest.raises(ControlError, match="unit norm"):
        ImpedanceCommand(pos=[0, 0, 0], quat=[1, 1, 0, 0])


def test_tracks_a_moving_setpoint_in_free_space():
    task = get_task("peg2d")
    robot = FloatingToolRobot(task)
    start = task.contact_pose([0.0, 0.0]).translated([0, 0, 0.05])  # well above the block
    robot.reset(start)
    v = np.array([0.02, -0.01, 0.0])
    cmd = ImpedanceCommand(
        pos=start.pos, lin_vel=v, stiffness=[2000] * 3 + [50] * 3, expires_after=2.0
    )
    robot.command(cmd)
    state = robot.step(1000)
    expected = start.pos + v * state.t
    assert np.linalg.norm(state.pos - expected) < 1e-3  # < 1 mm lag at 2 cm/s
    assert np.allclose(state.lin_vel, v, atol=2e-3)
    assert np.linalg.norm(state.wrench[:3]) < 0.5  # nothing touched


def test_an_expired_command_stops_moving_the_setpoint():
    task = get_task("peg2d")
    robot = FloatingToolRobot(task)
    start = task.contact_pose([0.0, 0.0]).translated([0, 0, 0.05])
    robot.reset(start)
    v = np.array([0.02, 0.0, 0.0])
    robot.command(ImpedanceCommand(pos=start.pos, lin_vel=v, expires_after=0.2))
    robot.step(1500)  # 1.5 s: the set-point moved for 0.2 s only, then held
    state = robot.step(1)
    assert state.pos[0] - start.pos[0] == pytest.approx(0.02 * 0.2, abs=5e-4)
    assert np.linalg.norm(state.lin_vel) < 1e-3


def test_velocity_limit_clips_the_setpoint_motion():
    ctrl = CartesianImpedance(np.ones(6), ImpedanceLimits(max_speed=0.1, max_force=1e4))
    ctrl.set_command(ImpedanceCommand(pos=np.zeros(3), lin_vel=[1.0, 0, 0], expires_after=5.0), 0.0)
    w = ctrl.compute(1.0, np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros(3), np.zeros(3))
    # after 1 s the set-point moved 0.1 m, not 1 m: force = K * 0.1 + D * 0.1
    k = 1000.0
    assert w[0] == pytest.approx(k * 0.1 + 2 * np.sqrt(k) * 0.1, rel=1e-6)
