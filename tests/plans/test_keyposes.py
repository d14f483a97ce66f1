"""Key-pose selection and ranking by the derivative of the fitted pose parameter."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from teachfit.core.errors import PlanningError
from teachfit.plans import build_assembly, rank_key_poses, synth_demo
from teachfit.plans.keyposes import straight_chain


def _pitch_demo(pitch):
    t = np.linspace(0.0, 2.0, len(pitch))
    pos = np.c_[np.linspace(0.0, 0.01, len(t)), np.zeros((len(t), 2))]
    q = Rotation.from_euler("y", np.asarray(pitch)[:, None]).as_quat()[:, [3, 0, 1, 2]]
    return t, pos, q


def test_steepest_pitch_is_ranked_first():
    # pitch follows a smooth step, steepest at t = 1.5 s
    t = np.linspace(0.0, 2.0, 201)
    pitch = -0.4 / (1.0 + np.exp(-(t - 1.5) / 0.08))
    keys = rank_key_poses(*_pitch_demo(pitch), 8, param="pitch")
    assert keys.param == "pitch"
    first = keys.order[0]
    assert abs(keys.t[first] - 1.5) < 0.2
    assert np.all(np.diff(np.abs(keys.derivative[keys.order])) <= 1e-12)
    assert sorted(keys.ranks) == list(range(1, len(keys.indices) + 1))
    assert np.all(np.diff(keys.indices) > 0)
    # the candidates as poses: the demonstrated samples themselves
    t_, pos, q = _pitch_demo(pitch)
    for pose, i in zip(keys.poses, keys.indices, strict=True):
        assert np.allclose(pose.pos, pos[i]) and abs(abs(pose.quat @ q[i]) - 1) < 1e-12


def test_included_samples_are_candidates_and_the_rest_stay_evenly_spaced():
    t, pos, q = _pitch_demo(np.linspace(0.0, 1.0, 101))
    plain = rank_key_poses(t, pos, q, 5, param="pitch").indices
    keys = rank_key_poses(t, pos, q, 5, param="pitch", include=np.array([7, 93]))
    assert len(keys.indices) == 5 and {7, 93} <= set(keys.indices.tolist())
    others = sorted(set(keys.indices.tolist()) - {7, 93})
    assert others != plain.tolist()[:3] and np.all(np.diff(others) > 20)  # 3 spread evenly
    with pytest.raises(PlanningError, match="include"):
        rank_key_poses(t, pos, q, 2, param="pitch", include=np.array([3, 5, 9]))
    with pytest.raises(PlanningError, match="include"):
        rank_key_poses(t, pos, q, 5, param="pitch", include=np.array([0]))


def test_auto_picks_the_most_changing_parameter():
    keys = rank_key_poses(*_pitch_demo(np.linspace(0.0, 1.0, 101)), 5, param="auto")
    assert keys.param == "pitch"
    assert len(keys.indices) == 5


def test_eligible_mask_restricts_candidates():
    t, pos, q = _pitch_demo(np.linspace(0.0, 1.0, 101))
    eligible = np.zeros(101, dtype=bool)
    eligible[60:90] = True
    keys = rank_key_poses(t, pos, q, 5, param="pitch", eligible=eligible)
    assert np.all((keys.indices >= 60) & (keys.indices < 90))


def test_synthetic_l_demo_ranks_pivot_poses_before_level_ones():
    asm = build_assembly("l-groove")
    demo = synth_demo(asm, 3)
    keys = rank_key_poses(demo.t, demo.pos, demo.quat, 6, param="pitch")
    assert len(keys.indices) == 6
    assert np.all(np.abs(keys.derivative[keys.order[:2]]) >= np.abs(keys.derivative).max() * 0.5)


@pytest.mark.parametrize("n", [0, 1])
def test_too_short_demonstrations_raise(n):
    t, pos, q = _pitch_demo(np.zeros(3))
    with pytest.raises(PlanningError, match="at least 2"):
        rank_key_poses(t[:n], pos[:n], q[:n], 4)


def test_bad_parameter_or_motionless_demo_raises():
    t, pos, q = _pitch_demo(np.linspace(0.0, 1.0, 20))
    with pytest.raises(PlanningError, match="unknown pose parameter"):
        rank_key_poses(t, pos, q, 4, param="speed")
    with pytest.raises(PlanningError, match="does not move"):
        rank_key_poses(t, np.zeros_like(pos), np.tile([1.0, 0, 0, 0], (20, 1)), 4)


def test_straight_chain_takes_the_farthest_reachable_candidate():
    # 5 candidates; straight motions reach at most 2 nodes ahead, except 1 -> 4
    def connects(a, b):
        return b - a <= 2 or (a, b) == (1, 4)

    assert straight_chain(5, connects) == [1, 4]
    assert straight_chain(5, lambda a, b: True) == []  # start sees the goal
    assert straight_chain(3, lambda a, b: False) == [0, 1, 2]  # nothing connects: all of them
