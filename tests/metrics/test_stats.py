import numpy as np
import pytest

from teachfit.core.errors import TeachfitError
from teachfit.metrics.stats import summarize, wilson_interval


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
