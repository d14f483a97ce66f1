import numpy as np
import pytest

from teachfit.core.control import AdaptiveSpec, FixedGainSpec
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot
from teachfit.tasks import get_task


def _run(task, spec, compiled):
    robot = FloatingToolRobot(task, spec, seed=4)  # the same gauge noise in both
    start = task.contact_pose([0.012, 0.004]).translated([0, 0, 0.001])
    robot.reset(start)
    if not compiled:
        robot._kernel = None  # the Python tick, for reference
    out = []
    for k in range(30):  # pushing down, sliding and turning across the rim: contact
        cmd = ImpedanceCommand(
            pos=start.pos + [-1e-4 * k, 0, -0.003],
            quat=start.quat,
            lin_vel=[-0.01, 0.0, 0.0],
            ang_vel=[0.0, 0.0, 0.2],
            wrench_ff=[0, 0, -5.0, 0, 0, 0],
            stiffness=[800, 800, 200, 30, 30, 30],
            expires_after=0.005,
        )
        robot.command(cmd)
        s = robot.step(10)
        out.append(np.concatenate([s.pos, s.quat, s.wrench, robot.law.last_wrench]))
    return np.array(out), robot


@pytest.mark.parametrize("spec", [AdaptiveSpec(), FixedGainSpec()], ids=["adaptive", "fixed"])
def test_compiled_tick_follows_the_python_law(spec):
    task = get_task("key")
    fast, robot = _run(task, spec, compiled=True)
    ref, ref_robot = _run(task, spec, compiled=False)
    assert robot._kernel is not None
    assert np.abs(ref[:, 7:10]).max() > 1.0  # in contact: the sensor feels the lock face
    np.testing.assert_allclose(fast, ref, rtol=1e-6, atol=1e-8)
    if isinstance(spec, AdaptiveSpec):  # the law's adapted state is the Python law's
        np.testing.assert_allclose(robot.law.feedforward, ref_robot.law.feedforward, atol=1e-9)
        np.testing.assert_allclose(robot.law.stiffness, ref_robot.law.stiffness, atol=1e-9)
        assert np.abs(robot.law.feedforward).max() > 0


def test_compiled_ticks_run_without_mujoco_timers_and_restore_the_hook():
    # MuJoCo's profiling hook is off inside the compiled ticks: mj_step counts its calls but
    # times none of them; the bindings' hook is back afterwards, and Python's mj_step times
    import mujoco

    from teachfit.robot.fr3.kernel import _timer_hook

    robot = FloatingToolRobot(get_task("key"), AdaptiveSpec(), seed=4)
    robot.reset(get_task("key").contact_pose([0.012, 0.004]).translated([0, 0, 0.01]))
    hook = _timer_hook().value
    assert hook  # the bindings' clock
    step = robot.data.timer[mujoco.mjtTimer.mjTIMER_STEP]
    calls, spent = int(step.number), float(step.duration)
    robot.step(10)
    assert int(step.number) == calls + 10 and float(step.duration) == spent
    assert _timer_hook().value == hook
    mujoco.mj_step(robot.model, robot.data)
    assert float(step.duration) > spent
