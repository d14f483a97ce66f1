"""Learning curves: best so far, first feasible trial, mean and 95 % band over experiments."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from teachfit.learning import LearningError
from teachfit.learning.curves import band, best_feasible_so_far, best_so_far, first_feasible, pad


def test_best_so_far_and_first_feasible() -> None:
    costs = [9.0, 7.5, 8.0, 1.2, 3.0, 0.9]
    assert best_so_far(costs).tolist() == [9.0, 7.5, 7.5, 1.2, 1.2, 0.9]
    feas = [False, False, True, True, False, True]
    assert first_feasible(feas) == 3
    assert first_feasible([False, False]) is None
    got = best_feasible_so_far(costs, feas)
    assert np.isnan(got[:2]).all() and got[2:].tolist() == [8.0, 1.2, 1.2, 0.9]
    with pytest.raises(LearningError, match="finite"):
        best_so_far([1.0, float("nan")])
    with pytest.raises(LearningError, match="3 costs but 2"):
        best_feasible_so_far([1.0, 2.0, 3.0], [True, False])


def test_band_is_the_t_interval_of_the_mean_and_pads_short_runs() -> None:
    rng = np.random.default_rng(3)
    curves = [best_so_far(rng.uniform(0.5, 2.0, 20)) for _ in range(5)]
    curves.append(curves[0][:12])  # a run that stopped early keeps its last value
    b = band(curves)
    mat = np.vstack([pad(c, 20) for c in curves])
    assert b.n == 6 and b.mean.shape == (20,) and b.trials[-1] == 20
    assert np.allclose(b.mean, mat.mean(axis=0))
    half = stats.t.ppf(0.975, 5) * mat.std(axis=0, ddof=1) / np.sqrt(6)
    assert np.allclose(b.high - b.mean, half) and np.allclose(b.mean - b.low, half)
    assert np.all(np.diff(b.mean) <= 1e-12)  # a mean of non-increasing curves
    one = band([curves[1]])
    assert one.n == 1 and np.array_equal(one.low, one.high)
    with pytest.raises(LearningError, match="at least one"):
        band([[]])
