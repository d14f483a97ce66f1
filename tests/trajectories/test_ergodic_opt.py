import numpy as np
import pytest

from teachfit.core.errors import PlanningError
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.ergodic import CosineBasis, ergodic_trajectory, search_box
from teachfit.trajectories.ergodic_opt import ergodic_cost_and_gradient, optimise_ergodic


def _expl(d: int) -> ExplorationDistribution:
    dims = ("x", "y", "rz")[:d]
    cov = np.diag([1e-4, 4e-5, 0.04][:d])
    cov[0, 1] = cov[1, 0] = 2e-5
    mean = np.array([[0.01, -0.005, 0.1][:d]])
    return ExplorationDistribution(dims, np.ones(1), mean, cov[None])


@pytest.mark.parametrize("d", [2, 3])
def test_gradient_matches_finite_differences(d):
    ex = _expl(d)
    basis = CosineBasis(*search_box(ex), 8)
    phi = basis.distribution_coefficients(ex)
    x = ex.sample(30, np.random.default_rng(d))
    _, g = ergodic_cost_and_gradient(x, basis, phi)
    h = 1e-7
    for i, j in [(0, 0), (7, 1), (29, d - 1)]:
        xp, xm = x.copy(), x.copy()
        xp[i, j] += h
        xm[i, j] -= h
        e_p = ergodic_cost_and_gradient(xp, basis, phi)[0]
        e_m = ergodic_cost_and_gradient(xm, basis, phi)[0]
        assert (e_p - e_m) / (2 * h) == pytest.approx(g[i, j], rel=1e-4, abs=1e-9)


def test_optimisation_lowers_the_metric_keeps_start_and_length():
    ex = _expl(2)
    init = ergodic_trajectory(ex, speed=0.01, length=0.25)
    opt = optimise_ergodic(init, ex, speed=0.01, iterations=150)
    assert opt.method == "ergodic-opt"
    assert opt.meta["ergodic_metric"] < 0.5 * opt.meta["ergodic_metric_initial"]
    assert np.allclose(opt.states[0], init.states[0])
    assert opt.path_length() == pytest.approx(init.path_length(), rel=0.001)
    free = optimise_ergodic(init, ex, speed=0.01, iterations=150, keep_length=False)
    assert free.path_length() > 1.01 * init.path_length()  # the length a free optimiser takes
    with pytest.raises(PlanningError):
        optimise_ergodic(init, ex, speed=0.01, n_knots=4)
