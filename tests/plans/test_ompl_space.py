"""The OMPL boundary: seeding, state conversion, rotation interpolation."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from teachfit.core.errors import PlanningError
from teachfit.plans.ompl_space import PLANNERS, matrix_to_state, seed_ompl, slerp


def test_matrix_to_state_round_trip():
    rot = Rotation.from_euler("xyz", [0.3, -0.2, 1.1])
    T = np.eye(4)
    T[:3, :3] = rot.as_matrix()
    T[:3, 3] = [0.01, -0.02, 0.03]
    s = matrix_to_state(T)
    assert s.shape == (7,)
    np.testing.assert_allclose(s[:3], T[:3, 3])
    back = Rotation.from_quat([s[4], s[5], s[6], s[3]]).as_matrix()  # scipy is x-y-z-w
    np.testing.assert_allclose(back, T[:3, :3], atol=1e-12)


def test_a_stack_of_transforms_converts_as_each_one_does():
    rots = Rotation.random(5, random_state=3).as_matrix()
    T = np.tile(np.eye(4), (5, 1, 1))
    T[:, :3, :3] = rots
    T[:, :3, 3] = np.arange(15.0).reshape(5, 3) * 1e-3
    stack = matrix_to_state(T)
    assert stack.shape == (5, 7)
    for i in range(5):  # the planner's states must not depend on how they were converted
        assert np.array_equal(stack[i], matrix_to_state(T[i]))


def test_slerp_ends_midpoint_and_shorter_arc():
    qa = np.array([1.0, 0.0, 0.0, 0.0])
    qb = np.array([np.cos(0.5), 0.0, 0.0, np.sin(0.5)])  # 1 rad about z
    q = slerp(qa, qb, np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(q[0], qa, atol=1e-12)
    np.testing.assert_allclose(q[2], qb, atol=1e-12)
    np.testing.assert_allclose(q[1], [np.cos(0.25), 0.0, 0.0, np.sin(0.25)], atol=1e-12)
    # -qb is the same rotation: the interpolation takes the shorter arc, not the 2 pi - 1 one
    q_neg = slerp(qa, -qb, np.array([0.5]))
    np.testing.assert_allclose(np.abs(q_neg[0]), np.abs(q[1]), atol=1e-12)


@pytest.mark.parametrize("bad", [-1, 2**32, 1.5, True])
def test_seed_ompl_rejects_bad_seeds(bad):
    with pytest.raises(PlanningError, match="seed"):
        seed_ompl(bad)


def test_planners_by_name():
    assert "RRTConnect" in PLANNERS
