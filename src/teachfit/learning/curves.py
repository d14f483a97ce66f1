"""Learning curves: best cost so far per trial, first feasible trial, bands over experiments.

For one experiment with trial costs ``c_1..c_n`` (in the order the trials finished; failures
at their penalised cost) the best-so-far curve is ``b_k = min(c_1..c_k)``. Over ``m``
experiments (curves padded with their last value to a common length) the band is the mean
and its two-sided 95 % confidence interval from Student's t:

    mean_k +- t_{0.975, m-1} * sd_k / sqrt(m)

(Johannsmeier et al. 2019, Fig. 6: mean per trial and the 95 % confidence interval). With one
experiment the band collapses onto the curve.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

from teachfit.core.params import LearningError


def best_so_far(costs: Sequence[float] | np.ndarray) -> np.ndarray:
    """``b_k = min(c_1..c_k)`` (n,); an empty input gives an empty curve."""
    arr = np.asarray(costs, dtype=float).reshape(-1)
    if arr.size and not np.all(np.isfinite(arr)):
        raise LearningError("trial costs must be finite (failures carry a penalty cost)")
    return np.minimum.accumulate(arr) if arr.size else arr


def first_feasible(feasible: Sequence[bool]) -> int | None:
    """1-based number of the first feasible trial, ``None`` if there is none."""
    for k, ok in enumerate(feasible, start=1):
        if ok:
            return k
    return None


def best_feasible_so_far(costs: Sequence[float], feasible: Sequence[bool]) -> np.ndarray:
    """Best cost among feasible trials so far (NaN until the first feasible one)."""
    arr = np.asarray(costs, dtype=float).reshape(-1)
    ok = np.asarray(feasible, dtype=bool).reshape(-1)
    if ok.shape != arr.shape:
        raise LearningError(f"{arr.size} costs but {ok.size} feasibility flags")
    return np.fmin.accumulate(np.where(ok, arr, np.nan)) if arr.size else arr


@dataclass(frozen=True)
class Band:
    """Mean curve with its 95 % confidence band over ``n`` experiments, trials 1..len."""

    mean: np.ndarray
    low: np.ndarray
    high: np.ndarray
    n: int

    @property
    def trials(self) -> np.ndarray:
        """Trial numbers 1..len (x axis)."""
        return np.arange(1, self.mean.size + 1)


def pad(curve: np.ndarray, length: int) -> np.ndarray:
    """``curve`` extended to ``length`` with its last value (a study that stopped early)."""
    if curve.size == 0:
        raise LearningError("cannot pad an empty curve")
    if curve.size >= length:
        return curve[:length]
    return np.concatenate([curve, np.full(length - curve.size, curve[-1])])


def band(curves: Sequence[Sequence[float] | np.ndarray], confidence: float = 0.95) -> Band:
    """Mean and ``confidence`` interval of the mean over experiments' curves."""
    arrays = [np.asarray(c, dtype=float).reshape(-1) for c in curves]
    arrays = [a for a in arrays if a.size]
    if not arrays:
        raise LearningError("a band needs at least one non-empty curve")
    if not 0 < confidence < 1:
        raise LearningError(f"confidence must be within (0, 1), got {confidence}")
    length = max(a.size for a in arrays)
    mat = np.vstack([pad(a, length) for a in arrays])
    m = mat.shape[0]
    mean = mat.mean(axis=0)
    if m < 2:
        return Band(mean, mean.copy(), mean.copy(), 1)
    half = stats.t.ppf(0.5 + confidence / 2, m - 1) * mat.std(axis=0, ddof=1) / np.sqrt(m)
    return Band(mean, mean - half, mean + half, m)
