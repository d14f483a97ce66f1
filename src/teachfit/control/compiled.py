"""The control laws compiled with numba, written once for both simulated robots' kernels.

:func:`fixed_law` is the fixed-gain Cartesian impedance law of
:class:`~teachfit.control.impedance.CartesianImpedance` with the set-point extrapolation and
expiry of :class:`~teachfit.control.impedance.SetpointError`; :func:`adapt` is one period of
the adaptation of :class:`~teachfit.control.adaptive.AdaptiveImpedance` and its adaptive
terms (the module docstrings there have the equations). The FR3's compiled tick
(:mod:`teachfit.robot.fr3.kernel`) and the floating tool's (:mod:`teachfit.robot.floating_kernel`)
call them; the Python classes stay the reference (the real Franka's loop runs them, and the
FR3 runs the adaptive law in Python), and tests check that both give the same trajectories.

The kernels pass MuJoCo's quaternion routines in a tuple ``fns`` (at the indices
:data:`SUB_QUAT`, :data:`ROT_VEC_QUAT`, :data:`QUAT_INTEGRATE`) and the scalar state in one
array ``sc`` whose slots are named here, once, for both kernels.

numba caches the machine code on disk (``cache=True``) keyed on each function's own file: after
an edit here, touch the kernels' files (or clear their ``__pycache__``) so that they compile
these functions in again.
"""

from __future__ import annotations

import ctypes
import math

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic, overload

#: indices in the kernels' routine tuple ``fns`` of the MuJoCo routines the law calls
SUB_QUAT, ROT_VEC_QUAT, QUAT_INTEGRATE = 6, 7, 8

# slots of the scalar array ``sc`` shared by the kernels and the laws:
# the law's set-point clock (s) and wrench limits (N, N·m)
T0, EXPIRY, SPINNING, LAPSED, MAX_F, MAX_T = range(6)
# the FR3's torque map (null-space gains, torque step per tick) and sensing (filter constant,
# 1 / control period, wrist sensor or joint torques, index of the next noise sample)
K_NULL, D_NULL, DTAU, ALPHA, INV_DT, USE_FT, NOISE_I = range(6, 13)
# the timestep (s); the adaptive law's damping ratio and its real wrench limits
DT, XI, CLIP_F, CLIP_T = range(13, 17)
N_SCALARS = 17


@numba.njit(cache=True, inline="always")
def addr(a: np.ndarray) -> int:
    """The address of ``a``'s data, for a MuJoCo routine's pointer argument."""
    return a.ctypes.data


def c_address(fn: object) -> int:
    """The address of a ``ctypes`` routine, for :func:`call` (an ``int`` numba types in C)."""
    return int(ctypes.cast(fn, ctypes.c_void_p).value or 0)  # type: ignore[arg-type]


@intrinsic
def _call_address(typingctx, fn, args):  # noqa: ANN001, ANN202, ARG001
    """Call the C routine at address ``fn`` (an integer) with the tuple ``args``, ignoring
    what it returns; each argument is passed as its numba type (integers of pointer size for
    pointers, ``float64`` for ``double``, ``int32`` for ``int``)."""
    if not isinstance(fn, types.Integer) or not isinstance(args, types.BaseTuple):
        return None

    def codegen(context, builder, signature, llargs):  # noqa: ANN001, ANN202, ARG001
        fn_addr, tup = llargs
        argtys = [context.get_value_type(t) for t in args.types]
        fnty = ir.FunctionType(ir.VoidType(), argtys)
        ptr = builder.inttoptr(fn_addr, fnty.as_pointer())
        builder.call(ptr, [builder.extract_value(tup, i) for i in range(len(args.types))])
        return context.get_dummy_value()

    return types.none(fn, args), codegen


def call(fn, args) -> None:  # noqa: ANN001
    """``fn(*args)`` in compiled code, for ``fn`` a ``ctypes`` routine or an address from
    :func:`c_address`. Why addresses: numba types every ``ctypes`` routine of a call's
    arguments in Python (``ctypes.cast``, ~1.3 µs each, per 10 ms command), an integer in C.
    With an address nothing converts the arguments: the caller passes the C types."""


@overload(call, inline="always")
def _call_overload(fn, args):  # noqa: ANN001, ANN202
    if isinstance(fn, types.Integer):
        return lambda fn, args: _call_address(fn, args)
    return lambda fn, args: fn(*args)


@numba.njit(cache=True)
def fixed_law(fns, t, pos, quat, twist, kmat, dmat, ff, xd, qd, vd, sc, err, derr, qtmp, rtmp, w):  # noqa: ANN001, ANN201, E501
    """``w = K e + D de + f_ff``, clipped: :class:`teachfit.control.CartesianImpedance`."""
    dt = t - sc[T0]
    if t > sc[EXPIRY]:  # hold the set-point where the expired command left it
        dt = sc[EXPIRY] - sc[T0]
        for i in range(3):
            xd[i] += vd[i] * dt
        if sc[SPINNING] != 0.0:
            call(fns[QUAT_INTEGRATE], (addr(qd), addr(vd) + 24, dt))
        vd[:] = 0.0
        sc[SPINNING], sc[T0], sc[EXPIRY], sc[LAPSED] = 0.0, t, np.inf, 1.0
        dt = 0.0
    for i in range(3):
        err[i] = xd[i] - pos[i]
        err[i] += vd[i] * dt
    q_target = qd
    if sc[SPINNING] != 0.0:
        qtmp[:] = qd
        call(fns[QUAT_INTEGRATE], (addr(qtmp), addr(vd) + 24, dt))
        q_target = qtmp
    call(fns[SUB_QUAT], (addr(rtmp), addr(q_target), addr(quat)))
    call(fns[ROT_VEC_QUAT], (addr(err) + 24, addr(rtmp), addr(quat)))
    for i in range(6):
        derr[i] = vd[i] - twist[i]
    for i in range(6):
        s = 0.0
        for j in range(6):
            s += kmat[i, j] * err[j]
        r = 0.0
        for j in range(6):
            r += dmat[i, j] * derr[j]
        w[i] = s + r + ff[i]
    clip_wrench(w, sc[MAX_F], sc[MAX_T])


@numba.njit(cache=True, inline="always")
def clip_wrench(w, max_f, max_t) -> None:  # noqa: ANN001
    """Scale force and torque of ``w`` (6,) in place to norms of at most ``max_f``, ``max_t``."""
    for lo, cap in ((0, max_f), (3, max_t)):
        norm = np.sqrt(w[lo] * w[lo] + w[lo + 1] * w[lo + 1] + w[lo + 2] * w[lo + 2])
        if norm > cap:
            for i in range(lo, lo + 3):
                w[i] *= cap / norm


@numba.njit(cache=True)
def adapt(ad, err, derr, w, sc) -> None:  # noqa: ANN001
    """Adaptation of ``F_ff`` and ``K_a`` (one period) and the adaptive terms added to ``w``,
    then clipped to ``sc[CLIP_F]``, ``sc[CLIP_T]``: :class:`teachfit.control.AdaptiveImpedance`
    on top of :func:`fixed_law` run with the command's gains and no clipping.

    ``ad``: (alpha, beta, gamma_a, gamma_b, kappa, dF step, dK step, F_max, F_ff, K_a,
    K room, K_cmd diagonal, its square root, 2 sqrt m), all (6,).
    """
    alpha, beta, gamma_a, gamma_b, kappa, df_step, dk_step, f_max = ad[:8]
    ff, ka, k_room, k0, sqrt_k0, sqrt_m2 = ad[8:]
    xi = sc[XI]
    for i in range(6):
        eps = kappa[i] * err[i] + derr[i]
        step = min(max(alpha[i] * (eps - gamma_a[i] * ff[i]), -df_step[i]), df_step[i])
        ff[i] = min(max(ff[i] + step, -f_max[i]), f_max[i])
        dk = min(max(beta[i] * (eps * err[i] - gamma_b[i] * ka[i]), -dk_step[i]), dk_step[i])
        ka[i] = max(min(ka[i] + dk, k_room[i]), 0.0)
        damp = (math.sqrt(k0[i] + ka[i]) - sqrt_k0[i]) * sqrt_m2[i] * xi
        w[i] += ka[i] * err[i] + damp * derr[i] + ff[i]
    clip_wrench(w, sc[CLIP_F], sc[CLIP_T])
