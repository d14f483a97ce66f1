"""The digital twin's physics: the task's FR3 cell behind franky-sim's robot and simulator classes.

The cell is the one ``--robot fr3`` runs (:func:`teachfit.robot.fr3.model.build_fr3_model`: the
task's fixture, the FR3, the held part rigidly on the hand, the joint torque sensors), placed
where the Franka driver expects it:

* the arm's base at the driver's default ``base2world``
  (:data:`~teachfit.robot.franka.frames.DEFAULT_BASE2WORLD`, a translation);
* the held part's top at libfranka's end-effector frame ``EE`` (``F_T_EE`` of the Franka Hand,
  0.1034 m down the flange axis, turned -pi/4 about it, which is the MJCF hand body's frame),
  so the driver's default ``ee2tcp`` (:func:`~teachfit.robot.franka.frames.ee2tcp_for_part`)
  is the part's tip. (For ``socket3d``, whose cell holds the part lower, ``grasp_drop`` m,
  the driver's TCP is that much above the part's tip.)

:class:`TwinRobot` is franky-sim's :class:`~franky_sim.mujoco_simulator.FrankaMujocoRobot`
(state, kinematics, gravity compensation and control modes, as franky-sim serves them) on that
cell instead of franky-sim's own scene: no fingers (the part is held rigidly). It starts at
rest with the TCP at ``TwinParams.start`` above the hole (the fr3 robot's inverse kinematics).

:class:`TwinSimulator` steps the cell at 1 kHz and, after each step, runs the fr3 robot's
joint-torque momentum observer (:class:`~teachfit.robot.fr3.sensing.JointTorqueObserver`, the
compiled :func:`teachfit.robot.fr3.kernel.observe`): the external joint torques estimated from
the link-side torque sensors (with white noise) through the arm's model, as the firmware
estimates ``tau_ext_hat_filtered``. A fixed per-joint offset (``TwinParams.torque_bias``, drawn
once from the seed; 0.2 N·m std reads 0.5-2 N at the hand at rest) stands for the sensors'
calibration and the model's errors: a real arm reads a few newtons at rest without contact
(franka_ros issue #404). :meth:`TwinSimulator.external_wrench` turns the estimate into
libfranka's ``O_F_ext_hat_K`` (see there for the sign). A scripted hand
(:attr:`TwinSimulator.hand`, :mod:`teachfit.robot.franka.twin_hand`) pushes the held part as a
person guiding the arm would, as an external force inside the physics.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from franky_sim.base_simulator import BaseSimulator
from franky_sim.mujoco_simulator import FrankaMujocoRobot

from teachfit.core.errors import TeachfitError
from teachfit.robot.fr3 import kernel
from teachfit.robot.fr3 import model as fr3_model
from teachfit.robot.fr3.ik import solve_ik
from teachfit.robot.fr3.params import READY_Q, FR3Params
from teachfit.robot.fr3.sensing import JointTorqueObserver
from teachfit.robot.franka.frames import DEFAULT_BASE2WORLD
from teachfit.robot.franka.hand import HandParams
from teachfit.robot.franka.twin_hand import TwinHand
from teachfit.robot.franka.twin_trace import ContactTrace
from teachfit.tasks.base import Task

#: libfranka's F_T_EE translation for the Franka Hand (m along the flange axis)
EE_OFFSET = 0.1034


@dataclass(frozen=True)
class TwinParams:
    """The twin's settings (m, N·m, Hz).

    ``start`` the TCP's start position relative to the task's contact pose at the hole
    (``task.contact_pose(0)``, m, world); ``torque_noise`` white noise per tick of the joint
    torque sensors (N·m), ``torque_bias`` the std of their fixed offsets (N·m, drawn from
    ``seed``); ``wrench_cutoff`` / ``output_cutoff`` the observer's and the output filter's
    cut-offs (Hz, as the fr3 robot's).
    """

    start: tuple[float, float, float] = (0.0, 0.0, 0.05)
    torque_noise: float = 0.02
    torque_bias: float = 0.2
    wrench_cutoff: float = 30.0
    output_cutoff: float = 18.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.torque_noise < 0 or self.torque_bias < 0:
            raise TeachfitError("twin: torque_noise and torque_bias must be >= 0 N·m")


def cell_params(params: TwinParams) -> FR3Params:
    """The fr3 cell's settings for the twin: base and part where the Franka driver puts them."""
    if not np.allclose(DEFAULT_BASE2WORLD.quat, [1.0, 0.0, 0.0, 0.0]):
        raise TeachfitError("twin: the driver's base2world must be a pure translation")
    base = tuple(float(v) for v in DEFAULT_BASE2WORLD.pos)
    return dataclasses.replace(
        FR3Params(),
        base_pos=(base[0], base[1], base[2]),
        mount_offset=EE_OFFSET,
        torque_noise=params.torque_noise,
        wrench_cutoff=params.wrench_cutoff,
        output_cutoff=params.output_cutoff,
    )


class TwinRobot(FrankaMujocoRobot):
    """franky-sim's MuJoCo FR3 on the task's cell: the 7 arm joints, no fingers."""

    def attach(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """Use ``model``/``data`` (the fr3 cell) for the arm's joints."""
        self._model, self._data = model, data
        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in fr3_model.JOINTS]
        self._qpos_addrs = [int(model.jnt_qposadr[i]) for i in ids]
        self._dof_addrs = [int(model.jnt_dofadr[i]) for i in ids]
        self._finger_qpos_addrs: list[int] = []
        self._finger_dof_addrs: list[int] = []

    def _pre_step(self) -> None:
        """No fingers to servo: the part is held rigidly."""

    def set_hand_goal(self, width: float, max_velocity: float, max_force: float) -> None:
        """The gripper does not move (the part is held rigidly)."""

    def _get_hand_width(self) -> float:
        return 0.0


class TwinSimulator(BaseSimulator):
    """The task's FR3 cell stepped at 1 kHz, with the firmware's external-torque estimate.

    Parameters
    ----------
    task : Task
    params : TwinParams or None
    """

    def __init__(self, task: Task, params: TwinParams | None = None) -> None:
        super().__init__()
        self.params = params or TwinParams()
        self.task = task
        cell = cell_params(self.params)
        self.model = fr3_model.build_fr3_model(task, cell)
        self.data = mujoco.MjData(self.model)
        self.robot = TwinRobot(initial_q=tuple(float(v) for v in self.start_q()))
        rng = np.random.default_rng(self.params.seed)
        #: fixed offsets of the joint torque sensors (N·m)
        self.bias = rng.normal(0.0, self.params.torque_bias, self.model.nv)
        self.observer = JointTorqueObserver(
            self.model,
            self.data,
            fr3_model.JOINT_TORQUE_SENSORS,
            self.params.wrench_cutoff,
            self.params.torque_noise,
            rng,
            self.params.output_cutoff,
        )
        self._hand = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, fr3_model.HAND)
        #: the part's tip (site id), for :mod:`~teachfit.robot.franka.twin_trace`
        self.tcp_site = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, fr3_model.TCP_SITE)
        #: a contact trace written every tick (``teachfit robot twin --trace``), or None
        self.trace: ContactTrace | None = None
        self._kernel_args = self._observer_args()
        # the fr3 robot's joint constants, for the Stribeck term of each step (no limit checks)
        self._joints = (np.zeros(0), np.zeros(0), np.zeros(0), *cell.stribeck())
        self._jac = np.zeros((6, self.model.nv))
        #: a scripted hand (:mod:`teachfit.robot.franka.twin_hand`), idle until a guide comes
        self.hand = TwinHand(self.model, self.data, task, HandParams())

    @property
    def hand_body(self) -> int:
        """The hand's body id (the held part hangs below it)."""
        return int(self._hand)

    def start_q(self) -> np.ndarray:
        """Joint angles (rad) placing the TCP at ``params.start`` from the hole's contact pose."""
        pose = self.task.contact_pose(np.zeros(2)).translated(list(self.params.start))
        q0 = np.array(READY_Q)
        return solve_ik(self.model, fr3_model.TCP_SITE, pose, q0, q0).q

    def _observer_args(self) -> tuple[Any, ...]:
        """The compiled observer's arguments (the fr3 robot's layout; no wrist sensor here)."""
        m, d, obs = self.model, self.data, self.observer
        dat = kernel.data_views(d, self.tcp_site)
        z6 = np.zeros(6)
        bufs = (*obs.bufs, 0, z6, obs.coef, obs.tau_out, obs.tau_z, np.zeros(6), np.zeros((2, 6)))
        sc = np.zeros(kernel.N_SCALARS)
        sc[kernel.ALPHA], sc[kernel.INV_DT] = obs.alpha, 1.0 / float(m.opt.timestep)
        return (kernel.routines(), m._address, d._address, dat, bufs, sc)

    # ------------------------------------------------------------------ BaseSimulator
    def _start(self) -> None:
        m, d = self.model, self.data
        self.robot.attach(m, d)
        mujoco.mj_resetData(m, d)
        d.qpos[self.robot._qpos_addrs] = self.robot.initial_q
        mujoco.mj_forward(m, d)
        self.observer.reset()
        self.hand.guide = None

    def _get_robots(self) -> list[Any]:
        return [self.robot]

    def _step(self) -> None:
        """One physics step (the joints' Stribeck term included, as on the fr3 robot), then
        the observer on the step's torques (``qM``, ``qfrc_bias``
        still hold the step's start, as the observer expects)."""
        fns, m_ptr, d_ptr, dat, bufs, sc = self._kernel_args
        if sc[kernel.NOISE_I] >= len(self.observer.noise):
            self.observer.draw_noise()
            sc[kernel.NOISE_I] = 0.0
        bufs[0][:] = self.data.qvel  # dq before the step
        self.hand.apply()  # a person's push: external, so the observer sees it
        kernel.step_physics(fns, m_ptr, d_ptr, dat, self._joints)
        kernel.observe(fns, m_ptr, d_ptr, dat, bufs, sc)
        if self.trace is not None:
            self.trace.record(self)

    def joints(self) -> tuple[np.ndarray, np.ndarray]:
        """The arm's joint angles (7,) (rad) and speeds (7,) (rad/s)."""
        r, d = self.robot, self.data
        return d.qpos[r._qpos_addrs], d.qvel[r._dof_addrs]

    # ------------------------------------------------------------------ the estimate
    def external_torques(self) -> np.ndarray:
        """The estimated external joint torques (7,) (N·m), *the environment's on the arm*
        (after the sensors' offsets)."""
        return self.observer.tau_out + self.bias

    def ee_frame(self) -> tuple[np.ndarray, np.ndarray]:
        """libfranka's EE frame in the world: position (3,) (m) and rotation (3, 3)."""
        d = self.data
        rot = d.xmat[self._hand].reshape(3, 3)
        return d.xpos[self._hand] + rot[:, 2] * EE_OFFSET, rot.copy()

    def external_wrench(self, ee_t_k: np.ndarray) -> np.ndarray:
        """``O_F_ext_hat_K`` (6,): the estimated wrench at the stiffness frame ``K``
        (``ee_t_k``, 4x4, in EE) in base-frame axes (N, N·m), in libfranka's sign.

        Sign: libfranka reports the wrench *the robot exerts on the environment* (the
        counterforce of what acts on the arm): pulling the hand along +z reads negative z
        (libfranka issue #26, "swapped orientation of the F_ext force components?", closed
        by Franka; teachfit's driver reads it so, :mod:`teachfit.robot.franka.tick`). So
        ``O_F_ext_hat_K = -pinv(J_K^T) tau_ext`` with ``tau_ext`` the environment's torques
        and ``J_K`` the Jacobian of the point K (world = base axes; the base is only
        translated). Pressing the part down on the fixture reads negative z.
        """
        p_ee, r_ee = self.ee_frame()
        point = p_ee + r_ee @ ee_t_k[:3, 3]
        jac = self._jac
        mujoco.mj_jac(self.model, self.data, jac[:3], jac[3:], point, self._hand)
        on_arm = np.linalg.lstsq(jac.T, self.external_torques(), rcond=None)[0]
        return -on_arm
