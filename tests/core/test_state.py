import numpy as np
import pytest

from teachfit.core.errors import ControlError
from teachfit.core.state import ImpedanceCommand


def test_xy_block_gains_are_checked_like_any_matrix():
    """The closed-form test of an x-y block on a diagonal agrees with eigvalsh (seeded)."""
    rng = np.random.default_rng(0)
    for _ in range(200):
        k = np.diag(rng.uniform(0.0, 100.0, 6))
        k[0, 1] = k[1, 0] = rng.uniform(-80.0, 80.0)
        psd = np.linalg.eigvalsh(k).min() >= -1e-9 * np.abs(k).max()
        if psd:
            assert np.array_equal(ImpedanceCommand(pos=[0, 0, 0], stiffness=k).stiffness, k)
        else:
            with pytest.raises(ControlError, match="positive semi-definite"):
                ImpedanceCommand(pos=[0, 0, 0], stiffness=k)
