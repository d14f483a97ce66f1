"""FrankaRobot through the real libfranka protocol (pylibfranka client, franky-sim server)."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from teachfit.core.control import AdaptiveSpec, FixedGainSpec
from teachfit.core.errors import ConnectionLost, ControlError, LimitViolation, RobotFault
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.interface import Robot

pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")

from teachfit.robot.franka import FrankaFrames, FrankaLimits, ee2tcp_for_part  # noqa: E402
from teachfit.robot.franka.driver import FrankaParams, FrankaRobot  # noqa: E402

PART = 0.05  # held part length (m)
HOME = Pose(np.array([0.0, 0.0, 0.15]))  # part pointing straight down above the cell
STIFF = np.array([3000.0] * 3 + [150.0] * 3)
# franky-sim's FR3 joints have 1.14 N·m Coulomb friction (frictionloss): at 3000 N/m the TCP
# stops a few mm short of a set-point. The tolerances below are that, not control error.
TOL = 0.006


#: the driver's limits with resets at 3x the default speed (0.15 m/s): a reset here only places
#: the arm (franky-sim runs in real time: a reset's length is the test's), and what the tests
#: of resets check (the pose reached, the clock, the bias, the way out of a hole) holds at it
FAST_RESETS = FrankaLimits(reset_speed=0.15)


def _params(limits: FrankaLimits | None = None) -> FrankaParams:
    return FrankaParams(
        limits=limits or FAST_RESETS, frames=FrankaFrames(ee2tcp=ee2tcp_for_part(PART))
    )


@pytest.fixture
def robot(franka_sim: object) -> Iterator[FrankaRobot]:
    r = FrankaRobot("127.0.0.1", params=_params(), realtime=False)
    try:
        yield r
    finally:
        r.close()


def test_connects_and_reports_the_tcp_in_the_task_world(
    franka_sim: object, expected_tcp: Callable[[FrankaFrames], np.ndarray]
) -> None:
    frames = _params().frames
    want = expected_tcp(frames)
    with FrankaRobot("127.0.0.1", params=_params(), realtime=False) as robot:
        assert isinstance(robot, Robot)
        s = robot.step(10)
        np.testing.assert_allclose(s.pos, want[:, 3], atol=2e-3)
        rot = Rotation.from_quat(np.roll(s.quat, -1)).as_matrix()
        np.testing.assert_allclose(rot, want[:, :3], atol=5e-3)
        assert np.linalg.norm(s.lin_vel) < 0.01
        assert robot.wrench_source == "joint-torques" and robot.control_period == 0.001
        t0 = robot.ticks
        robot.step(50)
        assert robot.ticks >= t0 + 50


def test_default_frames_put_the_part_pointing_down_above_the_cell(robot: FrankaRobot) -> None:
    """At franky-sim's start pose (EE 0.554 m ahead, 0.521 m up, pointing down) the default
    base2world puts the TCP near the cell and an identity quaternion means part down."""
    s = robot.reset(Pose(np.array([0.054, 0.0, 0.221])))
    assert abs(abs(s.quat[0]) - 1.0) < 0.01
    np.testing.assert_allclose(robot.joint_positions[[1, 3, 5]], [0.0, -1.57, 1.57], atol=0.15)


def test_reset_moves_to_the_pose_and_zeroes_time(robot: FrankaRobot) -> None:
    before = robot.ticks
    s = robot.reset(HOME)
    took = (robot.ticks - before) * robot.control_period  # the reset's length, in robot time
    # the clock restarted on the tick that adopted the task's law, at the end of the reset
    assert 0.0 < s.t < min(0.05, 0.1 * took), (s.t, took)
    assert robot.time >= s.t
    assert np.linalg.norm(s.pos - HOME.pos) < 0.006
    assert np.linalg.norm(s.wrench) < 1e-6  # bias taken at rest


def test_holds_and_tracks_a_small_cartesian_move(robot: FrankaRobot) -> None:
    start = robot.reset(HOME)
    target = start.pos + np.array([0.02, -0.01, -0.01])
    robot.command(ImpedanceCommand(pos=target, quat=HOME.quat, stiffness=STIFF))
    s = robot.step(600)  # within TOL and at rest after ~300 ticks
    assert np.linalg.norm(s.pos - target) < TOL
    assert np.linalg.norm(s.pos - start.pos) > 0.02  # it did move
    assert np.linalg.norm(s.lin_vel) < 0.01  # and came to rest


def test_adaptive_law_runs_in_the_loop(robot: FrankaRobot) -> None:
    robot.reset(HOME, controller=AdaptiveSpec())
    assert type(robot.law).__name__ == "AdaptiveImpedance"
    target = HOME.pos + np.array([0.0, 0.02, 0.0])
    robot.command(ImpedanceCommand(pos=target, quat=HOME.quat, stiffness=STIFF))
    s = robot.step(600)  # within TOL and at rest after ~300 ticks
    assert np.linalg.norm(s.pos - target) < TOL
    with pytest.raises(ControlError, match="k_max"):  # refused here, not in the loop
        robot.command(ImpedanceCommand(pos=target, stiffness=5000.0))
    assert robot.running
    robot.reset(HOME, controller=FixedGainSpec())
    assert type(robot.law).__name__ == "CartesianImpedance"


def test_the_loop_times_each_tick_since_a_tick_count(robot: FrankaRobot) -> None:
    start = robot.ticks
    robot.step(300)
    compute, gaps = robot.timing_since(start)
    assert 300 <= len(compute) <= robot.ticks - start
    assert np.all(compute > 0) and np.all(compute < 0.5)  # filled, in seconds
    assert np.all(gaps >= 0) and np.median(gaps) == pytest.approx(0.001)  # robot time, s
    assert len(robot.timing_since(robot.ticks + 5)[0]) == 0


def test_skill_like_sequence_follows_and_expires(robot: FrankaRobot) -> None:
    """A line at 2 cm/s commanded every 50 ms, then one moving command left to expire."""
    start = robot.reset(HOME)
    v = np.array([0.02, 0.0, 0.0])
    states = []
    for k in range(20):  # 1 s
        robot.command(
            ImpedanceCommand(
                pos=start.pos + v * 0.05 * k, lin_vel=v, stiffness=STIFF, expires_after=0.1
            )
        )
        states.append(robot.step(50))
    ys = np.array([s.pos for s in states])
    assert np.all(np.diff(ys[:, 0])[3:] > 0)  # moving along +x throughout
    assert abs(ys[-1, 0] - (start.pos[0] + 0.02)) < TOL
    # the set-point moves only for expires_after = 0.2 s: 4 mm, not the 2 cm of 1 s
    here = robot.state().pos
    robot.command(ImpedanceCommand(pos=here, lin_vel=v, stiffness=STIFF, expires_after=0.2))
    s = robot.step(1000)
    assert np.linalg.norm(s.pos[0] - here[0]) < 0.004 + TOL
    assert np.linalg.norm(s.lin_vel) < 0.01


def test_wrench_over_the_limit_is_refused_before_sending(robot: FrankaRobot) -> None:
    s = robot.reset(HOME)
    too_much = ImpedanceCommand.hold(s.pose, wrench_ff=[0, 0, -80.0, 0, 0, 0])
    with pytest.raises(LimitViolation, match="nothing was sent"):
        robot.command(too_much)
    after = robot.step(300)
    assert np.linalg.norm(after.pos - s.pos) < 0.003  # it still just holds
    with pytest.raises(LimitViolation, match="workspace"):
        robot.reset(Pose(np.array([0.0, 0.0, 0.9])))
    with pytest.raises(LimitViolation, match="workspace"):
        robot.command(ImpedanceCommand(pos=[0.5, 0.0, 0.1]))


def test_speed_limit_faults_the_loop_and_reset_recovers(franka_sim: object) -> None:
    limits = FrankaLimits(max_tcp_speed=0.02)
    with FrankaRobot("127.0.0.1", params=_params(limits), realtime=False) as robot:
        robot.reset(HOME)
        robot.command(
            ImpedanceCommand(pos=HOME.pos + [0.05, 0.0, 0.0], stiffness=STIFF, expires_after=5)
        )
        with pytest.raises(LimitViolation, match="TCP speed"):
            robot.step(2000)
        with pytest.raises(LimitViolation):  # latched: nothing more is accepted
            robot.command(ImpedanceCommand.hold(HOME))
        kept = robot.state()
        assert np.linalg.norm(kept.lin_vel) >= 0.02  # the state that tripped it is kept
        s = robot.reset(HOME)
        assert np.linalg.norm(s.pos - HOME.pos) < 0.006


def test_killed_server_is_a_lost_connection_with_the_data_kept(franka_sim: object) -> None:
    robot = FrankaRobot("127.0.0.1", params=_params(), realtime=False)
    old_pid = franka_sim.pid  # type: ignore[attr-defined]
    recorded = []
    try:
        robot.reset(HOME)
        v = np.array([0.0, 0.02, 0.0])
        with pytest.raises(ConnectionLost) as err:
            for k in range(40):
                robot.command(ImpedanceCommand(pos=HOME.pos + v * 0.05 * k, lin_vel=v))
                recorded.append(robot.step(50))
                if k == 10:
                    franka_sim.kill()  # type: ignore[attr-defined]
        assert "no control tick" in str(err.value) or "Network" in str(err.value)
        assert 10 <= len(recorded) <= 12
        assert all(np.all(np.isfinite(s.pos)) for s in recorded)
        with pytest.raises(RobotFault):
            robot.step(1)
    finally:
        robot.close()
        franka_sim.start()  # type: ignore[attr-defined]
    import os

    assert not os.path.exists(f"/proc/{old_pid}")  # the killed server is gone, reaped


def test_ctrl_c_holds_then_finishes_the_loop(robot: FrankaRobot, ctrl_c: None) -> None:
    import os
    import signal
    import threading

    robot.reset(HOME)
    robot.command(ImpedanceCommand(pos=HOME.pos + [0.0, 0.03, 0.0], lin_vel=[0, 0.01, 0]))
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        robot.step(5000)
    timer.join()
    assert not robot.running  # the loop finished
    assert np.linalg.norm(robot.state().lin_vel) < 0.02  # held still before finishing
    with pytest.raises(RobotFault, match="Ctrl-C"):
        robot.command(ImpedanceCommand.hold(HOME))
    s = robot.reset(HOME)  # and a reset starts a new loop
    assert np.linalg.norm(s.pos - HOME.pos) < 0.006


def test_gil_switch_interval_is_short_while_connected(franka_sim: object) -> None:
    import sys

    before = sys.getswitchinterval()
    with FrankaRobot("127.0.0.1", params=_params(), realtime=False):
        assert sys.getswitchinterval() <= 2e-4  # a busy caller cannot stall a tick for 5 ms
    assert sys.getswitchinterval() == before


def test_what_exists_at_connect_is_out_of_the_collectors_scans_while_connected(
    franka_sim: object,
) -> None:
    import gc

    def tracked(obj: object) -> bool:  # in a generation a collection scans
        return any(o is obj for o in gc.get_objects())

    before: list[list[str]] = [["made before connecting"]]
    assert tracked(before)
    with FrankaRobot("127.0.0.1", params=_params(), realtime=False) as robot:
        robot.step(5)
        after: list[list[str]] = [["made while connected"]]
        # a full collection stalls the control thread: it scans only what came since
        assert not tracked(before) and tracked(after)
    assert tracked(before) and gc.get_freeze_count() == 0


def test_reset_from_inside_a_hole_lifts_along_its_axis_before_moving_sideways(
    franka_sim: object,
) -> None:
    """With a reset cell the TCP leaves the hole straight up (its axis is world z here) to the
    clearance plane, then moves across; every reset's peak lateral force is kept."""
    from teachfit.robot.franka.reset_path import ResetCell

    hole = Pose(np.array([0.0, 0.0, 0.07]))
    cell = ResetCell(hole, clear_height=0.05)  # the clearance plane at z = 0.12
    params = FrankaParams(limits=FAST_RESETS, frames=_params().frames, reset_cell=cell)
    with FrankaRobot("127.0.0.1", params=params, realtime=False) as robot:
        robot.reset(Pose(np.array([0.0, 0.0, 0.095])))  # "inside": 25 mm below the plane
        robot.tap(5)
        robot.reset(Pose(np.array([0.05, 0.0, 0.095])))
        path = np.array([s.pos for s in robot.untap()])
        assert robot.reset_guard is not None and len(robot.reset_guard.peaks) == 2
    lifted = int(np.argmax(path[:, 2] > 0.11))  # first sample near the clearance plane
    assert lifted > 0 and path[:, 2].max() > 0.115
    # below it, on the way up, the TCP stayed over the hole (franky-sim's joint friction
    # leaves the TCP a few mm off a set-point: TOL); the sideways move came after
    assert np.abs(path[:lifted, 0]).max() < TOL
    assert path[-1, 0] > 0.05 - TOL


def test_finish_execution_stops_the_press_at_once_and_the_reset_goes_on_from_there(
    franka_sim: object,
) -> None:
    """A skill's last command still driving the TCP down the hole's axis is ended by
    ``finish_execution``, not by the next reset: the TCP is braked within a few millimetres
    and stays; the reset then leaves from where it was let go (one release per reset)."""
    from teachfit.robot.franka.reset_path import ResetCell

    cell = ResetCell(Pose(np.array([0.0, 0.0, 0.07])), clear_height=0.05)
    params = FrankaParams(limits=FAST_RESETS, frames=_params().frames, reset_cell=cell)
    with FrankaRobot("127.0.0.1", params=params, realtime=False) as robot:
        s = robot.reset(Pose(np.array([0.0, 0.0, 0.11])))  # below the clearance plane
        down = np.array([0.0, 0.0, -0.1])  # m/s: the skill's set-point sliding down
        robot.command(
            ImpedanceCommand(s.pos, s.quat, lin_vel=down, stiffness=STIFF, expires_after=1.0)
        )
        s = robot.step(150)
        assert s.lin_vel[2] < -0.05  # moving down the axis when the execution ends
        robot.finish_execution()
        stopped = robot.state()
        assert abs(stopped.lin_vel[2]) < 0.01 and s.pos[2] - stopped.pos[2] < 0.004
        held = robot.step(300)  # the skill's set-point would have gone 30 mm further
        assert abs(held.pos[2] - stopped.pos[2]) < 0.001
        robot.reset(Pose(np.array([0.05, 0.0, 0.095])))
        assert robot.reset_guard is not None and len(robot.reset_guard.peaks) == 2
        np.testing.assert_allclose(robot.state().pos, [0.05, 0.0, 0.095], atol=TOL)
