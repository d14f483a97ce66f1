"""The floating tool's 1 kHz tick compiled with numba: law, ``mj_applyFT`` and ``mj_step``.

Why: a tick of :class:`~teachfit.robot.floating.FloatingToolRobot` is one ``mj_step`` (6-60
µs, most of it narrow-phase collision in contact) plus the control law, ~30 small numpy
operations that cost 35-45 µs from Python (BENCHMARKS.md, Johannsmeier et al. 2019 throughput).
Compiled, the law costs well under a microsecond; the whole ``step(n)`` of ``n`` ticks becomes one
call.

This reuses the FR3 kernel's pattern and parts (:mod:`teachfit.robot.fr3.kernel`): MuJoCo's C
routines through ``ctypes`` on the bindings' own ``libmujoco`` with the model and data
pointers. The laws are the control layer's compiled ones (:mod:`teachfit.control.compiled`,
which also names the scalar slots of ``sc``), the same the FR3's tick calls: the fixed-gain
law :func:`~teachfit.control.compiled.fixed_law` (the set-point extrapolation and expiry of
:class:`teachfit.control.impedance.SetpointError`) and, for the adaptive law of
:class:`teachfit.control.AdaptiveImpedance` (its module docstring has the equations),
:func:`~teachfit.control.compiled.adapt` on top: the fixed-gain law with the command's ``K``,
``D`` and ``F_d`` and no clipping gives ``K e + D de + F_d`` and the errors, then the
adaptation and the adaptive terms are added and the sum is clipped. The kernel works on the law
objects' own buffers, so their state (adapted ``F_ff``, ``K_a``, set-point clock) is what the
Python law would hold; a test checks that both paths give the same trajectory.

numba caches the machine code on disk (``cache=True``): the first process after a change to
this file compiles it (about a minute on the busy 2-core machine), later ones load it. The
cache is keyed on this file only: after an edit of the compiled laws or of the FR3 kernel's
functions used here, touch this file (or clear its ``__pycache__``) so that they are compiled
in again.
"""

from __future__ import annotations

import ctypes
import math
from functools import cache
from typing import TypeGuard

import mujoco
import numba
import numpy as np

from teachfit.control import AdaptiveImpedance, CartesianImpedance
from teachfit.control import compiled as c
from teachfit.robot.fr3 import kernel as k

_P = ctypes.c_size_t
APPLY_FT = 13  # index of mj_applyFT in :func:`routines`


#: indices of the routines :func:`run` calls (with :func:`~teachfit.control.compiled.fixed_law`):
#: mju_subQuat, mju_rotVecQuat, mju_quatIntegrate, mj_step, mj_applyFT
USED = frozenset({c.SUB_QUAT, c.ROT_VEC_QUAT, c.QUAT_INTEGRATE, 12, APPLY_FT})


@cache
def routines() -> tuple[int, ...]:
    """The addresses (:func:`~teachfit.control.compiled.c_address`) of the FR3 kernel's
    routines plus ``mj_applyFT`` (index :data:`APPLY_FT`); the ones :func:`run` never calls
    are ``0``. Why addresses, not the ``ctypes`` routines: numba types every ``ctypes``
    routine of a call's arguments in Python (~1.3 µs each, per 10 ms command), a tuple of
    integers in C; :func:`run` passes the C types itself."""
    apply_ft = k._fn("mj_applyFT", _P, _P, _P, _P, _P, ctypes.c_int, _P)
    fns = (*k.routines(), apply_ft)
    return tuple(c.c_address(f) if i in USED else 0 for i, f in enumerate(fns))


@numba.njit(cache=True)
def run(n, t, fns, m, d, body, adaptive, st, law, ad, sc, ft, f_adr):  # noqa: ANN001, ANN201
    """``n`` ticks from time ``t`` (s); returns the ticks done (fewer: a non-finite wrench
    before the tick of that index, nothing applied).

    ``st``: (TCP pos, quat, linear velocity, local angular velocity, world angular velocity,
    TCP point, qfrc_applied, sensordata, twist scratch); ``law``: (K, D, f, x_d, q_d, v_d,
    e, de, q scratch, r scratch, wrench). ``ft``: (gauge noise (n, 6), filter coefficients,
    filter output (6,), filter state (2, 6), gauge scratch (6,)): every tick the raw F/T
    sensor at ``f_adr`` plus that tick's noise passes the device's low-pass
    (:class:`teachfit.robot.sensor_filter.LowPass2`, the recurrence of ``lfilter``).
    """
    pos, quat, linvel, angvel_local, angvel, point, qfrc, sdata, twist = st
    noise, coef, ft_out, ft_z, gauge = ft
    kmat, dmat, ff, xd, qd, vd, err, derr, qtmp, rtmp, w = law
    body32 = np.int32(body)  # mj_applyFT's ``int body``: the call converts nothing
    for tick in range(n):
        c.call(fns[c.ROT_VEC_QUAT], (c.addr(angvel), c.addr(angvel_local), c.addr(quat)))
        for i in range(3):
            twist[i] = linvel[i]
            twist[i + 3] = angvel[i]
        c.fixed_law(
            fns, t, pos, quat, twist, kmat, dmat, ff, xd, qd, vd, sc, err, derr, qtmp, rtmp, w
        )  # noqa: E501
        if adaptive:
            c.adapt(ad, err, derr, w, sc)
        total = 0.0
        for i in range(6):
            total += w[i]
        if not math.isfinite(total):
            return tick
        qfrc[:] = 0.0
        c.call(
            fns[APPLY_FT], (m, d, c.addr(w), c.addr(w) + 24, c.addr(point), body32, c.addr(qfrc))
        )
        c.call(fns[12], (m, d))  # mj_step
        for i in range(6):
            gauge[i] = sdata[f_adr + i] + noise[tick, i]
        k._biquad(coef, gauge, ft_out, ft_z)
        t += sc[c.DT]  # as mj_step advances d->time
    return n


class FloatingKernel:
    """Binds a fixed-gain or adaptive law of a floating tool to :func:`run`.

    ``state`` is the :func:`run` ``st`` tuple (views into the robot's MjData and buffers).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        body: int,
        law: AdaptiveImpedance | CartesianImpedance,
        state: tuple,
    ) -> None:
        self.fns = routines()
        self.m_ptr, self.d_ptr = model._address, data._address
        self.data, self.body, self.state = data, body, state
        self.law = law
        self.sc = np.zeros(c.N_SCALARS)
        self.sc[c.DT] = float(model.opt.timestep)
        self.binding = c.LawBinding(law)

    @staticmethod
    def supports(law: object) -> TypeGuard[AdaptiveImpedance | CartesianImpedance]:
        """Whether ``law`` runs compiled (the two laws of :mod:`teachfit.control`)."""
        return c.LawBinding.supports(law)

    def step(self, n: int, f_adr: int, ft: tuple) -> int:
        """``n`` ticks (``ft`` as for :func:`run`); the law's scalar state in and out around
        the compiled loop."""
        b, sc = self.binding, self.sc
        b.load(sc)
        with k.untimed():
            done = run(
                n, float(self.data.time), self.fns, self.m_ptr, self.d_ptr, self.body,
                b.adaptive, self.state, b.bufs, b.ad, sc, ft, f_adr,
            )  # fmt: skip
        b.store(sc)
        return int(done)
