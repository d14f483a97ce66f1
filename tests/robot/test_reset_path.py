"""Resets that leave the hole along its axis before any lateral move, with a force watch."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from teachfit.core.errors import RobotFault, TeachfitError
from teachfit.core.geometry import Pose, rotation_to_wxyz
from teachfit.robot.franka.reset_path import (
    BRAKE_RAMP,
    ResetCell,
    ResetGuard,
    brake_decel,
    brake_profile,
    brake_time,
    leave_stiffness,
    release_command,
    reset_via_points,
)

# a hole tilted 20 degrees about x, its entry at (0.1, 0, 0.05): the way out follows its axis
HOLE = Pose(np.array([0.1, 0.0, 0.05]), rotation_to_wxyz(Rotation.from_euler("x", 20, True)))
CELL = ResetCell(HOLE, clear_height=0.02)


def _in_hole(p: Pose) -> np.ndarray:
    return HOLE.inverse().compose(p).pos


def test_inside_the_hole_it_leaves_along_the_axis_first():
    inside = HOLE.compose(Pose(np.array([0.0003, -0.0002, -0.012])))
    goal = HOLE.compose(Pose(np.array([0.004, 0.003, 0.025]), rotation_to_wxyz(
        Rotation.from_euler("z", 0.3))))  # fmt: skip
    legs = reset_via_points(inside, goal, CELL)
    assert [name for name, _ in legs] == ["out", "over"]
    out = legs[0][1]
    # out: same x, y in the hole frame and the same orientation, at the clearance height
    np.testing.assert_allclose(_in_hole(out), [0.0003, -0.0002, 0.02], atol=1e-12)
    np.testing.assert_allclose(out.quat, inside.quat, atol=1e-12)
    assert legs[-1][1] is goal  # the start above the clearance plane: straight there


def test_a_start_below_the_clearance_plane_is_reached_from_above():
    inside = HOLE.compose(Pose(np.array([0.0, 0.0, -0.01])))
    goal = HOLE.compose(Pose(np.array([0.01, 0.0, 0.005])))
    names = [name for name, _ in reset_via_points(inside, goal, CELL)]
    assert names == ["out", "over", "down"]
    over = reset_via_points(inside, goal, CELL)[1][1]
    np.testing.assert_allclose(_in_hole(over), [0.01, 0.0, 0.02], atol=1e-12)


def test_clear_of_the_fixture_or_without_a_cell_it_goes_straight():
    above = HOLE.compose(Pose(np.array([0.0, 0.0, 0.03])))
    goal = HOLE.compose(Pose(np.array([0.02, 0.0, 0.005])))
    assert reset_via_points(above, goal, CELL) == [("direct", goal)]
    inside = HOLE.compose(Pose(np.array([0.0, 0.0, -0.01])))
    assert reset_via_points(inside, goal, None) == [("direct", goal)]


def test_guard_keeps_each_resets_peak_and_stops_past_the_limit():
    guard = ResetGuard(CELL)
    lateral = HOLE.rotation.apply([3.0, 4.0, 0.0])  # 5 N across the hole's axis
    along = HOLE.rotation.apply([0.0, 0.0, 40.0])  # along the axis: not lateral
    guard.watch(np.r_[lateral, 0, 0, 0])
    guard.watch(np.r_[along, 0, 0, 0])
    assert guard.finish() == pytest.approx(5.0)
    guard.watch(np.r_[0.5 * lateral, 0, 0, 0])
    assert guard.finish() == pytest.approx(2.5) and guard.peaks == pytest.approx([5.0, 2.5])
    with pytest.raises(RobotFault, match="reset stopped leaving the hole: 20.0 N"):
        guard.watch(np.r_[4 * lateral, 0, 0, 0])
    assert guard.peaks[-1] == pytest.approx(20.0)


def test_leaving_is_stiff_along_the_axis_and_compliant_across_and_about_it():
    k = leave_stiffness(CELL, along=2000.0)
    rot = HOLE.rotation.as_matrix()
    # in the hole frame: 200 N/m across its axis, the reset's 2000 along it, 10 N·m/rad turning
    np.testing.assert_allclose(rot.T @ k[:3, :3] @ rot, np.diag([200.0, 200.0, 2000.0]), atol=1e-9)
    np.testing.assert_allclose(k[3:, 3:], 10.0 * np.eye(3))
    assert not k[:3, 3:].any() and not k[3:, :3].any()
    # a 1 mm offset across the tilted axis pulls 0.2 N, the same offset along it 2 N
    across = HOLE.rotation.apply([0.001, 0.0, 0.0])
    assert np.linalg.norm(k[:3, :3] @ across) == pytest.approx(0.2)
    assert np.linalg.norm(k[:3, :3] @ HOLE.rotation.apply([0.0, 0.0, 0.001])) == pytest.approx(2.0)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"leave_stiffness": (0.0, 10.0)},
        {"release_stiffness": -1.0},
        {"release_time": (0.5, 0.1)},
        {"handover_time": 0.1},
        {"brake_decel": 0.0},
    ],
)
def test_a_cell_with_a_bad_compliance_or_release_time_is_refused(kwargs):
    with pytest.raises(TeachfitError, match="reset cell"):
        ResetCell(HOLE, clear_height=0.02, **kwargs)


def test_the_skills_force_at_the_hand_over_is_kept_apart_from_the_resets_own():
    guard = ResetGuard(CELL)
    lateral = HOLE.rotation.apply([0.6, 0.8, 0.0])  # 1 N across the hole's axis

    def watch(*newtons: float, handover: bool = True) -> None:
        for n in newtons:
            guard.watch(np.r_[n * lateral, 0, 0, 0], handover=handover)

    guard.take_over(np.r_[9.0 * lateral, 0, 0, 0])  # what the skill left: 9 N
    watch(9.5, 6.0, 2.0)  # the lagging estimate: still rising once, then fading
    watch(1.0, handover=False)  # past handover_time: the reset's own
    assert guard.finish() == pytest.approx(1.0)
    assert guard.peaks == pytest.approx([1.0]) and guard.handover_peaks == pytest.approx([9.5])
    # a reading that rises (after the first) ends the hand-over: it and all later are the reset's
    guard.take_over(np.r_[3.0 * lateral, 0, 0, 0])
    watch(2.0, 4.0, 2.5)
    assert guard.finish() == pytest.approx(4.0) and guard.handover_peaks[-1] == pytest.approx(3.0)
    watch(1.0)  # without a take-over: the reset's own
    guard.finish()
    assert guard.peaks[-1] == pytest.approx(1.0) and guard.handover_peaks[-1] == 0.0
    # the skill's force past the limit is no reason to stop (let go at the take-over) ...
    guard.take_over(np.r_[28.0 * lateral, 0, 0, 0])
    watch(27.9, 20.0)
    with pytest.raises(RobotFault, match="16.0 N"):  # ... the reset's own is
        watch(16.0, handover=False)
    assert guard.handover_peaks[-1] == pytest.approx(28.0)
    assert guard.peaks[-1] == pytest.approx(16.0)


@pytest.mark.parametrize("speed", [-0.2, 0.05, 0.004])
def test_the_brake_stops_smoothly_at_most_at_its_deceleration_and_jerk(speed):
    decel, ramp = 8.0, BRAKE_RAMP
    big_t = brake_time(speed, decel)
    t = np.linspace(0.0, big_t, 4001)
    dist, vel, acc = np.array([brake_profile(speed, decel, ti) for ti in t]).T
    # from the part's speed with no step in the force (zero acceleration) to rest, at rest after
    assert vel[0] == speed and acc[0] == 0.0 and vel[-1] == pytest.approx(0.0, abs=1e-12)
    assert acc[-1] == pytest.approx(0.0, abs=1e-12)
    peak = min(decel, abs(speed) / ramp)  # a slow part is stopped more gently
    assert np.max(np.abs(acc)) == pytest.approx(peak, rel=1e-3)
    assert np.max(np.abs(np.diff(acc))) <= decel / ramp * (t[1] - t[0]) * (1 + 1e-6)
    assert np.all(acc * speed <= 0.0)  # against the motion only
    assert dist[-1] == pytest.approx(speed * big_t / 2)
    if peak == decel:  # the shortest stop at that jerk and deceleration
        assert dist[-1] == pytest.approx(
            np.sign(speed) * (speed**2 / (2 * decel) + abs(speed) * ramp / 2)
        )
    # the parts agree: the distance is the speed's integral, the speed the acceleration's
    np.testing.assert_allclose(np.gradient(dist, t), vel, atol=1e-3 * abs(speed))
    np.testing.assert_allclose(np.gradient(vel, t), acc, atol=2e-2 * peak)
    assert brake_profile(speed, decel, 2 * big_t) == (dist[-1], 0.0, 0.0)
    assert brake_profile(0.0, decel, 0.1) == (0.0, 0.0, 0.0)


def _inertia() -> np.ndarray:
    """An operational-space inertia (6, 6) whose force along one axis also turns and shifts."""
    rng = np.random.default_rng(3)
    a = rng.normal(size=(6, 6))
    return a @ a.T + np.diag([8.0, 8.0, 8.0, 0.5, 0.5, 0.5])


def test_the_release_brakes_along_the_axis_alone():
    start = HOLE.compose(Pose(np.array([0.0003, -0.0002, -0.015])))
    axis = HOLE.rotation.apply([0.0, 0.0, 1.0])
    lam, speed, decel = _inertia(), -0.16, 8.0
    first = release_command(CELL, start, speed, lam, decel, 0.0)
    # the hand-over: where the part is, at its speed, no force yet (the skill's press let go)
    np.testing.assert_allclose(first.pos, start.pos)
    np.testing.assert_allclose(first.lin_vel, speed * axis)
    np.testing.assert_allclose(first.wrench_ff, 0.0, atol=1e-12)
    np.testing.assert_allclose(first.stiffness, leave_stiffness(CELL, CELL.release_stiffness))
    mid_t = brake_time(speed, decel) / 2
    mid = release_command(CELL, start, speed, lam, decel, mid_t)
    dist, _, acc = brake_profile(speed, decel, mid_t)
    np.testing.assert_allclose(mid.pos, start.pos + dist * axis, atol=1e-12)
    np.testing.assert_allclose(mid.quat, start.quat)
    assert acc == pytest.approx(decel)  # the part moves down the axis: braked upwards
    # the inertia's response to the brake: along the axis alone (no turn, no push across)
    response = np.linalg.solve(lam, mid.wrench_ff)
    np.testing.assert_allclose(response, np.r_[acc * axis, 0, 0, 0], atol=1e-9)
    assert np.linalg.norm(mid.wrench_ff[:3] - (mid.wrench_ff[:3] @ axis) * axis) > 1.0
    late = release_command(CELL, start, speed, lam, decel, 1.0)
    np.testing.assert_allclose(late.wrench_ff, 0.0, atol=1e-12)  # at rest, held there
    np.testing.assert_allclose(late.lin_vel, 0.0, atol=1e-12)
    stop = speed * brake_time(speed, decel) / 2
    np.testing.assert_allclose(late.pos, start.pos + stop * axis, atol=1e-12)


def test_the_brake_is_gentler_where_its_feed_forward_would_pass_the_force_limit():
    lam = _inertia()
    per = np.linalg.norm(lam[:3, :3] @ HOLE.rotation.apply([0.0, 0.0, 1.0]))
    assert brake_decel(CELL, lam, 1000.0, 1000.0) == CELL.brake_decel
    decel = brake_decel(CELL, lam, 5.0 * per, 1000.0)
    assert decel == pytest.approx(0.8 * 5.0) and decel < CELL.brake_decel
