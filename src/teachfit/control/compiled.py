"""The control laws compiled with numba, written once for both simulated robots' kernels.

:func:`fixed_law` is the fixed-gain Cartesian impedance law of
:class:`~teachfit.control.impedance.CartesianImpedance` with the set-point extrapolation and
expiry of :class:`~teachfit.control.impedance.SetpointError`; :func:`adapt` is one period of
the adaptation of :class:`~teachfit.control.adaptive.AdaptiveImpedance` and its adaptive
terms (the module docstrings there have the equations). The FR3's compiled tick
(:mod:`teachfit.robot.fr3.kernel`) and the floating tool's (:mod:`teachfit.robot.floating_kernel`)
call them; the Python classes stay the reference (the real Franka's loop runs them, and the
FR3 runs the adaptive law in Python), and tests check that both give the same trajectories.

:class:`LawBinding` hands a law object's own buffers and scalar state to them, for every
kernel that runs a law compiled (the floating tool's, the Franka driver's).

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
from typing import TypeGuard

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic, overload

from teachfit.control.adaptive import AdaptiveImpedance
from teachfit.control.impedance import CartesianImpedance

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


@intrinsic
def _f64_pointer(typingctx, address):  # noqa: ANN001, ANN202, ARG001
    """``(double *) address``, for ``numba.carray``."""
    if not isinstance(address, types.Integer):
        return None
    ptr = types.CPointer(types.float64)

    def codegen(context, builder, signature, llargs):  # noqa: ANN001, ANN202, ARG001
        return builder.inttoptr(llargs[0], context.get_value_type(ptr))

    return ptr(address), codegen


@numba.njit(cache=True, inline="always")
def array_at(address, shape):  # noqa: ANN001, ANN201
    """The C-contiguous ``float64`` array of ``shape`` whose data is at ``address`` (an integer
    from :func:`addresses`): no copy; the array there must outlive the view."""
    return numba.carray(_f64_pointer(address), shape)


def addresses(arrays: tuple[np.ndarray, ...], shapes: tuple[tuple[int, ...], ...]) -> list[int]:
    """The data addresses of ``arrays``, each checked to be C-contiguous ``float64`` of its
    shape in ``shapes``, for a kernel that takes one table of addresses (:func:`array_at`) instead
    of the arrays. Why: numba's dispatcher types and unboxes every array argument, ~0.17 µs
    each; a kernel that takes 45 arrays pays 8 µs per call before it starts, a table 0.3 µs."""
    if len(arrays) != len(shapes):
        raise ValueError(f"{len(arrays)} arrays for {len(shapes)} shapes")
    out = []
    for i, (a, shape) in enumerate(zip(arrays, shapes, strict=True)):
        if a.dtype != np.float64 or a.shape != shape or not a.flags.c_contiguous:
            raise ValueError(f"array {i}: {a.dtype} {a.shape}, the kernel takes float64 {shape}")
        out.append(a.ctypes.data)
    return out


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


class LawBinding:
    """A fixed-gain or adaptive law's own buffers, in the order :func:`fixed_law` (``bufs``:
    K, D, f, x_d, q_d, v_d, e, de, q scratch, r scratch, wrench) and :func:`adapt` (``ad``)
    take them: a compiled tick updates them in place, so the law object holds what its Python
    :meth:`compute` would. The scalar state (set-point clock, limits, damping ratio) goes
    through ``sc``: :meth:`load` before a compiled run, :meth:`store` after.

    For the adaptive law ``fixed_law`` runs with the command's ``K``, ``D`` and ``F_d`` and no
    clipping (``sc[MAX_F] = sc[MAX_T] = inf``); :func:`adapt` adds its terms and clips to the
    law's limits (``sc[CLIP_F]``, ``sc[CLIP_T]``).
    """

    def __init__(self, law: AdaptiveImpedance | CartesianImpedance) -> None:
        self.law = law
        self.adaptive = isinstance(law, AdaptiveImpedance)
        e = law._error  # the law's own buffers
        bufs = (e._xd, e._qd, e._vd, e.err, e.derr, e._qtmp, e._rtmp, np.zeros(6))
        self.bufs: tuple[np.ndarray, ...]
        self.ad: tuple[np.ndarray, ...]
        if isinstance(law, AdaptiveImpedance):
            self.bufs = (law._k0, law._d0, law._fd, *bufs)
            self.ad = (law._alpha, law._beta, law._gamma_a, law._gamma_b, law._kappa)
            self.ad += (law._df_step, law._dk_step, law._f_max, law._ff_adapt, law._k_adapt)
            self.ad += (law._k_room, law._k0_diag, law._sqrt_k0, law._sqrt_m2)
        else:
            self.bufs = (law._k, law._d, law._ff, *bufs)
            self.ad = (np.zeros(6),) * 14

    @staticmethod
    def supports(law: object) -> TypeGuard[AdaptiveImpedance | CartesianImpedance]:
        """Whether ``law`` runs compiled: exactly one of the two laws of :mod:`teachfit.control`
        (a subclass may change :meth:`compute`)."""
        return type(law) in (AdaptiveImpedance, CartesianImpedance)

    @property
    def wrench(self) -> np.ndarray:
        """The buffer the compiled law writes its wrench (6,) into."""
        return self.bufs[-1]

    def load(self, sc: np.ndarray) -> None:
        """The law's scalar state into ``sc``."""
        law = self.law
        e = law._error
        sc[T0], sc[EXPIRY] = e._t0, e._expiry
        sc[SPINNING], sc[LAPSED] = float(e._spinning), float(e.lapsed)
        if isinstance(law, AdaptiveImpedance):
            lim = law.impedance_limits
            sc[MAX_F] = sc[MAX_T] = np.inf
            sc[CLIP_F], sc[CLIP_T], sc[XI] = lim.max_force, lim.max_torque, law._xi
        else:
            sc[MAX_F], sc[MAX_T] = law.limits.max_force, law.limits.max_torque

    def store(self, sc: np.ndarray) -> None:
        """The set-point clock back from ``sc`` into the law, and its last wrench."""
        e = self.law._error
        e._t0, e._expiry = float(sc[T0]), float(sc[EXPIRY])
        e._spinning, e.lapsed = bool(sc[SPINNING]), bool(sc[LAPSED])
        self.law.last_wrench = self.bufs[-1].copy()
