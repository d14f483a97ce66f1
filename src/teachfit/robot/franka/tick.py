"""One tick of the Franka torque loop: libfranka state -> TCP state -> law -> joint torques.

Per tick (1 kHz, in the driver's control thread), with ``J`` libfranka's zero Jacobian of the
EE frame shifted to the TCP (base frame) and ``R`` the base->world rotation:

    x, q, [v; w]   = TCP pose and twist (J dq) in the world frame
    F              = clip(law(t, x, q, v, w))                       (N, N·m, world, at the TCP)
    tau            = J^T [R^T f; R^T tau] + coriolis + N (k_ns (q_rest - q) - d_ns dq)
    tau            = rate- and magnitude-limited against the last sent torques

``N = I - J^T (J J^T + lambda^2 I)^-1 J`` projects the posture term into the null space of
the TCP task. Gravity is not added: the firmware (and franky-sim) compensates it. The measured
wrench is libfranka's ``O_F_ext_hat_K`` converted to teachfit's convention:
libfranka reports the wrench the *robot exerts on the environment* at the stiffness frame ``K``
(pulling the hand along +z reads negative z; libfranka issue #26), so the sign is flipped and
the torque moved from ``K`` to the TCP, then rotated into the world frame.
"""

from __future__ import annotations

import mujoco
import numpy as np

from teachfit.control.base import Controller
from teachfit.core.state import RobotState
from teachfit.robot.franka.frames import FrankaFrames, col_major, skew
from teachfit.robot.franka.libfranka_types import LibfrankaModel, LibfrankaState
from teachfit.robot.franka.safety import FrankaLimits, clip_wrench_norm, limit_torque

#: the motors' rotor inertia reflected to the joints (kg·m²), which libfranka's mass matrix
#: leaves out: the FR3 model's armature (MuJoCo Menagerie's ``franka_fr3``, the twin's cell)
ROTOR_INERTIA = (0.195, 0.195, 0.195, 0.195, 0.074, 0.074, 0.074)


def operational_inertia(mass: np.ndarray, jacobian: np.ndarray, r_wo: np.ndarray) -> np.ndarray:
    """The operational-space inertia (6, 6) at the TCP in world axes (kg, kg·m, kg·m²),
    ``Lambda = (J M^-1 J^T)^-1``, for the joint-space inertia ``mass`` (7, 7), the TCP Jacobian
    ``jacobian`` (6, 7) (base frame) and the base->world rotation ``r_wo``: the wrench
    ``Lambda a`` at the TCP accelerates it by ``a`` (6,) alone, where a wrench along one axis
    alone also accelerates the TCP along the others (the off-diagonal terms)."""
    rot = np.zeros((6, 6))
    rot[:3, :3] = rot[3:, 3:] = r_wo
    jac = rot @ np.asarray(jacobian, dtype=float)
    jminv = np.linalg.solve(np.asarray(mass, dtype=float), jac.T).T
    lam = np.linalg.inv(jminv @ jac.T)
    return 0.5 * (lam + lam.T)


def operational_mass(mass: np.ndarray, jacobian: np.ndarray, r_wo: np.ndarray) -> np.ndarray:
    """The diagonal (6,) (kg, kg·m²) of the operational-space inertia at the TCP in world axes,
    ``Lambda = (J M^-1 J^T)^-1``, for the joint-space inertia ``mass`` (7, 7) (libfranka's
    ``Model.mass``), the TCP Jacobian ``jacobian`` (6, 7) (base frame) and the base->world
    rotation ``r_wo``: the apparent mass the law's critical damping needs, as the fr3 robot
    takes it from its model (:func:`teachfit.robot.fr3.control.operational_inertia`)."""
    return np.diag(operational_inertia(mass, jacobian, r_wo)).copy()


class TorqueTick:
    """The per-tick computation; holds buffers and the last sent torques.

    Parameters
    ----------
    frames : FrankaFrames
    limits : FrankaLimits
    period : float
        Control period (s).
    nullspace_stiffness, nullspace_damping : posture gains (N·m/rad, N·m·s/rad) per joint.
    """

    def __init__(
        self,
        frames: FrankaFrames,
        limits: FrankaLimits,
        period: float = 0.001,
        nullspace_stiffness: float = 5.0,
        nullspace_damping: float = 1.0,
    ) -> None:
        self.limits = limits
        self.period = period
        w_t_o, ee_t_tcp = frames.matrices()
        self._r_wo = w_t_o[:3, :3].copy()
        self._t_wo = w_t_o[:3, 3].copy()
        self._r_et = ee_t_tcp[:3, :3].copy()
        self._p_et = ee_t_tcp[:3, 3].copy()
        self.k_ns = float(nullspace_stiffness)
        self.d_ns = float(nullspace_damping)
        self.q_rest = np.zeros(7)
        self.tau_prev = np.zeros(7)
        self.bias = np.zeros(6)
        self._tau_lim = np.asarray(limits.joint_torque_limits, dtype=float)
        self._quat = np.zeros(4)
        self._k_offset: np.ndarray | None = None
        self._k_lever = np.zeros(3)
        self._wrench = np.zeros(6)
        self.jacobian = np.zeros((6, 7))
        self.pos = np.zeros(3)
        self.rot = np.eye(3)
        self.lin_vel = np.zeros(3)
        self.ang_vel = np.zeros(3)
        self.wrench_cmd = np.zeros(6)
        self.r_wo = self._r_wo  # the base->world rotation (read-only)

    # ------------------------------------------------------------------ kinematics
    def kinematics(self, state: LibfrankaState, model: LibfrankaModel) -> None:
        """TCP pose/twist in the world (``pos``, ``quat``, ``lin_vel``, ``ang_vel``) and the
        TCP Jacobian (base frame) from a pylibfranka ``RobotState``."""
        t_ee = col_major(state.O_T_EE)
        r_ee, p_ee = t_ee[:3, :3], t_ee[:3, 3]
        r_tcp = r_ee @ self._r_et
        lever = r_ee @ self._p_et  # EE -> TCP, base frame
        p_tcp = p_ee + lever
        zj = model.zero_jacobian(state)
        jac = np.asarray(zj, dtype=float).reshape(6, 7, order="F")
        jac[:3] -= skew(lever) @ jac[3:]  # v_tcp = v_ee + w x lever
        self.jacobian = jac
        twist = jac @ np.asarray(state.dq, dtype=float)
        self.pos = self._r_wo @ p_tcp + self._t_wo
        self.rot = self._r_wo @ r_tcp
        mujoco.mju_mat2Quat(self._quat, self.rot.reshape(-1))
        self.lin_vel = self._r_wo @ twist[:3]
        self.ang_vel = self._r_wo @ twist[3:]
        if self._k_offset is None:  # EE_T_K is set with set_K, not during control: read once
            self._k_offset = col_major(state.EE_T_K)[:3, 3].copy()
        # K -> TCP lever (base frame), for moving the measured torque to the TCP
        self._k_lever = r_ee @ (self._k_offset - self._p_et)

    @property
    def quat(self) -> np.ndarray:
        return self._quat

    def raw_wrench(self, state: LibfrankaState) -> np.ndarray:
        """The environment's wrench on the tool at the TCP, world frame, before the bias."""
        ext = np.asarray(state.O_F_ext_hat_K, dtype=float)
        f = -ext[:3]  # libfranka: robot on environment -> teachfit: environment on tool
        r = self._k_lever
        t = -ext[3:]
        t[0] += r[1] * f[2] - r[2] * f[1]  # torque moved from K to the TCP: + r x f
        t[1] += r[2] * f[0] - r[0] * f[2]
        t[2] += r[0] * f[1] - r[1] * f[0]
        out = self._wrench
        out[:3] = self._r_wo @ f
        out[3:] = self._r_wo @ t
        return out.copy()

    def robot_state(self, t: float, state: LibfrankaState) -> RobotState:
        """A teachfit :class:`RobotState` of the last :meth:`kinematics` call."""
        return RobotState(
            t=t,
            pos=self.pos.copy(),
            quat=self._quat.copy(),
            lin_vel=self.lin_vel.copy(),
            ang_vel=self.ang_vel.copy(),
            wrench=self.raw_wrench(state) - self.bias,
        )

    # ------------------------------------------------------------------ torques
    def torques(
        self, t: float, law: Controller, state: LibfrankaState, model: LibfrankaModel
    ) -> np.ndarray:
        """Joint torques (7,) for this tick (after :meth:`kinematics`)."""
        w = law.compute(t, self.pos, self._quat, self.lin_vel, self.ang_vel)
        w = clip_wrench_norm(
            np.array(w, dtype=float), self.limits.max_force, self.limits.max_torque
        )
        self.wrench_cmd = w
        f_base = np.concatenate([self._r_wo.T @ w[:3], self._r_wo.T @ w[3:]])
        jac = self.jacobian
        q = np.asarray(state.q, dtype=float)
        dq = np.asarray(state.dq, dtype=float)
        tau = jac.T @ f_base
        tau += np.asarray(model.coriolis(state), dtype=float)
        posture = self.k_ns * (self.q_rest - q) - self.d_ns * dq
        jjt = jac @ jac.T
        jjt.flat[::7] += 1e-4  # damped: well-posed near singularities
        tau += posture - jac.T @ np.linalg.solve(jjt, jac @ posture)  # null-space projection
        limit_torque(tau, self.tau_prev, self.limits.max_torque_rate, self.period, self._tau_lim)
        self.tau_prev = tau
        return tau
