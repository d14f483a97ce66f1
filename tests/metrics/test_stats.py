import numpy as np
import pytest

from teachfit.core.errors import TeachfitError
from teachfit.metrics.stats import paired_sign_test, summarize, wilson_interval


def test_wilson_known_values():
    lo, hi = wilson_interval(25, 30)
    assert lo == pytest.approx(0.6644, abs=1e-3)
    assert hi == pytest.approx(0.9266, abs=1e-3)
    assert wilson_interval(0, 10)[0] == 0.0
    assert wilson_interval(10, 10)[1] == pytest.approx(1.0)
    with pytest.raises(TeachfitError):
        wilson_interval(3, 0)


def test_summary():
    s = summarize([True, False, True], [1.0, np.nan, 3.0])
    assert s.successes == 2 and s.trials == 3 and s.median_time == 2.0
    assert "2/3" in str(s)


def test_paired_sign_test_counts_only_discordant_pairs():
    # 5 pairs where only "with" succeeded, 1 where only "without" did, 4 ties (both/neither)
    a = [True] * 5 + [False] + [True, True, False, False]
    b = [False] * 5 + [True] + [True, True, False, False]
    n_ab, n_ba, p = paired_sign_test(a, b)
    assert (n_ab, n_ba) == (5, 1)
    assert p == pytest.approx(2 * 7 / 64)  # 2 * P(X <= 1), X ~ Binomial(6, 1/2)
    assert paired_sign_test(b, a)[:2] == (1, 5) and paired_sign_test(b, a)[2] == pytest.approx(p)
    assert paired_sign_test([True, False], [True, False]) == (0, 0, 1.0)
    with pytest.raises(TeachfitError, match="pairs"):
        paired_sign_test([True], [True, False])
