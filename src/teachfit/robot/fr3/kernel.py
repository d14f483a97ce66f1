"""The FR3's 1 kHz tick compiled with numba: no Python between ``mj_step1`` and ``mj_step2``.

Why: the tick is ~40 small operations (Jacobian, Cartesian law, ``J^T F``, null-space
projector, rate and magnitude limits, the momentum observer) on 6- and 7-vectors. From Python
each costs a binding call (0.5-4 µs on the project's machine), together more than the physics
step itself. Here they run as one compiled loop that calls MuJoCo's own C routines
(``mj_step1``/``mj_step2``, ``mj_jacSite``, ``mj_solveM``, ``mj_mulM``, ``mju_*`` quaternion and
Cholesky routines) through ``ctypes`` on the very ``libmujoco`` the bindings loaded, with the
model and data pointers of the Python objects; the arithmetic between them is plain loops.
numba caches the machine code on disk (``cache=True``), so only the first process compiles.

The law and the torque map are those of :mod:`teachfit.robot.fr3.control` (the module
docstring there has the equations); the fixed-gain Cartesian law is the compiled
:func:`teachfit.control.compiled.fixed_law` (the one of
:class:`teachfit.control.CartesianImpedance`, set-point extrapolation and expiry included),
called here so that a whole :meth:`FR3Robot.step` of ``n`` ticks is one call; a test checks
both give the same torques. Other laws (the adaptive one) run in Python between
:func:`tick_pre` and :func:`tick_post`. The scalar slots of ``sc`` are named once in
:mod:`teachfit.control.compiled` (re-exported here); numba's cache is keyed on this file only:
after an edit there, touch this file so that the law is compiled in again.
"""

from __future__ import annotations

import ctypes
from functools import cache
from pathlib import Path

import mujoco
import numba
import numpy as np

# the scalar slots of ``sc`` (one layout for both kernels, in the control layer); the FR3's
# modules read them here: T0 ... MAX_T and the law are :mod:`teachfit.control.compiled`'s
from teachfit.control.compiled import (  # noqa: F401
    ALPHA,
    D_NULL,
    DT,
    DTAU,
    EXPIRY,
    INV_DT,
    K_NULL,
    LAPSED,
    MAX_F,
    MAX_T,
    N_SCALARS,
    NOISE_I,
    SPINNING,
    T0,
    USE_FT,
    fixed_law,
)
from teachfit.control.compiled import addr as _addr
from teachfit.core.errors import TeachfitError

_P = ctypes.c_size_t  # pointers travel as integers (same register as a pointer on x86-64 / arm64)


@cache
def _libmujoco() -> ctypes.CDLL:
    """The shared library the ``mujoco`` bindings loaded (dlopen returns that instance)."""
    folder = Path(mujoco.__file__).parent
    libs = sorted(folder.glob("libmujoco*.so*")) + sorted(folder.glob("libmujoco*.dylib"))
    if not libs:
        raise TeachfitError(f"no libmujoco shared library next to the bindings in {folder}")
    return ctypes.CDLL(str(libs[0]))


@cache
def _timer_hook() -> ctypes.c_void_p:
    """MuJoCo's global profiling hook ``mjcb_time`` (a function pointer in ``libmujoco``)."""
    return ctypes.c_void_p.in_dll(_libmujoco(), "mjcb_time")


class untimed:  # noqa: N801 (a context used as ``with untimed():``, like a function)
    """MuJoCo's profiling timers off inside the context, the hook restored after it.

    The Python bindings set ``mjcb_time`` to a clock, which ``mj_step`` reads twice per stage
    it times (``clock_gettime`` through the bindings' callback): 4-5 % of a learning
    execution's CPU, for ``MjData.timer`` durations that nothing here reads. With the hook
    NULL MuJoCo skips the clock (the timers' call counts still go up); the physics is the
    same."""

    __slots__ = ("_saved",)

    def __enter__(self) -> None:
        hook = _timer_hook()
        self._saved = hook.value
        hook.value = None

    def __exit__(self, *exc: object) -> None:
        _timer_hook().value = self._saved


def _fn(name: str, *argtypes: object, restype: object = None) -> object:
    fn = getattr(_libmujoco(), name)
    fn.argtypes, fn.restype = list(argtypes), restype
    return fn


@cache
def routines() -> tuple:
    """The MuJoCo C routines the kernel calls, in the order the kernel's ``fns`` takes them
    (the law's quaternion routines at :mod:`teachfit.control.compiled`'s ``SUB_QUAT``,
    ``ROT_VEC_QUAT`` and ``QUAT_INTEGRATE``)."""
    i, d = ctypes.c_int, ctypes.c_double
    return (
        _fn("mj_step1", _P, _P),
        _fn("mj_step2", _P, _P),
        _fn("mj_jacSite", _P, _P, _P, _P, i),
        _fn("mj_solveM", _P, _P, _P, _P, i),
        _fn("mj_mulM", _P, _P, _P, _P),
        _fn("mju_mat2Quat", _P, _P),
        _fn("mju_subQuat", _P, _P, _P),
        _fn("mju_rotVecQuat", _P, _P, _P),
        _fn("mju_quatIntegrate", _P, _P, d),
        _fn("mju_cholFactor", _P, i, d, restype=i),
        _fn("mju_cholSolve", _P, _P, _P, i),
        _clock(),
        _fn("mj_step", _P, _P),
    )


def _clock() -> object:
    """libc's ``clock_gettime`` (timing the law per tick inside the compiled loop)."""
    fn = ctypes.CDLL(None).clock_gettime
    fn.argtypes, fn.restype = [ctypes.c_int, _P], ctypes.c_int
    return fn


_MONOTONIC = 1  # CLOCK_MONOTONIC on Linux


# status codes returned with the number of ticks done
OK, LIMIT, NOISE_EMPTY = 0, 1, 2


def data_views(data: mujoco.MjData, site: int) -> tuple[np.ndarray, ...]:
    """The MjData views every kernel reads (``dat``): qpos, qvel, qfrc_bias, ctrl, sensordata,
    the TCP ``site``'s xmat and xpos, qfrc_passive."""
    return (
        data.qpos,
        data.qvel,
        data.qfrc_bias,
        data.ctrl,
        data.sensordata,
        data.site_xmat[site],
        data.site_xpos[site],
        data.qfrc_passive,
    )


@numba.njit(cache=True, inline="always")
def stribeck(qvel, passive, drop, inv_vs) -> None:  # noqa: ANN001
    """Between ``mj_step1`` and ``mj_step2``: the joints' Stribeck decay, a passive torque
    ``drop (1 - exp(-(dq / v_s)^2)) sign(dq)`` (N·m) along each joint's motion, added to
    ``qfrc_passive`` (which ``mj_step1`` has just computed). With ``frictionloss`` at the static
    level ``F_s`` and ``drop = F_s - F_c`` the sliding friction is the Stribeck curve
    (:mod:`teachfit.robot.fr3.model`). ``inv_vs``: ``1 / v_s`` (s/rad) per joint."""
    for j in range(qvel.shape[0]):
        x = qvel[j] * inv_vs[j]
        push = drop[j] * (1.0 - np.exp(-x * x))
        passive[j] += push if x > 0.0 else -push


@numba.njit(cache=True)
def step_physics(fns, m, d, dat, joints) -> None:  # noqa: ANN001
    """One physics step with the joints' Stribeck term: ``mj_step1``, :func:`stribeck`,
    ``mj_step2`` (``ctrl`` as it stands). ``joints``: as :func:`run_fixed`'s ``lim``."""
    fns[0](m, d)
    stribeck(dat[1], dat[7], joints[3], joints[4])
    fns[1](m, d)


@numba.njit(cache=True)
def kinematics(fns, m, d, site, jac, xmat, quat, twist, qvel):  # noqa: ANN001, ANN201
    """TCP Jacobian (world, rows ``[v; w]``), orientation and twist from current kinematics."""
    nv = jac.shape[1]
    fns[2](m, d, _addr(jac), _addr(jac) + 24 * nv, site)
    fns[5](_addr(quat), _addr(xmat))
    for i in range(6):
        s = 0.0
        for j in range(nv):
            s += jac[i, j] * qvel[j]
        twist[i] = s


@numba.njit(cache=True)
def torques(fns, m, d, w, dat, ctl, sc):  # noqa: ANN001, ANN201
    """``tau = J^T w + c + N^T tau_0``, rate- then magnitude-limited (see ``control``).

    ``dat``: the MjData views (qpos, qvel, qfrc_bias, ctrl, sensordata, TCP xmat, TCP xpos);
    ``ctl``: (J, J M^-1, Lambda^-1, q_null, tau_prev, tau_max, tau, tau_0, y, z) buffers.
    """
    qpos, qvel, bias = dat[0], dat[1], dat[2]
    jac, jminv, lam, q_null, tau_prev, tau_max, tau, tau0, y, z = ctl
    nv = jac.shape[1]
    for j in range(nv):
        s = 0.0
        for i in range(6):
            s += jac[i, j] * w[i]
        tau[j] = s + bias[j]
    if sc[K_NULL] > 0.0 or sc[D_NULL] > 0.0:
        for j in range(nv):
            tau0[j] = (q_null[j] - qpos[j]) * sc[K_NULL] + qvel[j] * -sc[D_NULL]
        fns[3](m, d, _addr(jminv), _addr(jac), 6)  # rows of J M^-1
        for i in range(6):
            for k in range(6):
                s = 0.0
                for j in range(nv):
                    s += jminv[i, j] * jac[k, j]
                lam[i, k] = s
        fns[9](_addr(lam), 6, 1e-10)
        for i in range(6):
            s = 0.0
            for j in range(nv):
                s += jminv[i, j] * tau0[j]
            y[i] = s
        fns[10](_addr(z), _addr(lam), _addr(y), 6)  # Lambda J M^-1 tau_0
        for j in range(nv):
            s = 0.0
            for i in range(6):
                s += jac[i, j] * z[i]
            tau[j] += tau0[j] - s
    step = sc[DTAU]
    for j in range(nv):
        delta = min(max(tau[j] - tau_prev[j], -step), step)
        tau[j] = min(max(tau_prev[j] + delta, -tau_max[j]), tau_max[j])
        tau_prev[j] = tau[j]


@numba.njit(cache=True)
def observe(fns, m, d, dat, obs, sc):  # noqa: ANN001, ANN201
    """After ``mj_step2``: the momentum observer on the joint torque sensors, or the wrist
    F/T filter (see ``sensing``). ``qM``, ``qfrc_bias`` still hold the step's start values.

    Either estimate then passes the output low-pass (second-order Butterworth, ``coef``,
    :mod:`teachfit.robot.sensor_filter`) into ``out`` (states ``z``, (2, n)).

    ``obs``: (dq_prev, ddq, M ddq, sensor addresses, joint axes, armature, noise block,
    tau_ext, wrist sensor address, wrist filter state, coef, tau out, tau z, ft out, ft z).
    """
    qvel, bias, sdata = dat[1], dat[2], dat[4]
    dq_prev, ddq, mddq, tj_adr, axes, armature, noise, tau_ext, ft_adr, ft_filt = obs[:10]
    coef, tau_out, tau_z, ft_out, ft_z = obs[10:]
    nv = qvel.shape[0]
    k = int(sc[NOISE_I])
    sc[NOISE_I] = k + 1
    if sc[USE_FT] != 0.0:
        for i in range(6):  # the gauges' noise is inside the sensor's filters
            ft_filt[i] += sc[ALPHA] * (sdata[ft_adr + i] + noise[k, i] - ft_filt[i])
        _biquad(coef, ft_filt, ft_out, ft_z)
        return
    for j in range(nv):
        ddq[j] = qvel[j] - dq_prev[j]
    fns[4](m, d, _addr(mddq), _addr(ddq))
    for j in range(nv):
        a = tj_adr[j]
        tau_j = sdata[a] * axes[j, 0] + sdata[a + 1] * axes[j, 1] + sdata[a + 2] * axes[j, 2]
        raw = (mddq[j] - armature[j] * ddq[j]) * sc[INV_DT] + bias[j] - tau_j - noise[k, j]
        tau_ext[j] += sc[ALPHA] * (raw - tau_ext[j])
    _biquad(coef, tau_ext, tau_out, tau_z)


@numba.njit(cache=True, inline="always")
def _biquad(coef, x, y, z) -> None:  # noqa: ANN001
    """One sample of :class:`teachfit.robot.sensor_filter.LowPass2` per channel of ``x``."""
    b0, b1, b2, a1, a2 = coef[0], coef[1], coef[2], coef[3], coef[4]
    for i in range(x.shape[0]):
        y[i] = b0 * x[i] + z[0, i]
        z[0, i] = b1 * x[i] - a1 * y[i] + z[1, i]
        z[1, i] = b2 * x[i] - a2 * y[i]


@numba.njit(cache=True, inline="always")
def _outside(qpos, qvel, lim) -> bool:  # noqa: ANN001
    q_min, q_max, dq_max = lim[0], lim[1], lim[2]
    for j in range(qpos.shape[0]):
        if qpos[j] < q_min[j] or qpos[j] > q_max[j] or abs(qvel[j]) > dq_max[j]:
            return True
    return False


@numba.njit(cache=True, inline="always")
def _actuate_and_step(fns, m, d, dat, ctl, obs, lim, sc) -> bool:  # noqa: ANN001
    """``ctrl = tau``, the Stribeck term, ``mj_step2``, sensing; True if a joint left its
    limits."""
    dat[3][:] = ctl[6]
    obs[0][:] = dat[1]
    stribeck(dat[1], dat[7], lim[3], lim[4])
    fns[1](m, d)
    observe(fns, m, d, dat, obs, sc)
    return _outside(dat[0], dat[1], lim)


@numba.njit(cache=True)
def tick_pre(fns, m, d, site, dat, ctl, law):  # noqa: ANN001, ANN201
    """``mj_step1`` and the TCP kinematics: the state a Python law then reads."""
    fns[0](m, d)
    kinematics(fns, m, d, site, ctl[0], dat[5], law[11], law[12], dat[1])


@numba.njit(cache=True)
def tick_post(fns, m, d, w, dat, ctl, obs, lim, sc):  # noqa: ANN001, ANN201
    """Torques for wrench ``w``, ``mj_step2``, sensing; True if a joint left its limits."""
    torques(fns, m, d, w, dat, ctl, sc)
    return _actuate_and_step(fns, m, d, dat, ctl, obs, lim, sc)


@numba.njit(cache=True)
def compute_fixed(t, fns, m, d, site, dat, ctl, law, sc):  # noqa: ANN001, ANN201
    """Kinematics, the fixed-gain law and the torques of one tick, without stepping.

    ``law``: (K, D, f_ff, x_d, q_d, v_d, e, de, q scratch, r scratch, wrench, quat, twist).
    """
    kmat, dmat, ff, xd, qd, vd, err, derr, qtmp, rtmp, w, quat, twist = law
    kinematics(fns, m, d, site, ctl[0], dat[5], quat, twist, dat[1])
    fixed_law(fns, t, dat[6], quat, twist, kmat, dmat, ff, xd, qd, vd, sc, err, derr, qtmp, rtmp, w)
    torques(fns, m, d, w, dat, ctl, sc)


@numba.njit(cache=True, inline="always")
def _now(fns, ts) -> int:  # noqa: ANN001
    fns[11](_MONOTONIC, _addr(ts))
    return ts[0] * 1_000_000_000 + ts[1]


@numba.njit(cache=True)
def replay(fns, m, d, dat, joints, log):  # noqa: ANN001, ANN201
    """:func:`step_physics` with the torques ``log[k]`` (n, nu) written into ``ctrl`` before
    step ``k``, in a compiled loop: the physics alone of a controlled run, for comparison."""
    for k in range(log.shape[0]):
        dat[3][:] = log[k]
        step_physics(fns, m, d, dat, joints)


@numba.njit(cache=True)
def run_fixed(n, t, fns, m, d, site, dat, ctl, law, obs, lim, sc, times, log):  # noqa: ANN001, ANN201, E501
    """``n`` whole ticks with the fixed-gain law from time ``t``: ``(ticks done, status)``.

    ``lim``: the joints' (q_min, q_max, dq_max, Stribeck ``F_s - F_c``, ``1 / v_s``).
    Stops early after a tick that left the joint limits (``LIMIT``) or before one that has no
    sensor noise left (``NOISE_EMPTY``: the caller draws more and calls again). When ``times``
    (int64) is not empty, ``times[k]`` gets tick ``k``'s law and torque compute time (ns), and
    ``log[k]`` (n, nu) its torques.
    """
    noise = obs[6]
    timed = times.shape[0] >= n
    ts = np.zeros(2, np.int64)
    for k in range(n):
        if sc[NOISE_I] >= noise.shape[0]:
            return k, NOISE_EMPTY
        fns[0](m, d)
        start = _now(fns, ts) if timed else 0
        compute_fixed(t, fns, m, d, site, dat, ctl, law, sc)
        if timed:
            times[k] = _now(fns, ts) - start
            log[k] = ctl[6]
        t += sc[DT]  # as mj_step2 advances d->time
        if _actuate_and_step(fns, m, d, dat, ctl, obs, lim, sc):
            return k + 1, LIMIT
    return n, OK
