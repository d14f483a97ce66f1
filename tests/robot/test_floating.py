import numpy as np
import pytest
from scipy import signal

from teachfit.core.control import AdaptiveSpec
from teachfit.core.errors import ControlError, SimulationDiverged
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolParams, FloatingToolRobot
from teachfit.robot.interface import Robot
from teachfit.robot.sensor_filter import butterworth2
from teachfit.tasks import get_task


def test_is_a_robot_and_tares_at_reset():
    task = get_task("peg2d")
    robot = FloatingToolRobot(task, params=FloatingToolParams(ft_noise=(0.0, 0.0)))
    assert isinstance(robot, Robot)
    state = robot.reset(task.contact_pose([0.02, 0.0]).translated([0, 0, 0.01]))
    assert np.allclose(state.wrench, 0.0, atol=1e-9)
    assert robot.time == 0.0


@pytest.mark.parametrize("push", [4.0, 10.0])
def test_feedforward_force_is_read_back_by_the_wrist_sensor(push):
    task = get_task("peg2d")
    robot = FloatingToolRobot(task, params=FloatingToolParams(ft_noise=(0.0, 0.0)))
    start = task.contact_pose([0.02, 0.01])
    robot.reset(start)
    robot.command(
        ImpedanceCommand(
            pos=start.pos, wrench_ff=[0, 0, -push, 0, 0, 0], stiffness=[500, 500, 0, 40, 40, 40]
        )
    )
    state = robot.step(500)
    assert state.wrench[2] == pytest.approx(push, rel=0.02)  # the surface pushes back
    assert np.linalg.norm(state.wrench[:2]) < 0.05 * push


def test_sensor_noise_and_bias_are_applied():
    task = get_task("peg2d")
    params = FloatingToolParams(ft_noise=(0.5, 0.0), ft_bias=(1.0, 0, 0, 0, 0, 0))
    robot = FloatingToolRobot(task, params=params, seed=3)
    robot.reset(task.contact_pose([0.02, 0.0]).translated([0, 0, 0.01]))
    assert np.array_equal(robot.state().wrench, robot.state().wrench)  # noise enters per tick
    samples = np.array([robot.step(10).wrench for _ in range(400)])  # in free space, 100 Hz
    assert samples[:, 0].mean() == pytest.approx(1.0, abs=0.1)
    # the gauges' white noise (0.5 N per 1 kHz sample) leaves the 18 Hz Butterworth scaled by
    # the root of its impulse response's energy (about 0.19)
    b0, b1, b2, a1, a2 = butterworth2(params.ft_cutoff, params.timestep)
    impulse = signal.lfilter([b0, b1, b2], [1.0, a1, a2], np.eye(1, 2000)[0])
    gain = float(np.sqrt(np.sum(impulse**2)))
    assert 0.15 < gain < 0.25
    assert samples[:, 1].std() == pytest.approx(0.5 * gain, rel=0.15)


def test_divergence_is_reported_not_crashed():
    task = get_task("peg2d")
    robot = FloatingToolRobot(task)
    robot.reset(task.contact_pose([0.02, 0.0]))
    robot.data.qvel[0] = np.nan
    with pytest.raises(SimulationDiverged):
        robot.step(5)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "python"])
def test_a_nan_wrench_of_the_law_is_a_control_error_not_divergence(compiled):
    """The state goes NaN because the (adaptive) law commanded NaN: the law is reported."""
    task = get_task("peg2d")
    robot = FloatingToolRobot(task, controller=AdaptiveSpec())
    robot.reset(task.contact_pose([0.02, 0.0]))
    law = robot.law
    if compiled:
        law._ff_adapt[0] = np.nan  # type: ignore[attr-defined]  # adapted state blown up
    else:
        robot._kernel = None  # the Python tick
        real = law.compute  # type: ignore[attr-defined]

        def blown_up(*args: object) -> np.ndarray:
            w = real(*args) * np.nan
            law.last_wrench = w  # type: ignore[attr-defined]
            return w

        law.compute = blown_up  # type: ignore[attr-defined]
    with pytest.raises(ControlError, match="AdaptiveImpedance control law produced a non-fin"):
        robot.step(5)
    with pytest.raises(ControlError):  # the robot stays faulted until reset
        robot.step(1)
