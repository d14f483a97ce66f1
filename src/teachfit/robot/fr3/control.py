"""Cartesian impedance in joint torques for the FR3 (Johannsmeier et al. 2019 eq. 2, Ehlers et al.
2019 eqs. 8-9).

Each 1 ms tick, with the kinematics and dynamics of the current state (``mj_step1`` done):

    F     = K e + D de + F_ff                        (teachfit's Cartesian law, TCP, world)
    tau   = J^T F + c(q, dq) + N^T tau_0
    tau_0 = K_n (q_n - q) - D_n dq                    (posture in the null space)
    N^T   = I - J^T Lambda J M^-1,   Lambda = (J M^-1 J^T)^-1

``F`` comes from the control law the robot runs (:func:`teachfit.control.make_law`: fixed-gain
or adaptive impedance, ``e``/``de`` the TCP pose and twist errors); ``J`` (6 x 7) is the TCP
site's Jacobian (``mj_jacSite``, world frame, rows ``[v; w]``); ``c = qfrc_bias`` compensates
gravity, Coriolis and centrifugal torques as Franka's firmware and its ``coriolis`` term do;
``N^T`` is the dynamically consistent null-space projector (Khatib), so the posture torques
``tau_0`` (N·m) produce no TCP acceleration. ``M^-1`` is applied with ``mj_solveM`` on the
factorised joint-space inertia (armature included). ``Lambda`` (kg, kg·m²) is the operational
space inertia; its diagonal is the apparent mass the law's critical damping uses.

The commanded torque is limited as the FR3 limits it: first the rate,
``|tau_k - tau_{k-1}| <= dtau_max dt`` (1000 N·m/s), then the magnitude,
``|tau_k| <= tau_max`` (87/87/87/87/12/12/12 N·m), every tick.

The arithmetic runs compiled (:mod:`teachfit.robot.fr3.kernel`); this class owns the buffers
(allocated once, names and pointers resolved once) that the kernel works on.
"""

from __future__ import annotations

from typing import cast

import mujoco
import numpy as np

from teachfit.control import CartesianImpedance
from teachfit.control.base import Controller
from teachfit.robot.fr3 import kernel as k


def operational_inertia(model: mujoco.MjModel, data: mujoco.MjData, site: int) -> np.ndarray:
    """``Lambda = (J M^-1 J^T)^-1`` (6, 6) at ``site`` for the state in ``data`` (kinematics and
    the factorised inertia must be current, e.g. after ``mj_forward``)."""
    jac = np.zeros((6, model.nv))
    mujoco.mj_jacSite(model, data, jac[:3], jac[3:], site)
    jminv = np.zeros_like(jac)
    mujoco.mj_solveM(model, data, jminv, jac)
    return np.linalg.inv(jminv @ jac.T)


class TorqueImpedance:
    """The torque law of the module docstring, with its buffers allocated once.

    Parameters
    ----------
    model, data : the MuJoCo cell (the arm's dofs are ``0 .. nv-1``).
    site : id of the TCP site.
    law : the Cartesian controller producing ``F`` (TCP wrench, world frame).
    tau_max : (nv,) torque limits (N·m); ``dtau_max`` rate limit (N·m/s).
    null_stiffness, null_damping : ``K_n`` (N·m/rad) and ``D_n`` (N·m·s/rad).

    ``sc`` holds the kernel's scalars (:data:`teachfit.robot.fr3.kernel.N_SCALARS` slots),
    shared with the robot's sensing.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        site: int,
        law: Controller,
        tau_max: np.ndarray,
        dtau_max: float,
        null_stiffness: float,
        null_damping: float,
    ) -> None:
        nv = model.nv
        self.model, self.data, self.site = model, data, site
        self.fns = k.routines()
        self.m_ptr, self.d_ptr = model._address, data._address
        self.sc = np.zeros(k.N_SCALARS)
        self.sc[k.K_NULL], self.sc[k.D_NULL] = float(null_stiffness), float(null_damping)
        self.sc[k.DT] = float(model.opt.timestep)
        self.sc[k.DTAU] = float(dtau_max) * float(model.opt.timestep)
        self.tau_max = np.asarray(tau_max, dtype=float)
        self.q_null = np.zeros(nv)
        self.jac = np.zeros((6, nv))
        self.twist = np.zeros(6)
        self._v, self._w = self.twist[:3], self.twist[3:]
        self.quat = np.zeros(4)
        self.pos = data.site_xpos[site]
        self.tau = np.zeros(nv)
        self.tau_prev = np.zeros(nv)
        self.wrench = np.zeros(6)
        self._work = (np.zeros((6, nv)), np.zeros((6, 6)), np.zeros(nv), np.zeros(6), np.zeros(6))
        self.dat = k.data_views(data, site)
        self.law = law

    @property
    def law(self) -> Controller:
        return self._law

    @law.setter
    def law(self, law: Controller) -> None:
        """Install ``law``; the fixed-gain Cartesian law runs compiled, others in Python."""
        self._law = law
        #: True when the whole tick runs compiled (:func:`teachfit.robot.fr3.kernel.run_fixed`)
        self.compiled = type(law) is CartesianImpedance
        self.law_bufs: tuple[np.ndarray, ...]
        if type(law) is CartesianImpedance:
            e = law._error  # the law's own buffers: the kernel updates them in place
            self.law_bufs = (law._k, law._d, law._ff, e._xd, e._qd, e._vd, e.err, e.derr)
            self.law_bufs += (e._qtmp, e._rtmp, self.wrench, self.quat, self.twist)
        else:
            z3, z4, z6, z66 = np.zeros(3), np.zeros(4), np.zeros(6), np.zeros((6, 6))
            self.law_bufs = (z66, z66, z6, z3, z4, z6, z6, z6, z4, z3, z6, self.quat, self.twist)

    def ctl_bufs(self) -> tuple:
        """The torque map's buffers in the kernel's order (``tau_max`` may be changed)."""
        jminv, lam, tau0, y, z = self._work
        tau = self.tau
        return (self.jac, jminv, lam, self.q_null, self.tau_prev, self.tau_max, tau, tau0, y, z)

    def _fixed_law(self) -> CartesianImpedance:
        """The installed law, which is the fixed-gain one while :attr:`compiled` (the only time
        :meth:`load_law` and :meth:`store_law` run)."""
        return cast(CartesianImpedance, self._law)

    def load_law(self) -> None:
        """Copy the fixed-gain law's scalar state into the kernel's scalars."""
        law, sc = self._fixed_law(), self.sc
        e, lim = law._error, law.limits
        sc[k.T0], sc[k.EXPIRY] = e._t0, e._expiry
        sc[k.SPINNING], sc[k.LAPSED] = float(e._spinning), float(e.lapsed)
        sc[k.MAX_F], sc[k.MAX_T] = lim.max_force, lim.max_torque

    def store_law(self) -> None:
        """Copy the kernel's scalars back into the fixed-gain law (after a compiled run)."""
        law, sc = self._fixed_law(), self.sc
        e = law._error
        e._t0, e._expiry = float(sc[k.T0]), float(sc[k.EXPIRY])
        e._spinning, e.lapsed = bool(sc[k.SPINNING]), bool(sc[k.LAPSED])
        law.last_wrench = self.wrench.copy()

    def reset(self, q_null: np.ndarray) -> None:
        """Hold the posture ``q_null`` and start the rate limit from the current bias torque
        (the arm at rest holds itself: ``tau = c(q, 0)``)."""
        self.q_null[:] = q_null
        self.tau_prev[:] = self.data.qfrc_bias
        self.tau[:] = self.tau_prev

    def update_kinematics(self) -> None:
        """TCP Jacobian, pose and twist (world frame) from the current kinematics."""
        k.kinematics(
            self.fns, self.m_ptr, self.d_ptr, self.site, self.jac, self.dat[5], self.quat,
            self.twist, self.data.qvel,
        )  # fmt: skip

    def compute(self, t: float) -> np.ndarray:
        """Joint torques (nv,) for this tick, limited in rate and magnitude (a view, reused);
        the kinematics of the current state must be done (``mj_step1``)."""
        if self.compiled:
            self.load_law()
            k.compute_fixed(
                t, self.fns, self.m_ptr, self.d_ptr, self.site, self.dat, self.ctl_bufs(),
                self.law_bufs, self.sc,
            )  # fmt: skip
            self.store_law()
            return self.tau
        self.update_kinematics()
        w = self._law.compute(t, self.pos, self.quat, self._v, self._w)
        self.wrench[:] = w
        k.torques(self.fns, self.m_ptr, self.d_ptr, self.wrench, self.dat, self.ctl_bufs(), self.sc)
        return self.tau
