"""The Franka twin (``teachfit robot twin``): the peg cell behind libfranka's protocol.

A plain pylibfranka client (no teachfit in between) presses the held peg on the base plate
beside the boss and reads what the twin's firmware reports; the teachfit driver checks the
robot and descends onto the boss as a skill does. The twin runs in lock-step
(``--no-realtime``), so nothing here depends on the machine's speed.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pf = pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")
pytest.importorskip("franky_sim", reason="needs the franka extra (franky-sim)")

from teachfit.core.geometry import Pose  # noqa: E402
from teachfit.core.state import ImpedanceCommand  # noqa: E402
from teachfit.robot.franka import (  # noqa: E402
    DEFAULT_BASE2WORLD,
    FrankaLimits,
    franka_for_task,
)
from teachfit.robot.franka.check import check_robot  # noqa: E402
from teachfit.robot.franka.frames import (  # noqa: E402
    approach_waypoints,
    ee2tcp_for_part,
)
from teachfit.robot.franka.sim import SimServer  # noqa: E402
from teachfit.tasks import get_task  # noqa: E402

TASK = get_task("peg")
PLATE_TOP = TASK.params.base_height  # the base plate's top beside the boss (m, world z)
#: the TCP 30 mm beside the hole (the peg clear of the boss), 2 mm above the plate
BESIDE_BOSS = (0.03, 0.0, PLATE_TOP + 0.002 - TASK.surface_z)
Twin = Callable[..., SimServer]


def _press(robot: Any, model: Any, force: float, ticks: int) -> Any:
    """Torque-control the arm from where it is: hold x, y and the orientation (Cartesian
    impedance), push ``force`` N down (world/base -z); return the last state. Raises
    pylibfranka's exceptions (a reflex)."""
    from scipy.spatial.transform import Rotation

    control = robot.start_torque_control()
    state, _ = control.readOnce()
    t0 = np.asarray(state.O_T_EE).reshape(4, 4, order="F")
    for i in range(ticks):
        t = np.asarray(state.O_T_EE).reshape(4, 4, order="F")
        jac = np.asarray(model.zero_jacobian(state)).reshape(6, 7, order="F")
        twist = jac @ np.asarray(state.dq)
        rot_err = Rotation.from_matrix(t0[:3, :3] @ t[:3, :3].T).as_rotvec()
        wrench = np.zeros(6)
        wrench[:2] = 1500.0 * (t0[:2, 3] - t[:2, 3]) - 60.0 * twist[:2]
        wrench[2] = -force * min(1.0, i / 500) - 300.0 * twist[2]
        wrench[3:] = 60.0 * rot_err - 3.0 * twist[3:]
        tau = jac.T @ wrench + np.asarray(model.coriolis(state)) - 0.5 * np.asarray(state.dq)
        torques = pf.Torques(tau.tolist())
        torques.motion_finished = i == ticks - 1
        control.writeOnce(torques)
        if i < ticks - 1:
            state, _ = control.readOnce()
    return state


def _client() -> tuple[Any, Any]:
    robot = pf.Robot("127.0.0.1", pf.RealtimeConfig.kIgnore)
    return robot, robot.load_model()


def test_robot_check_passes_and_the_tcp_is_where_the_cell_holds_the_part(
    franka_twin: Twin,
) -> None:
    franka_twin()
    result = check_robot("127.0.0.1", seconds=0.3, realtime=False)
    assert result.robot_mode == "Idle"
    assert result.timing.ticks == 300
    # check_robot's TCP is libfranka's EE frame, where the twin holds the part's top: the
    # part's tip starts 50 mm above the hole's entry
    top = TASK.contact_pose(np.zeros(2)).pos + [0.0, 0.0, 0.05 + TASK.scene.held_part_length]
    np.testing.assert_allclose(result.tcp_pos, top, atol=2e-3)


def test_pressing_down_reads_o_f_ext_hat_k_in_libfrankas_sign(franka_twin: Twin) -> None:
    franka_twin(start=BESIDE_BOSS)
    robot, model = _client()
    state = _press(robot, model, force=10.0, ticks=900)
    o_f = np.asarray(state.O_F_ext_hat_K)
    # the robot pushes the plate down with 10 N: libfranka reports that push, -z in the base
    assert -13.0 < o_f[2] < -7.0, o_f
    assert np.all(np.abs(o_f[:2]) < 3.0), o_f
    # K (= EE) has its z axis pointing down the part: the same push is +z in K
    assert 7.0 < state.K_F_ext_hat_K[2] < 13.0, state.K_F_ext_hat_K
    ee_z = np.asarray(state.O_T_EE)[14] + DEFAULT_BASE2WORLD.pos[2]  # world
    tip_z = ee_z - TASK.scene.held_part_length
    assert tip_z > PLATE_TOP - 1e-3
    assert tuple(state.cartesian_collision) == (0.0,) * 6  # under the 20 N default


@pytest.mark.parametrize(
    ("torque", "force", "reflex", "other"),
    [
        ([20.0] * 7, [5.0] * 6, "cartesian_reflex", "joint_reflex"),
        ([1.0] * 7, [20.0] * 6, "joint_reflex", "cartesian_reflex"),
    ],
)
def test_a_low_threshold_makes_a_push_a_reflex_that_recovery_clears(
    franka_twin: Twin, torque: list[float], force: list[float], reflex: str, other: str
) -> None:
    franka_twin(start=BESIDE_BOSS)
    robot, model = _client()
    lower = [min(v, 3.0) for v in force]
    robot.set_collision_behavior([min(v, 1.0) for v in torque], torque, lower, force)
    with pytest.raises(pf.ControlException, match=f"reflex.*{reflex}"):
        _press(robot, model, force=10.0, ticks=1500)
    state = robot.read_once()
    assert state.robot_mode == pf.RobotMode.Reflex
    assert getattr(state.current_errors, reflex) and getattr(state.last_motion_errors, reflex)
    assert not getattr(state.current_errors, other)
    robot.set_collision_behavior([20.0] * 7, [20.0] * 7, [20.0] * 6, [20.0] * 6)
    robot.automatic_error_recovery()
    for _ in range(10):  # states sent before the recovery may still be in flight
        state = robot.read_once()
        if state.robot_mode != pf.RobotMode.Reflex:
            break
    assert state.robot_mode == pf.RobotMode.Idle
    assert not getattr(state.current_errors, reflex)
    # a new motion is accepted again and runs
    state = _press(robot, model, force=2.0, ticks=300)
    assert not state.current_errors


def test_a_motion_is_refused_until_the_reflex_is_recovered(franka_twin: Twin) -> None:
    franka_twin(start=BESIDE_BOSS)
    robot, model = _client()
    robot.set_collision_behavior([20.0] * 7, [20.0] * 7, [3.0] * 6, [5.0] * 6)
    with pytest.raises(pf.ControlException, match="cartesian_reflex"):
        _press(robot, model, force=10.0, ticks=1500)
    with pytest.raises((pf.ControlException, pf.CommandException), match="not possible"):
        _press(robot, model, force=0.0, ticks=10)


def test_descending_below_the_entry_off_the_hole_is_stopped_by_the_boss(
    franka_twin: Twin,
) -> None:
    franka_twin(start=(0.003, 0.0, 0.005))  # 3 mm off the hole: the peg meets its rim
    above = TASK.contact_pose(np.array([0.003, 0.0]))
    below = Pose(above.pos - [0.0, 0.0, 0.01], above.quat)  # 10 mm below the entry
    with franka_for_task(TASK, host="127.0.0.1", realtime=False) as robot:
        start = above.translated([0.0, 0.0, 0.005])
        robot.reset(start)
        # the set-point descends at 2 cm/s as a skill's does, to 10 mm below the entry
        for pose in approach_waypoints(start, below, 0.02, 0.3, 0.01):
            robot.command(ImpedanceCommand.hold(pose, stiffness=800.0))
            state = robot.step(10)
        for _ in range(30):
            robot.command(ImpedanceCommand.hold(below, stiffness=800.0))
            state = robot.step(10)
    assert state.pos[2] > TASK.surface_z - 5e-4, state.pos  # on the boss, not in it
    assert state.wrench[2] > 4.0, state.wrench  # the boss pushes the part up (~8 N)


def test_a_client_that_stops_commanding_violates_the_communication_constraint(
    franka_twin: Twin,
) -> None:
    import time

    franka_twin(start=BESIDE_BOSS, realtime=True)
    robot, _ = _client()
    control = robot.start_torque_control()
    state, _ = control.readOnce()
    control.writeOnce(pf.Torques([0.0] * 7))
    time.sleep(0.3)  # 300 ticks without a command (the limit is 20)
    with pytest.raises(pf.ControlException, match="communication_constraints_violation"):
        for _ in range(50):
            state, _ = control.readOnce()
            control.writeOnce(pf.Torques([0.0] * 7))
    # 21 of the motion's last 100 ticks went without a command
    assert robot.read_once().control_command_success_rate == pytest.approx(0.79, abs=0.011)


_MAIN = "from teachfit.cli import main; main()"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--task", "nope"], "unknown task 'nope'"),
        (["--task", "peg", "--host", "10.1.2.3"], "--host 10.1.2.3: the twin listens on loopback"),
    ],
)
def test_robot_twin_bad_input_is_one_line_and_status_2(args: list[str], message: str) -> None:
    from typer.testing import CliRunner

    from teachfit.cli import app

    res = CliRunner().invoke(app, ["robot", "twin", *args])
    assert res.exit_code == 2, res.output
    assert message in " ".join(res.output.split()), res.output


def test_robot_twin_on_a_taken_port_is_one_line_and_status_2(franka_twin: Twin) -> None:
    from typer.testing import CliRunner

    from teachfit.cli import app

    franka_twin()
    args = ["robot", "twin", "--task", "peg", "--host", "127.0.0.1", "--no-realtime"]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 2, res.output
    text = " ".join(res.output.split())
    assert "127.0.0.1:1337 is taken" in text and "start the twin again" in text, text


def _spin_wrist(robot: Any, step: float, peak: float, ticks: int) -> None:
    """Torque-control joint 7 alone: ramp its torque by ``step`` N·m per tick up to ``peak``
    (the other joints get no torque; franky-sim compensates gravity)."""
    control = robot.start_torque_control()
    control.readOnce()
    tau = np.zeros(7)
    for _ in range(ticks):
        tau[6] = min(peak, tau[6] + step)
        control.writeOnce(pf.Torques(tau.tolist()))
        control.readOnce()


def test_a_joint_over_its_speed_limit_aborts_the_motion(franka_twin: Twin) -> None:
    franka_twin()
    robot, _ = _client()
    with pytest.raises(pf.ControlException, match="joint_velocity_violation"):
        _spin_wrist(robot, step=0.9, peak=8.0, ticks=400)  # 5.26 rad/s is joint 7's limit
    assert robot.read_once().current_errors.joint_velocity_violation


def test_a_torque_step_over_the_rate_limit_is_a_discontinuity(franka_twin: Twin) -> None:
    franka_twin()
    robot, _ = _client()
    with pytest.raises(pf.ControlException, match="controller_torque_discontinuity"):
        _spin_wrist(robot, step=3.0, peak=6.0, ticks=10)  # 3 N·m in 1 ms: 3000 N·m/s


def _default_sigint() -> None:
    # as at a terminal: a runner that started the tests in the background left SIGINT ignored
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize(
    ("sig", "status", "said"),
    [(signal.SIGTERM, 143, "twin stopped (SIGTERM)"), (signal.SIGINT, 130, "(Ctrl-C)")],
)
def test_robot_twin_stops_on_sigterm_and_ctrl_c_with_nothing_left(
    robot_port: int, sig: int, status: int, said: str
) -> None:
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2] / "src")}
    proc = subprocess.Popen(
        [sys.executable, "-c", _MAIN, "robot", "twin", "--task", "peg", "--no-realtime"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,
        preexec_fn=_default_sigint,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        assert "listening on 127.0.0.1" in line and f"PID {proc.pid}" in line, line
        os.killpg(proc.pid, sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == status, err
    assert said in err
    with pytest.raises(ProcessLookupError):
        os.killpg(proc.pid, 0)  # no process of its group is left


def _into_the_hole(robot: Any, stiffness: np.ndarray) -> tuple[Pose, Pose]:
    """Reset 5 mm above the hole's entry and lower the part 4 mm into it at 2 cm/s at
    ``stiffness``; the entry's contact pose and the pose 4 mm in."""
    entry = TASK.contact_pose(np.array([0.0, 0.0]))
    start, into = entry.translated([0.0, 0.0, 0.005]), entry.translated([0.0, 0.0, -0.004])
    robot.reset(start)
    for pose in approach_waypoints(start, into, 0.02, 0.3, 0.01):
        robot.command(ImpedanceCommand.hold(pose, stiffness=stiffness))
        robot.step(10)
    return entry, into


def test_a_reset_out_of_an_inserted_hole_leaves_along_its_axis_under_5_n(
    franka_twin: Twin,
) -> None:
    """The part inserted 8 mm deep, the next start 20 mm to the side: the reset pulls it out
    along the hole's axis first; the largest lateral force on the way out stays under 5 N."""
    franka_twin(start=(0.0, 0.0, 0.005))
    with franka_for_task(TASK, host="127.0.0.1", realtime=False) as robot:
        # compliant across (the chamfer centres the peg), stiff along the axis
        soft = np.array([150.0, 150.0, 800.0, 30.0, 30.0, 100.0])
        entry, into = _into_the_hole(robot, soft)
        deep = entry.translated([0.0, 0.0, -0.008])
        for pose in approach_waypoints(into, deep, 0.02, 0.3, 0.01):
            robot.command(ImpedanceCommand.hold(pose, stiffness=soft))
            state = robot.step(10)
        for _ in range(50):
            robot.command(ImpedanceCommand.hold(deep, stiffness=soft))
            state = robot.step(10)
        assert state.pos[2] < TASK.surface_z - 0.004, state.pos  # in the hole
        aside = entry.translated([0.02, 0.0, 0.025])
        done = robot.reset(aside)
        assert robot.reset_guard is not None
        peak = robot.reset_guard.peaks[-1]
    assert np.linalg.norm(done.pos - aside.pos) < 0.006
    assert peak <= 5.0, peak


def test_a_part_handed_over_still_sliding_into_the_hole_is_stopped_under_5_n(
    franka_twin: Twin, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The last command pushes the part into the hole (15 N down, compliant across); the
    reset takes over 18 mm deep with the part sliding in at about 0.2 m/s, as a skill's
    insertion leaves it at its success depth. The reset brakes along the hole's axis alone
    (the arm's inertia times the deceleration), so the lateral force of the whole reset, the
    hand-over included, stays under 5 N; braked by its impedance alone it read 10-11 N (the
    arm's inertia turned the brake along the axis into a push on the wall, and the part hit
    the hole's bottom still moving).

    The caller's thread is made to fall behind the loop, 4 ms per brake set-point (a busy
    machine): with set-points scheduled by its own steps the brake read 7-9 N; scheduled by
    the robot's ticks, under 3 N as without the lag."""
    from teachfit.robot.franka import driver

    command = driver.release_command

    def late(*args: Any) -> ImpedanceCommand:
        time.sleep(0.004)
        return command(*args)

    monkeypatch.setattr(driver, "release_command", late)
    franka_twin(start=(0.0, 0.0, 0.005))
    with franka_for_task(TASK, host="127.0.0.1", realtime=False) as robot:
        soft = np.array([150.0, 150.0, 300.0, 150.0, 150.0, 150.0])
        entry, _ = _into_the_hole(robot, soft)
        deep, push = entry.translated([0.0, 0.0, -0.03]), np.array([0, 0, -15.0, 0, 0, 0])
        for _ in range(300):
            robot.command(ImpedanceCommand.hold(deep, stiffness=soft, wrench_ff=push))
            state = robot.step(1)
            if state.pos[2] < TASK.surface_z - 0.018:
                break
        assert state.lin_vel[2] < -0.15, state.lin_vel  # handed over still sliding in
        robot.reset(entry.translated([0.02, 0.0, 0.025]))
        guard = robot.reset_guard
    assert guard is not None
    assert guard.peaks[-1] <= 5.0 and guard.handover_peaks[-1] <= 5.0, guard


#: the TCP 30 mm beside the hole, 2 mm above the plate (:data:`BESIDE_BOSS`), and 10 mm above
#: the boss's top there, over the reset's clearance plane (5 mm): a reset from there to
#: ``_BESIDE`` goes straight down, one from below the plane out of it and back
_BESIDE = TASK.contact_pose(np.zeros(2)).translated(list(BESIDE_BOSS))
_OVER_BESIDE = (BESIDE_BOSS[0], BESIDE_BOSS[1], 0.01)


def _press_down(robot: Any, depth: float, ticks: int) -> Any:
    """From :data:`_BESIDE` (where the caller reset the arm), hold the TCP ``depth`` m below
    the plate at 2000 N/m (about 2000 * depth N down once it rests on the plate); the last
    state."""
    below = Pose(_BESIDE.pos - [0.0, 0.0, 0.002 + depth], _BESIDE.quat)
    for pose in approach_waypoints(_BESIDE, below, 0.02, 0.3, 0.01):
        robot.command(ImpedanceCommand.hold(pose, stiffness=2000.0))
        state = robot.step(10)
    for _ in range(ticks // 10):
        robot.command(ImpedanceCommand.hold(below, stiffness=2000.0))
        state = robot.step(10)
    return state


def test_the_driver_sets_the_collision_reflex_above_its_force_limit_a_low_one_still_trips(
    franka_twin: Twin,
) -> None:
    """libfranka's default 20 N would stop a 30 N press; the driver's default (75 N) does not,
    and a reflex force of 10 N set through the driver makes the same press a reflex.

    The resets only place the arm (above the clearance plane between the two drivers, so that
    neither has to leave the plate's clearance and come back), at 3x the default reset speed;
    they run outside ``pytest.raises``: the reflex must come from the press."""
    from teachfit.core.errors import ReflexFault

    fast = FrankaLimits(reset_speed=0.15)
    franka_twin(start=_OVER_BESIDE)
    over = TASK.contact_pose(np.zeros(2)).translated(list(_OVER_BESIDE))
    with franka_for_task(TASK, host="127.0.0.1", realtime=False, limits=fast) as robot:
        assert robot.reflex is not None and robot.reflex.upper_force[:3] == (75.0,) * 3
        robot.reset(_BESIDE)
        state = _press_down(robot, depth=0.015, ticks=300)
        robot.reset(over)  # off the plate, over the clearance plane
    assert state.wrench[2] > 25.0, state.wrench  # the plate pushes back past 20 N: no reflex
    with franka_for_task(
        TASK, host="127.0.0.1", realtime=False, reflex_force=10.0, limits=fast
    ) as robot:
        robot.reset(_BESIDE)
        with pytest.raises(ReflexFault, match="cartesian_reflex"):
            _press_down(robot, depth=0.015, ticks=300)


def test_the_hand_answers_while_the_driver_holds_the_arm_in_lock_step(franka_twin: Twin) -> None:
    """pylibfranka's ``Gripper.read_once`` holds the GIL: the twin in lock-step gets no command
    while it waits, and still sends the hand's state (a reset's grasp check timed out)."""
    franka_twin()
    with franka_for_task(TASK, host="127.0.0.1", realtime=False) as robot:
        assert robot.grasp is not None, robot.grasp_note
        ticks = robot.ticks
        widths = [robot.grasp.gripper.read_once().width for _ in range(20)]
        robot.step(5)
        assert robot.ticks > ticks  # the control loop ran on after the reads
    assert len(widths) == 20


def test_a_peg_skill_execution_in_contact_is_not_stopped_by_a_reflex(franka_twin: Twin) -> None:
    """The skill's default parameters from the first start of seed 0: its lateral move pressed
    19 N across, over libfranka's default 20 N thresholds with the estimate's noise."""
    from teachfit.core.outcome import Outcome
    from teachfit.execution.skill_trial import SkillTrial, peg_in_hole_setup

    franka_twin()
    setup = peg_in_hole_setup(TASK, 0, 1)
    trial = SkillTrial(setup, robot="franka", host="127.0.0.1", realtime=False)
    try:
        trace = trial.run(None, setup.starts[0], setup.frame(0))
    finally:
        trial.robot.close()
    assert not trace.reflex and trace.outcome is not Outcome.FAULT, trace.reason
    assert trace.peak_force > 15.0, trace.peak_force  # it was in contact
    assert "lateral" in [v.node for v in trace.visits]


def test_the_laws_apparent_mass_is_the_arms_at_the_reset_pose(franka_twin: Twin) -> None:
    """The driver's damping uses the operational-space inertia from libfranka's mass matrix
    (the cell's own, up to the motors' rotor inertia the model leaves out), not 2 kg."""
    import mujoco

    from teachfit.robot.fr3 import model as fr3_model
    from teachfit.robot.fr3.control import operational_inertia
    from teachfit.robot.franka.twin_cell import TwinSimulator

    franka_twin()
    fast = FrankaLimits(reset_speed=0.15)  # the reset only places the arm: at 3x its speed
    with franka_for_task(TASK, host="127.0.0.1", realtime=False, limits=fast) as robot:
        robot.reset(TASK.contact_pose(np.zeros(2)).translated([0.0, 0.0, 0.02]))
        mass, q = robot.apparent_mass, robot.joint_positions
    sim = TwinSimulator(TASK)
    m, d = sim.model, sim.data
    ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in fr3_model.JOINTS]
    d.qpos[[m.jnt_qposadr[i] for i in ids]] = q
    mujoco.mj_forward(m, d)
    site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, fr3_model.TCP_SITE)
    cell = np.diag(operational_inertia(m, d, site))
    assert mass[0] > 5.0, mass  # the FR3's TCP weighs 10-15 kg along x here
    np.testing.assert_allclose(mass[:5], cell[:5], rtol=0.4)
    assert mass[5] >= 0.05  # about the tool axis: the floor (the model reads 0.002)


def test_the_driver_sends_the_held_part_as_the_firmwares_load(franka_twin: Twin) -> None:
    """On connect the driver sends the task's held part with ``setLoad``: the firmware's state
    then carries its mass and centre of mass (flange frame), which its gravity model uses."""
    from teachfit.robot.franka.load import part_load

    franka_twin(start=(0.0, 0.0, 0.05))
    raw, _ = _client()
    assert raw.read_once().m_load == 0.0  # a fresh twin carries no load
    del raw
    load = part_load(TASK)
    with franka_for_task(TASK, host="127.0.0.1", realtime=False) as robot:
        f_t_ee = np.asarray(robot._robot.read_once().F_T_EE).reshape(4, 4, order="F")
    mass, com, _ = load.in_flange(f_t_ee @ ee2tcp_for_part(TASK.scene.held_part_length).matrix)
    raw, _ = _client()
    state = raw.read_once()
    del raw
    assert state.m_load == pytest.approx(mass) and mass > 0.03
    np.testing.assert_allclose(state.F_x_Cload, com, atol=1e-9)
    assert com[2] == pytest.approx(0.1034 + 0.06 - 0.03, abs=1e-3)  # down the flange axis
