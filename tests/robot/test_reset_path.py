"""Resets that leave the hole along its axis before any lateral move, with a force watch."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from teachfit.core.errors import RobotFault
from teachfit.core.geometry import Pose, rotation_to_wxyz
from teachfit.robot.franka.reset_path import ResetCell, ResetGuard, reset_via_points

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
