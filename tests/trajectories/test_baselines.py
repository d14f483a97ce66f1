import numpy as np
import pytest

from teachfit.core.errors import PlanningError
from teachfit.trajectories.baselines import archimedean_spiral, random_walk


def test_spiral_pitch_radius_speed():
    tr = archimedean_spiral(("x", "y"), pitch=0.002, radius=0.01, speed=0.01)
    np.testing.assert_allclose(tr.states[0], 0.0, atol=1e-15)
    r = np.linalg.norm(tr.states, axis=1)
    assert r.max() == pytest.approx(0.01, rel=1e-3)
    theta = np.unwrap(np.arctan2(tr.states[1:, 1], tr.states[1:, 0]))
    # r = a θ with a = pitch / 2π: after one more turn the radius grows by the pitch
    assert np.polyfit(theta - theta[0], r[1:], 1)[0] == pytest.approx(0.002 / (2 * np.pi), rel=0.01)
    speed = np.linalg.norm(np.diff(tr.states, axis=0), axis=1) / np.diff(tr.t)
    assert np.median(speed) == pytest.approx(0.01, rel=0.02) and speed.max() < 0.0101


def test_spiral_3d_keeps_or_sweeps_rz():
    flat = archimedean_spiral(("x", "y", "rz"), pitch=0.002, radius=0.01, speed=0.01)
    np.testing.assert_array_equal(flat.states[:, 2], 0.0)
    sweep = archimedean_spiral(
        ("x", "y", "rz"), pitch=0.002, radius=0.01, speed=0.01, rz_amplitude=0.2, angular_speed=0.1
    )
    assert np.abs(sweep.states[:, 2]).max() == pytest.approx(0.2, rel=0.01)
    assert np.abs(np.diff(sweep.states[:, 2]) / np.diff(sweep.t)).max() <= 0.1 * 1.01


def test_random_walk_bounded_and_seeded():
    kw = dict(
        n_steps=200,
        step_max=0.003,
        radius=0.01,
        speed=0.01,
        rz_step_max=0.05,
        rz_radius=0.2,
        length_scale=0.05,
    )
    a = random_walk(("x", "y", "rz"), np.random.default_rng(0), **kw)
    b = random_walk(("x", "y", "rz"), np.random.default_rng(0), **kw)
    np.testing.assert_array_equal(a.states, b.states)
    assert np.linalg.norm(a.states[:, :2], axis=1).max() <= 0.01 + 1e-12
    assert np.abs(a.states[:, 2]).max() <= 0.2 + 1e-12 and np.ptp(a.states[:, 2]) > 0.1
    steps = np.linalg.norm(np.diff(a.states[:, :2], axis=0), axis=1)
    assert steps.max() <= 0.003 * 1.0001
    c = random_walk(
        ("x", "y"), np.random.default_rng(1), n_steps=100, step_max=0.003, radius=0.01, speed=0.01
    )
    assert c.states.shape[1] == 2 and c.method == "random_walk"


def test_bad_input():
    with pytest.raises(PlanningError):
        random_walk(("x", "z"), np.random.default_rng(0), n_steps=5, step_max=1, radius=1, speed=1)
    with pytest.raises(PlanningError):
        random_walk(("x", "y"), np.random.default_rng(0), n_steps=0, step_max=1, radius=1, speed=1)
    with pytest.raises(PlanningError):
        archimedean_spiral(("x", "y"), pitch=0.0, radius=0.01, speed=0.01)
