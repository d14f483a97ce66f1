"""The follow primitive's felt-press loop (``press_feel``) and lag loop (``track_feel``)."""

import numpy as np
import pytest

from teachfit.core.geometry import Pose
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.follow import FollowConfig, FollowSetpoints
from teachfit.skills.percept import MPCommand, Percept


def _pushes(press_feel, measured, ticks=50):
    t = np.array([0.0, 10.0])
    traj = SetpointTrajectory.from_path(t, np.zeros((2, 3)), np.tile([1.0, 0, 0, 0], (2, 1)))
    run = FollowSetpoints(traj, FollowConfig(push_force=6.0, press_feel=press_feel)).compile({})
    pc = Percept(Pose(np.zeros(3)), 0.01)
    run.enter(pc)
    out = []
    for _ in range(ticks):
        pc.f[2] = measured
        cmd = MPCommand()
        run.command(pc, cmd)
        out.append(-cmd.wrench[2])
    return np.array(out)


def test_open_loop_by_default():
    assert np.all(_pushes(0.0, 4.0) == 6.0)


def test_a_light_felt_press_is_pushed_harder_slowly_and_bounded():
    push = _pushes(0.3, 4.5, ticks=200)  # 1.5 N short of the wanted 6 N
    assert push[0] < 6.2 and np.all(np.diff(push) >= 0)
    assert push[30] == pytest.approx(6.0 + 1.5 * 0.01 / 0.3 * 31)
    assert push[-1] == 9.0  # clipped at half the push force more


def test_no_correction_out_of_contact():
    assert np.all(_pushes(0.3, 0.5) == 6.0)  # over a hole or in the air: the plain push


def test_once_held_the_lateral_stiffness_is_the_hold_stiffness_every_way():
    t = np.array([0.0, 10.0])
    pos = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    traj = SetpointTrajectory.from_path(t, pos, np.tile([1.0, 0, 0, 0], (2, 1)))
    cfg = FollowConfig(hold_depth=0.001, hold_stiffness=200.0)
    run = FollowSetpoints(traj, cfg).compile({})
    pc = Percept(Pose(np.zeros(3)), 0.01)
    run.enter(pc)
    cmd = MPCommand()
    run.command(pc, cmd)  # sliding: stiff along x, soft across
    assert cmd.stiffness_full[0, 0] == 1500.0 and cmd.stiffness_full[1, 1] == 150.0
    pc.p[:] = (0.003, 0.0005, -0.0012)  # sank 1.2 mm: held where it is, relaxed sideways
    cmd = MPCommand()
    run.command(pc, cmd)
    assert np.allclose(pc.p_d[:2], (0.003, 0.0005)) and np.all(cmd.twist[:2] == 0.0)
    assert np.allclose(cmd.stiffness_full[:2, :2], 200.0 * np.eye(2))
    with pytest.raises(Exception, match="hold_stiffness"):
        FollowConfig(hold_stiffness=-1.0)


def _drags(cfg, pressed, ticks=200):
    """The x force the follower adds along a +x trajectory at 10 mm/s, the TCP held at 0."""
    t = np.array([0.0, 10.0])
    pos = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    traj = SetpointTrajectory.from_path(t, pos, np.tile([1.0, 0, 0, 0], (2, 1)))
    run = FollowSetpoints(traj, cfg).compile({})
    pc = Percept(Pose(np.zeros(3)), 0.01)
    run.enter(pc)
    out = []
    for k in range(ticks):
        pc.f[2] = pressed
        pc.t_node = pc.t = 0.01 * k
        pc.p[:] = 0.0  # stuck: the set-point runs ahead
        cmd = MPCommand()
        run.command(pc, cmd)
        out.append((cmd.wrench[0], cmd.wrench[1]))
    return np.array(out)


def test_a_lagging_part_is_pushed_along_the_motion_slowly_and_bounded():
    f = _drags(FollowConfig(track_feel=0.1), pressed=6.0)
    assert np.all(f[:, 1] == 0.0) and np.all(np.diff(f[:, 0]) >= 0.0)  # along x only, growing
    # the integral of k_along x lag over 0.1 s: at tick k the set-point leads by 1e-4 k m
    lags = 1e-4 * np.arange(10)
    assert f[9, 0] == pytest.approx(1500.0 * 0.01 / 0.1 * lags.sum())
    assert f[-1, 0] == 6.0  # clipped at the push force
    assert np.all(_drags(FollowConfig(track_feel=0.1), pressed=1.0) == 0.0)  # not pressed
    assert np.all(_drags(FollowConfig(), pressed=6.0) == 0.0)  # off by default


def test_a_tilted_search_closes_the_lag_while_searching_only():
    """Tilted, the part is pushed along the motion in the searching phases (a tilted part
    held back by friction far from the hole lagged 5 mm for 10 s on the FR3); in the slide and
    the align it stalls at the wall on purpose: no push there, and the loop starts afresh."""
    from teachfit.skills.follower import Follower
    from teachfit.skills.tilt import TiltConfig

    t = np.array([0.0, 10.0])
    pos = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    traj = SetpointTrajectory.from_path(t, pos, np.tile([1.0, 0, 0, 0], (2, 1)))
    follower = Follower(traj, FollowConfig(track_feel=0.1, tilt=TiltConfig()))
    pc = Percept(Pose(np.zeros(3)), 0.01)
    follower.start(pc)

    def along(k: int, searching: bool) -> float:
        pc.f[2], pc.t = 6.0, 0.01 * k
        pc.p[:] = 0.0  # stuck: the set-point runs ahead
        cmd = MPCommand()
        follower.track(pc, cmd, pc.t, searching)
        return float(cmd.wrench[0])

    pushed = [along(k, True) for k in range(20)]
    assert pushed[-1] > 0.0 and np.all(np.diff(pushed) >= 0.0)
    assert along(20, False) == 0.0 and follower.track_correction == 0.0  # sliding: none
    assert 0.0 < along(21, True) < pushed[-1]  # searching again: from zero
