import numpy as np
import pytest

from teachfit.core.errors import PlanningError
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.ergodic import (
    CosineBasis,
    ergodic_metric,
    ergodic_trajectory,
    search_box,
)


@pytest.fixture
def expl2():
    return ExplorationDistribution(
        ("x", "y"), np.ones(1), np.array([[0.01, 0.005]]), np.array([[[1e-4, 2e-5], [2e-5, 4e-5]]])
    )


@pytest.fixture
def expl3():
    return ExplorationDistribution(
        ("x", "y", "rz"),
        np.array([0.6, 0.4]),
        np.array([[0.01, 0.005, 0.05], [-0.01, 0.0, -0.1]]),
        np.stack([np.diag([1e-4, 4e-5, 0.01]), np.diag([4e-5, 4e-5, 4e-3])]),
    )


@pytest.mark.parametrize("which", ["expl2", "expl3"])
def test_fourier_coefficients_match_monte_carlo(which, request):
    e = request.getfixturevalue(which)
    lo, hi = search_box(e, n_sigma=1.5, margin=0.0)  # tight box: much mass outside, folded
    basis = CosineBasis(lo, hi, 6)
    phi = basis.distribution_coefficients(e)
    x = e.sample(400_000, np.random.default_rng(0))
    mc = basis.trajectory_coefficients(x)  # f_k is even and 2-periodic: folding is implicit
    assert np.abs(phi - mc).max() < 0.01
    assert phi.flat[0] == pytest.approx(1.0)  # φ_0 = ∫ p / h_0 = 1 on the unit box


def test_orthonormal_basis():
    basis = CosineBasis(np.zeros(2), np.array([2.0, 1.0]), 5)
    g = (np.arange(400) + 0.5) / 400
    u = np.stack(np.meshgrid(g * 2, g), -1).reshape(-1, 2)
    c = basis.trajectory_coefficients(u)  # coefficients of the uniform density
    expect = np.zeros((5, 5))
    expect[0, 0] = 1.0
    np.testing.assert_allclose(c, expect, atol=1e-4)


def test_metric_decreases_with_time_2d(expl2):
    tr = ergodic_trajectory(expl2, speed=0.01, length=0.5)
    np.testing.assert_allclose(tr.states[0], 0.0, atol=1e-12)
    speed = np.linalg.norm(np.diff(tr.states, axis=0), axis=1) / np.diff(tr.t)
    assert speed.max() < 0.0101
    e = [ergodic_metric(tr.states[: int(f * tr.t.size)], expl2) for f in (0.25, 0.5, 1.0)]
    assert e[0] > e[1] > e[2]
    assert tr.meta["ergodic_metric"] == pytest.approx(e[2], rel=0.05)
    # better coverage of p_e than a straight line of the same length
    line = np.linspace([0.0, 0.0], [0.03, 0.0], 500)
    assert ergodic_metric(line, expl2) > 10 * e[2]


def test_3d_trajectory_covers_rotation(expl3):
    tr = ergodic_trajectory(expl3, speed=0.01, length=0.6, angular_speed=0.1)
    assert tr.path_length(tr.meta["length_scale"]) == pytest.approx(0.6, rel=0.02)
    assert np.ptp(tr.states[:, 2]) > 0.3
    e_half = ergodic_metric(tr.states[: tr.t.size // 2], expl3)
    assert tr.meta["ergodic_metric"] < e_half
    lo, hi = tr.meta["box_lo"], tr.meta["box_hi"]
    assert np.all(tr.states >= np.array(lo) - 1e-9) and np.all(tr.states <= np.array(hi) + 1e-9)


def test_bad_input(expl2):
    with pytest.raises(PlanningError):
        ergodic_trajectory(expl2, speed=0.01)
    with pytest.raises(PlanningError):
        ergodic_trajectory(expl2, speed=0.0, length=1.0)
    with pytest.raises(PlanningError):
        ergodic_metric(np.zeros((10, 3)), expl2)
