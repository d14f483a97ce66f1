"""The Franka driver's tick compiled with numba: libfranka's state -> TCP state -> law -> torques.

Why: written in numpy, the tick (:mod:`teachfit.robot.franka.tick` has the equations) is ~60
small operations on 3- to 7-vectors, each a binding call. In the loop, woken by ``readOnce``
with cold caches, they took 250-350 µs per tick on a 2-core Intel Xeon and the 99th percentile
passed the 0.5 ms budget (BENCHMARKS.md, ``bench robot --robot franka``). Here they run as one
compiled call: the TCP kinematics, the measured wrench, the driver's motion limits, the law
(the control layer's compiled :func:`~teachfit.control.compiled.fixed_law` and
:func:`~teachfit.control.compiled.adapt`: the fixed-gain and adaptive laws the driver runs) and
the torque map. libfranka's own model calls (Jacobian, Coriolis) stay in Python: they are its
model library.

Buffers, all ``float64`` and allocated once by :class:`~teachfit.robot.franka.tick.TorqueTick`:

- ``raw``: libfranka's ``O_T_EE`` (16, column-major), the zero Jacobian of EE (42,
  column-major 6 x 7, base frame), ``q``, ``dq``, the Coriolis torques (7 each),
  ``O_F_ext_hat_K`` (6).
- ``geo``: base->world rotation (3, 3) and translation (3,), EE->TCP rotation (3, 3) and
  translation (3,), EE->K translation (3,), the workspace box grown by its margin (lo, hi).
- ``kin``: the TCP Jacobian (6, 7, base frame), TCP position (3,), rotation (3, 3),
  quaternion (4,) and twist ``[v; w]`` (6,) in the world, the K->TCP lever (3,, base frame),
  the measured wrench before and after the bias (6, 6), the bias (6,), scratch (6,), (3, 3).
- ``tq``: posture ``q_rest``, the last sent torques, the torques (7 each), the joint torque
  limits (7,), the clipped commanded wrench (6,), scratch (6,), (6, 6), (6,), (7,), (6,).
- ``fs``: the driver's scalars at the slots named below.

MuJoCo's ``mju_mat2Quat`` and its Cholesky routines are called through their addresses
(:func:`routines`), as the other kernels call theirs. numba caches the machine code on disk
keyed on this file: after an edit of the compiled laws, touch this file.
"""

from __future__ import annotations

import math
from functools import cache

import numba
import numpy as np
from numba.core import types

from teachfit.control import compiled as c
from teachfit.control.compiled import array_at as _at
from teachfit.robot.fr3 import kernel as k

# slots of ``fs``: posture gains, torque step per tick (N·m), motion limits (m/s, rad/s),
# the commanded wrench's caps (N, N·m)
K_NS, D_NS, TAU_STEP, V_MAX, W_MAX, F_MAX, T_MAX = range(7)
N_SCALARS = 7

#: what a tick found: torques ready, or the measured motion over one of the driver's limits
OK, TOO_FAST, TOO_FAST_ANGULAR, LEFT_WORKSPACE = range(4)

MAT2QUAT, CHOL_FACTOR, CHOL_SOLVE = 5, 9, 10
#: indices of the FR3 kernel's routines this kernel and the compiled laws call
USED = frozenset({MAT2QUAT, c.SUB_QUAT, c.ROT_VEC_QUAT, c.QUAT_INTEGRATE, CHOL_FACTOR, CHOL_SOLVE})
_DAMP = 1e-4  # lambda² of the damped null-space projection (well-posed near singularities)

# the buffers' shapes by group, in the order of the address table (:func:`table`)
_V3, _V6, _V7, _M3, _M6 = (3,), (6,), (7,), (3, 3), (6, 6)
RAW = ((16,), (42,), _V7, _V7, _V7, _V6)
GEO = (_M3, _V3, _M3, _V3, _V3, _V3, _V3)
KIN = ((6, 7), _V3, _M3, (4,), _V6, _V3, _V6, _V6, _V6, _V6, _M3)
LAW = (_M6, _M6, _V6, _V3, (4,), _V6, _V6, _V6, (4,), _V3, _V6)  # LawBinding.bufs
AD = (_V6,) * 14  # LawBinding.ad
TQ = (_V7, _V7, _V7, _V7, _V6, _V6, _M6, _V6, _V7, _V6)
GROUPS = (RAW, GEO, KIN, LAW, AD, ((c.N_SCALARS,),), TQ, ((N_SCALARS,),))
N_FNS = 13  # the table starts with the routines' addresses; it ends with the adaptive flag
_R, _G, _K, _L, _A, _SC, _T, _F = (N_FNS + sum(map(len, GROUPS[:i])) for i in range(8))
_ADAPTIVE = _F + 1


@cache
def routines() -> tuple[int, ...]:
    """The addresses of the FR3 kernel's routines this kernel calls; ``0`` for the others."""
    return tuple(c.c_address(f) if i in USED else 0 for i, f in enumerate(k.routines()))


@numba.njit(cache=True)
def kinematics(fns, raw, geo, kin) -> None:  # noqa: ANN001
    """TCP pose, twist and Jacobian, and the measured wrench, from libfranka's state.

    ``J_tcp = [J_v - [l]x J_w; J_w]`` for the EE->TCP lever ``l = R_ee p_et`` (base frame);
    ``x = R_wo (p_ee + l) + t_wo``, ``R = R_wo R_ee R_et``, ``[v; w] = R_wo J_tcp dq``. The
    wrench: libfranka's is the robot's on the environment at K, so ``f = -F``,
    ``tau = -T + r x f`` (``r`` the K->TCP lever), rotated into the world; then less the bias.
    """
    o_t_ee, zj, dq, ext = raw[0], raw[1], raw[3], raw[5]
    r_wo, t_wo, r_et, p_et, k_off = geo[0], geo[1], geo[2], geo[3], geo[4]
    jac, pos, rot, quat, twist, k_lever, measured, wrench, bias, v6, m3 = kin
    lever = v6[:3]
    for i in range(3):
        lever[i] = o_t_ee[i] * p_et[0] + o_t_ee[4 + i] * p_et[1] + o_t_ee[8 + i] * p_et[2]
        k_lever[i] = o_t_ee[i] * (k_off[0] - p_et[0]) + o_t_ee[4 + i] * (k_off[1] - p_et[1])
        k_lever[i] += o_t_ee[8 + i] * (k_off[2] - p_et[2])
        for j in range(3):  # R_tcp = R_ee R_et
            m3[i, j] = o_t_ee[i] * r_et[0, j] + o_t_ee[4 + i] * r_et[1, j]
            m3[i, j] += o_t_ee[8 + i] * r_et[2, j]
    for j in range(7):
        for i in range(6):
            jac[i, j] = zj[6 * j + i]
        wx, wy, wz = jac[3, j], jac[4, j], jac[5, j]
        jac[0, j] -= lever[1] * wz - lever[2] * wy  # v_tcp = v_ee + w x lever
        jac[1, j] -= lever[2] * wx - lever[0] * wz
        jac[2, j] -= lever[0] * wy - lever[1] * wx
    for i in range(3):
        lever[i] += o_t_ee[12 + i]  # now the TCP's position (base frame)
    for i in range(6):
        s = 0.0
        for j in range(7):
            s += jac[i, j] * dq[j]
        twist[i] = s  # base frame for now
    for i in range(3):
        pos[i] = t_wo[i]
        for j in range(3):
            pos[i] += r_wo[i, j] * lever[j]
            rot[i, j] = r_wo[i, 0] * m3[0, j] + r_wo[i, 1] * m3[1, j] + r_wo[i, 2] * m3[2, j]
    _rotate(r_wo, twist)
    c.call(fns[MAT2QUAT], (c.addr(quat), c.addr(rot)))
    f0, f1, f2 = -ext[0], -ext[1], -ext[2]
    r = k_lever
    measured[0], measured[1], measured[2] = f0, f1, f2
    measured[3] = -ext[3] + r[1] * f2 - r[2] * f1
    measured[4] = -ext[4] + r[2] * f0 - r[0] * f2
    measured[5] = -ext[5] + r[0] * f1 - r[1] * f0
    _rotate(r_wo, measured)
    for i in range(6):
        wrench[i] = measured[i] - bias[i]


@numba.njit(cache=True, inline="always")
def _rotate(rot, w) -> None:  # noqa: ANN001
    """``w[:3]``, ``w[3:]`` (6,) rotated by ``rot`` (3, 3) in place."""
    for lo in (0, 3):
        a, b, z = w[lo], w[lo + 1], w[lo + 2]
        for i in range(3):
            w[lo + i] = rot[i, 0] * a + rot[i, 1] * b + rot[i, 2] * z


@numba.njit(cache=True)
def check(geo, kin, fs) -> int:  # noqa: ANN001
    """Which of the driver's motion limits the measured TCP breaks (:data:`OK` if none); the
    Python :meth:`~teachfit.robot.franka.safety.FrankaLimits.check_motion` words it."""
    pos, twist = kin[1], kin[4]
    v = math.sqrt(twist[0] * twist[0] + twist[1] * twist[1] + twist[2] * twist[2])
    if v > fs[V_MAX]:
        return TOO_FAST
    w = math.sqrt(twist[3] * twist[3] + twist[4] * twist[4] + twist[5] * twist[5])
    if w > fs[W_MAX]:
        return TOO_FAST_ANGULAR
    lo, hi = geo[5], geo[6]
    for i in range(3):
        if not lo[i] <= pos[i] <= hi[i]:
            return LEFT_WORKSPACE
    return OK


@numba.njit(cache=True)
def torques(fns, raw, geo, kin, w, tq, fs) -> None:  # noqa: ANN001
    """``tau = J^T F + c + N (k_ns (q_rest - q) - d_ns dq)``, ``N = I - J^T (J J^T +
    lambda² I)^-1 J``, for the world wrench ``w`` (6,) clipped to the driver's caps, with ``F``
    it in base axes; then rate- and magnitude-limited against the last sent torques."""
    q, dq, cor, r_wo = raw[2], raw[3], raw[4], geo[0]
    jac = kin[0]
    q_rest, tau_prev, tau, tau_lim, w_cmd, f_base, jjt, y, post, z = tq
    w_cmd[:] = w
    c.clip_wrench(w_cmd, fs[F_MAX], fs[T_MAX])
    for lo in (0, 3):  # R_wo^T w
        for i in range(3):
            f_base[lo + i] = r_wo[0, i] * w_cmd[lo] + r_wo[1, i] * w_cmd[lo + 1]
            f_base[lo + i] += r_wo[2, i] * w_cmd[lo + 2]
    for j in range(7):
        post[j] = fs[K_NS] * (q_rest[j] - q[j]) - fs[D_NS] * dq[j]
    for i in range(6):
        s = 0.0
        for j in range(7):
            s += jac[i, j] * post[j]
        y[i] = s
        for m in range(6):
            s = 0.0
            for j in range(7):
                s += jac[i, j] * jac[m, j]
            jjt[i, m] = s + (_DAMP if i == m else 0.0)
    c.call(fns[CHOL_FACTOR], (c.addr(jjt), np.int32(6), 1e-12))
    c.call(fns[CHOL_SOLVE], (c.addr(z), c.addr(jjt), c.addr(y), np.int32(6)))
    step = fs[TAU_STEP]
    for j in range(7):
        s = cor[j] + post[j]
        for i in range(6):
            s += jac[i, j] * (f_base[i] - z[i])
        s = max(min(s, tau_prev[j] + step), tau_prev[j] - step)
        tau[j] = max(min(s, tau_lim[j]), -tau_lim[j])
        tau_prev[j] = tau[j]


@numba.njit(cache=True)
def tick(t, fns, raw, geo, kin, law, ad, adaptive, sc, tq, fs) -> int:  # noqa: ANN001
    """One whole tick with the compiled law (``law``, ``ad``, ``sc``: as
    :class:`~teachfit.control.compiled.LawBinding` holds them) at time ``t`` (s): the status of
    :func:`check`; the torques ``tq[2]`` are ready when it is :data:`OK`."""
    kinematics(fns, raw, geo, kin)
    status = check(geo, kin, fs)
    if status != OK:
        return status
    kmat, dmat, ff, xd, qd, vd, err, derr, qtmp, rtmp, w = law
    pos, quat, twist = kin[1], kin[3], kin[4]
    c.fixed_law(fns, t, pos, quat, twist, kmat, dmat, ff, xd, qd, vd, sc, err, derr, qtmp, rtmp, w)
    if adaptive:
        c.adapt(ad, err, derr, w, sc)
    torques(fns, raw, geo, kin, w, tq, fs)
    return OK


def table(
    raw: tuple[np.ndarray, ...],
    geo: tuple[np.ndarray, ...],
    kin: tuple[np.ndarray, ...],
    law: tuple[np.ndarray, ...],
    ad: tuple[np.ndarray, ...],
    sc: np.ndarray,
    tq: tuple[np.ndarray, ...],
    fs: np.ndarray,
    adaptive: bool,
) -> np.ndarray:
    """The address table (int64) of the buffers (shapes checked against :data:`GROUPS`) that
    :func:`tick_at`, :func:`kinematics_at` and :func:`torques_at` take. The arrays must stay
    alive, and be updated in place, as long as the table is used."""
    arrays = (*raw, *geo, *kin, *law, *ad, sc, *tq, fs)
    shapes = tuple(shape for group in GROUPS for shape in group)
    return np.array([*routines(), *c.addresses(arrays, shapes), int(adaptive)], dtype=np.int64)


@numba.njit(cache=True, inline="always")
def _groups(tb):  # noqa: ANN001, ANN202
    """The buffers of table ``tb`` as views, grouped as the functions above take them (numba
    types a tuple by its length: each is written out whole)."""
    r, g, k, q = _R, _G, _K, _T
    raw = (
        _at(tb[r], 16), _at(tb[r + 1], 42), _at(tb[r + 2], 7), _at(tb[r + 3], 7), _at(tb[r + 4], 7),
        _at(tb[r + 5], 6),
    )  # fmt: skip
    geo = (
        _at(tb[g], (3, 3)), _at(tb[g + 1], 3), _at(tb[g + 2], (3, 3)), _at(tb[g + 3], 3),
        _at(tb[g + 4], 3), _at(tb[g + 5], 3), _at(tb[g + 6], 3),
    )  # fmt: skip
    kin = (
        _at(tb[k], (6, 7)), _at(tb[k + 1], 3), _at(tb[k + 2], (3, 3)), _at(tb[k + 3], 4),
        _at(tb[k + 4], 6), _at(tb[k + 5], 3), _at(tb[k + 6], 6), _at(tb[k + 7], 6),
        _at(tb[k + 8], 6), _at(tb[k + 9], 6), _at(tb[k + 10], (3, 3)),
    )  # fmt: skip
    tq = (
        _at(tb[q], 7), _at(tb[q + 1], 7), _at(tb[q + 2], 7), _at(tb[q + 3], 7), _at(tb[q + 4], 6),
        _at(tb[q + 5], 6), _at(tb[q + 6], (6, 6)), _at(tb[q + 7], 6), _at(tb[q + 8], 7),
        _at(tb[q + 9], 6),
    )  # fmt: skip
    return tb[:N_FNS], raw, geo, kin, tq, _at(tb[_F], N_SCALARS)


@numba.njit(cache=True, inline="always")
def _law(tb):  # noqa: ANN001, ANN202
    """The law's buffers (``LawBinding.bufs``, ``.ad``) and scalars of table ``tb``."""
    m, a = _L, _A
    law = (
        _at(tb[m], (6, 6)), _at(tb[m + 1], (6, 6)), _at(tb[m + 2], 6), _at(tb[m + 3], 3),
        _at(tb[m + 4], 4), _at(tb[m + 5], 6), _at(tb[m + 6], 6), _at(tb[m + 7], 6),
        _at(tb[m + 8], 4), _at(tb[m + 9], 3), _at(tb[m + 10], 6),
    )  # fmt: skip
    ad = (
        _at(tb[a], 6), _at(tb[a + 1], 6), _at(tb[a + 2], 6), _at(tb[a + 3], 6), _at(tb[a + 4], 6),
        _at(tb[a + 5], 6), _at(tb[a + 6], 6), _at(tb[a + 7], 6), _at(tb[a + 8], 6),
        _at(tb[a + 9], 6), _at(tb[a + 10], 6), _at(tb[a + 11], 6), _at(tb[a + 12], 6),
        _at(tb[a + 13], 6),
    )  # fmt: skip
    return law, ad, _at(tb[_SC], c.N_SCALARS)


@numba.njit(cache=True)
def tick_at(t, tb) -> int:  # noqa: ANN001
    """:func:`tick` on the buffers of table ``tb`` (:func:`table`)."""
    fns, raw, geo, kin, tq, fs = _groups(tb)
    law, ad, sc = _law(tb)
    return tick(t, fns, raw, geo, kin, law, ad, tb[_ADAPTIVE] != 0, sc, tq, fs)


@numba.njit(cache=True)
def kinematics_at(tb) -> int:  # noqa: ANN001
    """:func:`kinematics`, then :func:`check`, on the buffers of table ``tb``."""
    fns, raw, geo, kin, tq, fs = _groups(tb)
    kinematics(fns, raw, geo, kin)
    return check(geo, kin, fs)


@numba.njit(cache=True)
def torques_at(tb, w) -> None:  # noqa: ANN001
    """:func:`torques` for the wrench ``w`` (6,) on the buffers of table ``tb``."""
    fns, raw, geo, kin, tq, fs = _groups(tb)
    torques(fns, raw, geo, kin, w, tq, fs)


def compile_entries() -> None:
    """Compile the entry points above for the argument types the driver passes, or load them
    from numba's cache, in the calling thread. Why: numba compiles on the first call, and a
    first call from the control thread would stall the 1 kHz loop for the compile (10-20 s on a
    busy 2-core machine: the robot's communication constraint, the driver's tick timeout)."""
    table, vector = types.Array(types.int64, 1, "C"), types.Array(types.float64, 1, "C")
    tick_at.compile((types.float64, table))
    kinematics_at.compile((table,))
    torques_at.compile((table, vector))
