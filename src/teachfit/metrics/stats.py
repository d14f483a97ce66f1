"""Success statistics with honest uncertainty."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.stats import binomtest, norm

from teachfit.core.errors import TeachfitError


def wilson_interval(successes: int, trials: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval for a binomial success rate.

    ``(p + z²/2n ± z sqrt(p(1-p)/n + z²/4n²)) / (1 + z²/n)`` with ``p = successes / trials``.
    """
    if trials <= 0:
        raise TeachfitError("wilson_interval needs at least one trial")
    if not 0 <= successes <= trials:
        raise TeachfitError(f"successes must be within [0, {trials}], got {successes}")
    z = float(norm.ppf(0.5 + confidence / 2))
    p = successes / trials
    denom = 1 + z * z / trials
    centre = (p + z * z / (2 * trials)) / denom
    half = z * np.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def paired_sign_test(a: Sequence[bool], b: Sequence[bool]) -> tuple[int, int, float]:
    """Exact two-sided sign test of paired successes ``a`` against ``b`` (same seeds).

    Only the discordant pairs count: ``n_ab`` (``a`` succeeded, ``b`` did not) and ``n_ba``;
    under the null hypothesis each is Binomial(n_ab + n_ba, 1/2) (McNemar's exact test).
    Returns ``(n_ab, n_ba, p)``; ``p`` is 1 without a discordant pair.
    """
    if len(a) != len(b):
        raise TeachfitError(f"paired_sign_test needs pairs: {len(a)} against {len(b)} outcomes")
    n_ab = sum(1 for x, y in zip(a, b, strict=True) if x and not y)
    n_ba = sum(1 for x, y in zip(a, b, strict=True) if y and not x)
    if n_ab + n_ba == 0:
        return 0, 0, 1.0
    return n_ab, n_ba, float(binomtest(n_ab, n_ab + n_ba, 0.5).pvalue)


@dataclass(frozen=True)
class SuccessSummary:
    """Success count, Wilson 95 % interval and median time to insertion (s) of a batch."""

    successes: int
    trials: int
    low: float
    high: float
    median_time: float

    @property
    def rate(self) -> float:
        return self.successes / self.trials

    def __str__(self) -> str:
        t = "n/a" if np.isnan(self.median_time) else f"{self.median_time:.2f} s"
        return (
            f"{self.successes}/{self.trials} = {100 * self.rate:.0f} % "
            f"[{100 * self.low:.0f}, {100 * self.high:.0f}] %, median time {t}"
        )


def summarize(successes: Sequence[bool], times: Sequence[float]) -> SuccessSummary:
    """Summarise a batch of outcomes (``times`` of the successful ones are used)."""
    ok = np.asarray(successes, dtype=bool)
    ts = np.asarray(times, dtype=float)[ok]
    lo, hi = wilson_interval(int(ok.sum()), int(ok.size))
    med = float(np.median(ts)) if ts.size else float("nan")
    return SuccessSummary(int(ok.sum()), int(ok.size), lo, hi, med)
