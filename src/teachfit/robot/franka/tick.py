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

The arithmetic runs compiled (:mod:`teachfit.robot.franka.kernel`), the fixed-gain and the
adaptive law with it; any other law runs in Python between the kinematics and the torques.
:class:`TorqueTick` owns the buffers and reads libfranka's state and model into them.
"""

from __future__ import annotations

import numpy as np

from teachfit.control.base import Controller
from teachfit.control.compiled import N_SCALARS, LawBinding
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.robot.franka import kernel as k
from teachfit.robot.franka.frames import FrankaFrames, col_major
from teachfit.robot.franka.libfranka_types import LibfrankaModel, LibfrankaState
from teachfit.robot.franka.safety import FrankaLimits

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
    """The per-tick computation: its buffers (allocated once), the last sent torques, and the
    law it runs compiled.

    Parameters
    ----------
    frames : FrankaFrames
    limits : FrankaLimits
    period : float
        Control period (s).
    nullspace_stiffness, nullspace_damping : posture gains (N·m/rad, N·m·s/rad) per joint.

    The TCP state of the last tick (``pos``, ``rot``, ``quat``, ``lin_vel``, ``ang_vel``,
    world frame) are views that the next tick overwrites; :attr:`jacobian` is a copy.
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
        self.r_wo = w_t_o[:3, :3].copy()  # the base->world rotation (read-only)
        m = limits.workspace_margin
        lo, hi = np.asarray(limits.workspace_lo) - m, np.asarray(limits.workspace_hi) + m
        z = np.zeros
        # the kernel's buffers (:mod:`teachfit.robot.franka.kernel` names them)
        self._geo: tuple[np.ndarray, ...] = (
            self.r_wo, w_t_o[:3, 3].copy(), ee_t_tcp[:3, :3].copy(), ee_t_tcp[:3, 3].copy(),
            z(3), lo, hi,
        )  # fmt: skip
        self._k_read = False  # EE_T_K is set with set_K, not during control: read once
        self._raw: tuple[np.ndarray, ...] = (z(16), z(42), z(7), z(7), z(7), z(6))
        self._kin: tuple[np.ndarray, ...] = (
            z((6, 7)), z(3), z((3, 3)), z(4), z(6), z(3), z(6), z(6), z(6), z(6), z((3, 3)),
        )  # fmt: skip
        self.pos, self.rot, self.quat, twist = self._kin[1:5]
        self.lin_vel, self.ang_vel = twist[:3], twist[3:]
        self._tq: tuple[np.ndarray, ...] = (
            z(7), z(7), z(7), np.asarray(limits.joint_torque_limits, float), z(6), z(6),
            z((6, 6)), z(6), z(7), z(6),
        )  # fmt: skip
        self._fs = np.zeros(k.N_SCALARS)
        self._fs[k.K_NS], self._fs[k.D_NS] = float(nullspace_stiffness), float(nullspace_damping)
        self._fs[k.TAU_STEP] = limits.max_torque_rate * period
        self._fs[k.V_MAX], self._fs[k.W_MAX] = limits.max_tcp_speed, limits.max_tcp_ang_speed
        self._fs[k.F_MAX], self._fs[k.T_MAX] = limits.max_force, limits.max_torque
        k.compile_entries()  # here, not on the control thread's first tick
        self._sc = np.zeros(N_SCALARS)
        self._law: Controller | None = None
        self._binding: LawBinding | None = None
        self._table = self._make_table(None)

    # ------------------------------------------------------------------ buffers
    @property
    def q_rest(self) -> np.ndarray:
        """The posture (7,) (rad) the null space pulls to."""
        return self._tq[0]

    @q_rest.setter
    def q_rest(self, q: np.ndarray) -> None:
        self._tq[0][:] = q

    @property
    def tau_prev(self) -> np.ndarray:
        """The last sent torques (7,) (N·m), the rate limit's start."""
        return self._tq[1]

    @tau_prev.setter
    def tau_prev(self, tau: np.ndarray) -> None:
        self._tq[1][:] = tau

    @property
    def bias(self) -> np.ndarray:
        """The wrench bias (6,) taken off the measured wrench (N, N·m, world)."""
        return self._kin[8]

    @bias.setter
    def bias(self, bias: np.ndarray) -> None:
        self._kin[8][:] = bias

    @property
    def q(self) -> np.ndarray:
        """The joint angles (7,) (rad) of the last state read (a view)."""
        return self._raw[2]

    @property
    def jacobian(self) -> np.ndarray:
        """The TCP Jacobian (6, 7) (base frame, rows ``[v; w]``) of the last tick, a copy (it
        is read outside the control thread)."""
        return self._kin[0].copy()

    @property
    def wrench_cmd(self) -> np.ndarray:
        """The last commanded wrench (6,), clipped to the driver's caps (world, TCP)."""
        return self._tq[4]

    @property
    def tau(self) -> np.ndarray:
        """The torques (7,) of the last tick (N·m), limited (a view)."""
        return self._tq[2]

    # ------------------------------------------------------------------ per tick
    def _read(self, state: LibfrankaState, model: LibfrankaModel, coriolis: bool) -> None:
        o_t_ee, zj, q, dq, cor, ext = self._raw
        o_t_ee[:] = state.O_T_EE
        zj[:] = model.zero_jacobian(state)
        q[:] = state.q
        dq[:] = state.dq
        ext[:] = state.O_F_ext_hat_K
        if coriolis:
            cor[:] = model.coriolis(state)
        if not self._k_read:
            self._geo[4][:] = col_major(state.EE_T_K)[:3, 3]
            self._k_read = True

    def kinematics(self, state: LibfrankaState, model: LibfrankaModel) -> None:
        """TCP pose/twist in the world, the TCP Jacobian and the measured wrench from a
        pylibfranka ``RobotState``."""
        self._read(state, model, coriolis=False)
        k.kinematics_at(self._table)

    def raw_wrench(self) -> np.ndarray:
        """The environment's wrench on the tool at the TCP, world frame, before the bias, of
        the last :meth:`kinematics` (a copy)."""
        return self._kin[6].copy()

    def robot_state(self, t: float) -> RobotState:
        """A teachfit :class:`RobotState` of the last tick's kinematics, at time ``t`` (s)."""
        kin = self._kin
        return RobotState(
            t=t,
            pos=kin[1].copy(),
            quat=kin[3].copy(),
            lin_vel=self.lin_vel.copy(),
            ang_vel=self.ang_vel.copy(),
            wrench=kin[7].copy(),
        )

    def step(self, t: float, law: Controller, state: LibfrankaState, model: LibfrankaModel) -> str:
        """One tick at time ``t`` (s): the kinematics, the driver's motion limits, ``law`` and
        the torques (:attr:`tau`); why the motion broke a limit ("" when it did not: the
        torques are ready)."""
        self._read(state, model, coriolis=True)
        b = self._bind(law)
        if b is None:
            status = k.kinematics_at(self._table)
            if status == k.OK:
                self._python_law(t, law)
        else:
            status = k.tick_at(t, self._table)
        if status == k.OK:
            return ""
        why = self.limits.check_motion(self.pos, self.lin_vel, self.ang_vel)
        return why or f"TCP motion over the driver's limits (check {status})"

    def torques(
        self, t: float, law: Controller, state: LibfrankaState, model: LibfrankaModel
    ) -> np.ndarray:
        """Joint torques (7,) for this tick after :meth:`kinematics`, the motion not checked
        (a view)."""
        self._raw[4][:] = model.coriolis(state)
        self._python_law(t, law)
        return self.tau

    def _python_law(self, t: float, law: Controller) -> None:
        w = np.array(law.compute(t, self.pos, self.quat, self.lin_vel, self.ang_vel), float)
        k.torques_at(self._table, w)

    def command(self, law: Controller, cmd: ImpedanceCommand, t: float) -> None:
        """``law.set_command(cmd, t)`` at time ``t`` (s). A law that runs compiled keeps its
        set-point clock in the kernel's scalars while it is bound: they go back into the law
        before the command and are read from it after (the only time the law's Python side
        runs), so call this, not ``law.set_command``."""
        b = self._bind(law)
        if b is not None:
            b.store(self._sc)
        law.set_command(cmd, t)
        if b is not None:
            b.load(self._sc)
            b.law.last_wrench = b.wrench  # the kernel's buffer, live

    def _bind(self, law: Controller) -> LawBinding | None:
        """The compiled binding of ``law`` (made when the law changes, its state loaded), or
        None for a law that runs in Python."""
        if law is not self._law:
            if self._binding is not None:
                self._binding.store(self._sc)  # the law it replaces holds where it got to
            self._law = law
            self._binding = LawBinding(law) if LawBinding.supports(law) else None
            self._table = self._make_table(self._binding)
            if self._binding is not None:
                self._binding.load(self._sc)
        return self._binding

    def _make_table(self, b: LawBinding | None) -> np.ndarray:
        """The kernel's address table of the buffers, with ``b``'s law (or unused ones)."""
        law = b.bufs if b is not None else tuple(np.zeros(shape) for shape in k.LAW)
        ad = b.ad if b is not None else tuple(np.zeros(shape) for shape in k.AD)
        self._table_keep = (law, ad)  # the table holds only addresses: keep the arrays alive
        adaptive = b is not None and b.adaptive
        return k.table(
            self._raw, self._geo, self._kin, law, ad, self._sc, self._tq, self._fs, adaptive
        )
