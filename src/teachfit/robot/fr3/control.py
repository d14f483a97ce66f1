"""Cartesian impedance in joint torques for the FR3 (seed B eq. 2, seed A eqs. 8-9).

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
"""

from __future__ import annotations

import mujoco
import numpy as np

from teachfit.control.base import Controller


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
        self.model, self.data, self.site, self.law = model, data, site, law
        self.tau_max = np.asarray(tau_max, dtype=float)
        self.dtau_step = float(dtau_max) * float(model.opt.timestep)
        self.k_null, self.d_null = float(null_stiffness), float(null_damping)
        self.q_null = np.zeros(nv)
        self.jac = np.zeros((6, nv))
        self._jacp, self._jacr = self.jac[:3], self.jac[3:]
        self._jminv = np.zeros((6, nv))
        self._lam_inv = np.zeros((6, 6))
        self.twist = np.zeros(6)
        self._v, self._w = self.twist[:3], self.twist[3:]
        self.quat = np.zeros(4)
        self.pos = data.site_xpos[site]
        self._xmat = data.site_xmat[site]
        self._qpos, self._qvel, self._bias = data.qpos, data.qvel, data.qfrc_bias
        self._neg_tau_max = -self.tau_max
        self._null = self.k_null > 0.0 or self.d_null > 0.0
        self.tau = np.zeros(nv)
        self.tau_prev = np.zeros(nv)
        self.wrench = np.zeros(6)
        self._tau0 = np.zeros(nv)
        self._tmp = np.zeros(nv)
        self._y = np.zeros(6)
        self._z = np.zeros(6)

    def reset(self, q_null: np.ndarray) -> None:
        """Hold the posture ``q_null`` and start the rate limit from the current bias torque
        (the arm at rest holds itself: ``tau = c(q, 0)``)."""
        self.q_null[:] = q_null
        self.tau_prev[:] = self.data.qfrc_bias
        self.tau[:] = self.tau_prev

    def update_kinematics(self) -> None:
        """TCP Jacobian, pose and twist (world frame) from the current kinematics."""
        mujoco.mj_jacSite(self.model, self.data, self._jacp, self._jacr, self.site)
        mujoco.mju_mat2Quat(self.quat, self._xmat)
        mujoco.mju_mulMatVec(self.twist, self.jac, self._qvel)

    def compute(self, t: float) -> np.ndarray:
        """Joint torques (nv,) for this tick, limited in rate and magnitude (a view, reused).

        MuJoCo's own vector and matrix routines (``mju_*``) do the small algebra: they cost a
        fraction of numpy's per-call overhead at these sizes (1 kHz path).
        """
        self.update_kinematics()
        jac, tau, tau0 = self.jac, self.tau, self._tau0
        wrench = self.law.compute(t, self.pos, self.quat, self._v, self._w)
        self.wrench = wrench
        mujoco.mju_mulMatTVec(tau, jac, wrench)  # J^T F
        mujoco.mju_addTo(tau, self._bias)
        if self._null:
            mujoco.mju_sub(tau0, self.q_null, self._qpos)
            mujoco.mju_scl(tau0, tau0, self.k_null)
            mujoco.mju_addToScl(tau0, self._qvel, -self.d_null)
            mujoco.mj_solveM(self.model, self.data, self._jminv, jac)  # rows of J M^-1
            lam_inv = self._lam_inv
            mujoco.mju_mulMatMatT(lam_inv, self._jminv, jac)
            mujoco.mju_cholFactor(lam_inv, 1e-10)
            mujoco.mju_mulMatVec(self._y, self._jminv, tau0)
            mujoco.mju_cholSolve(self._z, lam_inv, self._y)  # Lambda J M^-1 tau_0
            mujoco.mju_mulMatTVec(self._tmp, jac, self._z)
            mujoco.mju_subFrom(tau0, self._tmp)  # N^T tau_0
            mujoco.mju_addTo(tau, tau0)
        step = self._tmp  # (ufuncs: np.clip's Python wrapper costs more than the arithmetic)
        mujoco.mju_sub(step, tau, self.tau_prev)
        np.minimum(step, self.dtau_step, out=step)
        np.maximum(step, -self.dtau_step, out=step)
        mujoco.mju_add(tau, self.tau_prev, step)
        np.minimum(tau, self.tau_max, out=tau)
        np.maximum(tau, self._neg_tau_max, out=tau)
        mujoco.mju_copy(self.tau_prev, tau)
        return tau
