import numpy as np
import pytest

from teachfit.core.errors import PlanningError, TeachfitError
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.tshix import SearchTrajectory, TshixPlanner, timed_path, tshix


@pytest.fixture
def expl2():
    return ExplorationDistribution(
        ("x", "y"), np.ones(1), np.array([[0.01, 0.005]]), np.array([[[1e-4, 2e-5], [2e-5, 4e-5]]])
    )


def test_plan_starts_at_origin_and_moves_at_teacher_speed(expl2):
    tr = tshix(expl2, 300, np.random.default_rng(0), speed=0.01, rate_hz=100.0)
    assert isinstance(tr, SearchTrajectory)
    np.testing.assert_allclose(tr.states[0], 0.0, atol=1e-15)
    speed = np.linalg.norm(np.diff(tr.states, axis=0), axis=1) / np.diff(tr.t)
    assert np.median(speed) == pytest.approx(0.01, rel=0.02)
    assert speed.max() < 0.0101
    assert tr.samples.shape == (300, 2) and sorted(tr.order.tolist()) == list(range(300))
    # the smoothed path passes close to the samples (within ~ one itinerary edge)
    it = tr.itinerary
    edge = np.median(np.linalg.norm(np.diff(it, axis=0), axis=1))
    d = np.min(np.linalg.norm(tr.states[None, ::2] - it[:, None], axis=2), axis=1)
    assert np.median(d) < 0.5 * edge
    # smoothing does not overshoot: the path stays within the samples' box (+ 1 mm)
    assert np.all(tr.states >= tr.samples.min(axis=0) - 1e-3)
    assert np.all(tr.states <= tr.samples.max(axis=0) + 1e-3)
    # and most of the time within the 3-sigma box of p_e
    lo, hi = expl2.bounding_box(3.0)
    assert np.all((tr.states >= lo) & (tr.states <= hi), axis=1).mean() > 0.8


def test_new_seed_new_trajectory_same_seed_same(expl2):
    p = TshixPlanner(expl2, 0.01)
    a, b = p.plan(100, np.random.default_rng(1)), p.plan(100, np.random.default_rng(1))
    c = p.plan(100, np.random.default_rng(2))
    np.testing.assert_array_equal(a.states, b.states)
    assert a.states.shape != c.states.shape or not np.allclose(a.states, c.states)


def test_extend_continues_from_the_end(expl2):
    p = TshixPlanner(expl2, 0.01)
    a = p.plan(100, np.random.default_rng(1))
    b = p.extend(a, 50, np.random.default_rng(2))
    n = a.t.size
    np.testing.assert_array_equal(b.states[:n], a.states)
    assert np.all(np.diff(b.t) > 0)
    assert np.linalg.norm(b.states[n] - a.states[-1]) < 0.011 * np.diff(b.t)[n - 1] + 1e-12
    assert b.samples.shape == (150, 2) and b.meta["passes"] == 2
    assert not np.any(np.all(np.isin(b.samples[100:], a.samples), axis=1))


def test_rotation_dim_and_angular_speed():
    e = ExplorationDistribution(
        ("x", "y", "rz"), np.ones(1), np.zeros((1, 3)), np.diag([1e-4, 4e-5, 0.01])[None]
    )
    p = TshixPlanner(e, speed=0.01, angular_speed=0.05)
    assert p.length_scale == pytest.approx(np.sqrt(7e-5 / 0.01))
    tr = p.plan(200, np.random.default_rng(0))
    v = np.diff(tr.states, axis=0) / np.diff(tr.t)[:, None]
    assert np.abs(v[:, 2]).max() <= 0.05 * 1.01
    assert np.linalg.norm(v[:, :2], axis=1).max() <= 0.01 * 1.01
    assert np.ptp(tr.states[:, 2]) > 0.2


def test_timed_path_and_bad_input(expl2):
    t, s = timed_path(np.array([[0.0, 0.0], [0.03, 0.04]]), ("x", "y"), speed=0.05, rate_hz=10)
    assert t[-1] == pytest.approx(1.0) and t.size == 11
    np.testing.assert_allclose(s[5], [0.015, 0.02])
    p = TshixPlanner(expl2, 0.01)
    for n in (0, -1):
        with pytest.raises(TeachfitError):
            p.plan(n, np.random.default_rng(0))
    with pytest.raises(TeachfitError):
        TshixPlanner(expl2, 0.0)
    with pytest.raises(PlanningError):
        SearchTrajectory(np.array([0.0, 0.0]), np.zeros((2, 2)), ("x", "y"))
