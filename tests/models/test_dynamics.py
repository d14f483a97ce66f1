import numpy as np
import pytest

from teachfit.core.errors import ModelError
from teachfit.models.dynamics import DynamicsModel, fit_dynamics


def _random_spd(rng, n):
    a = rng.normal(size=(n, n))
    return a @ a.T + n * np.eye(n)


def test_conditioning_matches_closed_form_2d():
    rng = np.random.default_rng(0)
    cov = _random_spd(rng, 4)
    mu = rng.normal(size=4)
    m = DynamicsModel(("x", "y"), np.ones(1), mu[None], cov[None])
    ds = rng.normal(size=(5, 2))
    mean, c = m.condition(ds)
    s, a = slice(0, 2), slice(2, 4)
    for k in range(5):
        expect = mu[a] + cov[a, s] @ np.linalg.inv(cov[s, s]) @ (ds[k] - mu[s])
        np.testing.assert_allclose(mean[k], expect, rtol=1e-10)
    expect_cov = cov[a, a] - cov[a, s] @ np.linalg.inv(cov[s, s]) @ cov[s, a]
    np.testing.assert_allclose(c[0], expect_cov, rtol=1e-10)


def test_scalar_case_by_hand():
    # D = 1 per block (x only): mu* = mu_a + (c_as / c_ss)(ds - mu_s)
    m = DynamicsModel(
        ("x",), np.ones(1), np.array([[1.0, 2.0]]), np.array([[[4.0, 2.0], [2.0, 3.0]]])
    )
    mean, cov = m.condition(np.array([3.0]))
    assert mean[0] == pytest.approx(2.0 + 0.5 * 2.0)
    assert cov[0, 0] == pytest.approx(3.0 - 2.0 * 2.0 / 4.0)


def test_mixture_far_from_one_component_follows_the_other():
    c = np.eye(2)
    m = DynamicsModel(
        ("x",),
        np.array([0.5, 0.5]),
        np.array([[-10.0, 1.0], [10.0, -1.0]]),
        np.stack([c, c]),
    )
    mean, _ = m.condition(np.array([[-10.0], [10.0], [0.0]]))
    np.testing.assert_allclose(mean[:, 0], [1.0, -1.0, 0.0], atol=1e-9)


def test_fit_recovers_linear_relation_with_torque():
    rng = np.random.default_rng(1)
    steps = rng.normal(size=(5000, 3)) * [1e-4, 1e-4, 1e-3]
    gain = np.diag([2e4, 3e4, 100.0])
    actions = steps @ gain.T + [0.5, 0.0, 0.01] + rng.normal(size=(5000, 3)) * 0.01
    m = fit_dynamics(steps, actions, ("x", "y", "rz"), rel_floor=0.0)
    pred = m.feedforward(np.array([[1e-4, 0.0, 0.0], [0.0, 0.0, 1e-3]]))
    np.testing.assert_allclose(pred[0], [2.5, 0.0, 0.01], atol=0.02)
    np.testing.assert_allclose(pred[1], [0.5, 0.0, 0.11], atol=0.02)


def test_bad_input():
    with pytest.raises(ModelError):
        fit_dynamics(np.zeros((10, 2)), np.ones((10, 2)), ("x", "y"))
    with pytest.raises(ModelError):
        fit_dynamics(np.ones((10, 2)), np.ones((9, 2)), ("x", "y"))
    m = DynamicsModel(("x",), np.ones(1), np.zeros((1, 2)), np.eye(2)[None])
    with pytest.raises(ModelError):
        m.condition(np.array([[np.nan]]))
