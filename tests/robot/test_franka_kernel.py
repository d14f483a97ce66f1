"""The Franka driver's compiled torque map on hand-made buffers: the driver's limits."""

from __future__ import annotations

import numpy as np

from teachfit.control.compiled import N_SCALARS as LAW_SCALARS
from teachfit.robot.franka import FrankaLimits
from teachfit.robot.franka import kernel as k


def _table(limits: FrankaLimits) -> tuple[np.ndarray, tuple, tuple, tuple]:
    """A table whose Jacobian is zero and posture gains are zero: ``tau = c`` before limits."""
    raw, geo, kin, law, ad, tq = (
        tuple(np.zeros(shape) for shape in group)
        for group in (k.RAW, k.GEO, k.KIN, k.LAW, k.AD, k.TQ)
    )
    geo[0][:] = np.eye(3)
    tq[3][:] = limits.joint_torque_limits
    fs = np.zeros(k.N_SCALARS)
    fs[k.TAU_STEP] = limits.max_torque_rate * 0.001
    fs[k.F_MAX], fs[k.T_MAX] = limits.max_force, limits.max_torque
    tb = k.table(raw, geo, kin, law, ad, np.zeros(LAW_SCALARS), tq, fs, adaptive=False)
    return tb, raw, tq, (geo, kin, law, ad, fs)  # the arrays the table points at, kept alive


def test_torques_are_rate_limited_then_clipped_to_the_joints_limits() -> None:
    tb, raw, tq, _keep = _table(FrankaLimits())
    raw[4][:] = 50.0  # the Coriolis term alone
    k.torques_at(tb, np.zeros(6))
    np.testing.assert_allclose(tq[2], 1.0)  # 1000 N·m/s over 1 ms from zero
    np.testing.assert_allclose(tq[1], tq[2])  # the next tick's start
    tq[1][:] = [86.5, 0, 0, 0, 12, 0, 0]
    raw[4][:] = [100.0, 0, 0, 0, 20.0, 0, 0]
    k.torques_at(tb, np.zeros(6))
    np.testing.assert_allclose(tq[2][[0, 4]], [87.0, 12.0])


def test_the_commanded_wrench_is_scaled_to_the_caps_keeping_its_direction() -> None:
    tb, _raw, tq, _keep = _table(FrankaLimits(max_force=10.0, max_torque=1.0))
    k.torques_at(tb, np.array([30.0, 40.0, 0, 0, 0, 3.0]))
    np.testing.assert_allclose(tq[4], [6.0, 8.0, 0, 0, 0, 1.0])


def test_a_buffer_of_the_wrong_shape_is_refused() -> None:
    import pytest

    raw, geo, kin, law, ad, tq = (
        tuple(np.zeros(shape) for shape in group)
        for group in (k.RAW, k.GEO, k.KIN, k.LAW, k.AD, k.TQ)
    )
    with pytest.raises(ValueError, match="float64"):
        k.table(raw, geo, kin, law, ad, np.zeros(3), tq, np.zeros(k.N_SCALARS), adaptive=False)
