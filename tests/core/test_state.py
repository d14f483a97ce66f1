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


def _rotated(rng: np.random.Generator, k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``B diag(k) B^T`` for a random rotation ``B`` per 3-block, as the engine builds it."""
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    out = np.zeros((6, 6))
    out[:3, :3] = (q * k[:3]) @ q.T
    out[3:, 3:] = (q * k[3:]) @ q.T
    return out, q


def test_a_task_frame_diagonal_command_is_the_checked_one():
    """``from_diagonal_frame`` skips only checks its construction makes true: same values as
    the checked constructor (seeded), and bad values still raise the constructor's errors."""
    rng = np.random.default_rng(1)
    for _ in range(50):
        k = rng.uniform(0.0, 3000.0, 6)
        stiff, q = _rotated(rng, k)
        quat = rng.normal(size=4)
        quat *= (1.0 + rng.uniform(-5e-4, 5e-4)) / np.linalg.norm(quat)  # nearly unit
        args = [rng.normal(size=3), quat, rng.normal(size=3), rng.normal(size=3)]
        args += [rng.normal(size=6), stiff]
        fast = ImpedanceCommand.from_diagonal_frame(*args, k)
        slow = ImpedanceCommand(*args)
        for name in ("pos", "quat", "lin_vel", "ang_vel", "wrench_ff", "stiffness"):
            a, b = getattr(fast, name), getattr(slow, name)
            assert np.array_equal(a, b) and not a.flags.writeable
        assert (fast.damping, fast.damping_ratio, fast.expires_after) == (None, 1.0, 0.25)
        assert fast.stiffness is stiff  # taken over, not copied: now read-only for all
        with pytest.raises(ValueError, match="read-only"):
            stiff[0, 0] = -1.0
    good = [np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros(3), np.zeros(3), np.zeros(6)]
    k = np.full(6, 100.0)
    with pytest.raises(ControlError, match="pos contains NaN"):
        ImpedanceCommand.from_diagonal_frame(np.array([0, np.nan, 0]), *good[1:], np.diag(k), k)
    with pytest.raises(ControlError, match="unit norm"):
        bad = [good[0], np.array([2.0, 0, 0, 0]), *good[2:]]
        ImpedanceCommand.from_diagonal_frame(*bad, np.diag(k), k)
    neg = np.array([100.0, -5.0, 100.0, 10.0, 10.0, 10.0])
    with pytest.raises(ControlError, match="positive semi-definite"):
        ImpedanceCommand.from_diagonal_frame(*good, np.diag(neg), neg)
