"""The compiled adaptation (what the floating tool's kernel runs) is the Python law's."""

from __future__ import annotations

import mujoco
import numba
import numpy as np

from teachfit.control import compiled
from teachfit.control.adaptive import AdaptiveImpedance
from teachfit.core.control import ImpedanceLimits
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.fr3 import kernel

MASS = np.array([1.0, 1.0, 1.0, 0.004, 0.004, 0.004])


def _adaptive_terms(law: AdaptiveImpedance) -> tuple[np.ndarray, ...]:
    """The ``ad`` tuple of :func:`compiled.adapt`, with copies of the adapted state."""
    ad = (law._alpha, law._beta, law._gamma_a, law._gamma_b, law._kappa, law._df_step)
    ad += (law._dk_step, law._f_max, law._ff_adapt.copy(), law._k_adapt.copy(), law._k_room)
    return (*ad, law._k0_diag, law._sqrt_k0, law._sqrt_m2)


def test_compiled_adaptation_follows_the_python_law():
    limits = ImpedanceLimits(max_force=8.0, max_torque=0.5)
    law = AdaptiveImpedance(MASS, impedance_limits=limits, damping_ratio=0.7)
    cmd = ImpedanceCommand(
        pos=np.array([0.0, 0.0, 0.1]), stiffness=[500.0, 400.0, 300.0, 20.0, 20.0, 20.0]
    )
    law.set_command(cmd, 0.0)
    ad = _adaptive_terms(law)
    sc = np.zeros(compiled.N_SCALARS)
    sc[compiled.XI], sc[compiled.CLIP_F], sc[compiled.CLIP_T] = 0.7, 8.0, 0.5
    rng = np.random.default_rng(3)
    offset = np.array([0.004, -0.003, 0.002])  # a steady error: the law stiffens and pushes
    clipped = 0
    for tick in range(400):
        pos = cmd.pos + offset + rng.normal(0.0, 1e-4, 3)
        vel, spin = rng.normal(0.0, 1e-3, 3), rng.normal(0.0, 1e-2, 3)
        quat = np.array([1.0, *rng.normal(0.0, 1e-3, 3)])
        quat /= np.linalg.norm(quat)
        expected = law.compute(tick * 1e-3, pos, quat, vel, spin).copy()
        err, derr = law._error.err, law._error.derr
        w = law._k0 @ err + law._d0 @ derr + law._fd  # the fixed-gain part, not clipped
        compiled.adapt(ad, err, derr, w, sc)
        np.testing.assert_allclose(w, expected, rtol=1e-9, atol=1e-12)
        clipped += np.linalg.norm(expected[:3]) >= 8.0 - 1e-9
    np.testing.assert_allclose(ad[8], law.feedforward, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(ad[9], law.stiffness_adapt, rtol=1e-9, atol=1e-15)
    assert law.stiffness_adapt[:3].min() > 0  # it did adapt
    assert clipped > 0  # and the force limit was reached


@numba.njit
def _sub_quat(fn, res, qa, qb):  # noqa: ANN001, ANN202
    compiled.call(fn, (compiled.addr(res), compiled.addr(qa), compiled.addr(qb)))


def test_a_routine_by_address_is_the_ctypes_routine():
    """``call`` with an address (the floating kernel's) = with the ctypes routine (the FR3's)."""
    routine = kernel.routines()[compiled.SUB_QUAT]
    rng = np.random.default_rng(5)
    for _ in range(20):
        qa, qb = rng.normal(size=4), rng.normal(size=4)
        qa, qb = qa / np.linalg.norm(qa), qb / np.linalg.norm(qb)
        by_ctypes, by_address, reference = np.zeros(3), np.zeros(3), np.zeros(3)
        _sub_quat(routine, by_ctypes, qa, qb)
        _sub_quat(compiled.c_address(routine), by_address, qa, qb)
        mujoco.mju_subQuat(reference, qa, qb)
        assert by_address.tobytes() == by_ctypes.tobytes() == reference.tobytes()
