"""The scripted hand inside the twin's physics: a guide's force on the held part, every tick.

A person's push is an external force on the arm: :class:`TwinHand` writes it into MuJoCo's
``xfrc_applied`` of the body holding the TCP before each physics step, so the joint torque
sensors, the momentum observer and libfranka's ``O_F_ext_hat_K`` see it as they would see a
person's hand (the client adds nothing to its torques). The force law is
:class:`~teachfit.robot.franka.hand.HandParams`'s (see :mod:`teachfit.robot.franka.hand`),
applied at the TCP; the guide's clock is the simulation's (``MjData.time``) from the tick
after the guide arrived, so in lock-step (``--no-realtime``) it follows the client's ticks.
"""

from __future__ import annotations

import mujoco
import numpy as np

from teachfit.robot.fr3 import model as fr3_model
from teachfit.robot.franka.hand import Guide, HandParams
from teachfit.tasks.base import Task


class TwinHand:
    """A scripted hand on the twin's cell (``model``, ``data``) of ``task``."""

    def __init__(
        self, model: mujoco.MjModel, data: mujoco.MjData, task: Task, params: HandParams
    ) -> None:
        self.model, self.data, self.params = model, data, params
        self._site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, fr3_model.TCP_SITE)
        self._body = int(model.site_bodyid[self._site])
        hole = task.hole2world
        self._hole_pos, self._hole_rot = hole.pos.copy(), hole.rotation.as_matrix()
        self._jac = np.zeros((6, model.nv))
        self.pending: Guide | None = None
        self.guide: Guide | None = None
        self._t0 = 0.0
        self._rot0 = np.eye(3)

    def take(self, guide: Guide) -> None:
        """Start ``guide`` at the next tick (called from the hand channel's thread)."""
        self.pending = guide

    def apply(self) -> None:
        """Set this tick's hand force (zero when no guide runs)."""
        d = self.data
        if self.pending is not None:
            self.guide, self.pending = self.pending, None
            self._t0 = float(d.time) - float(self.guide.t[0])  # guide time = sim time - t0
            self._rot0 = d.site_xmat[self._site].reshape(3, 3).copy()
        if self.guide is None:
            return
        now = self.guide.at(float(d.time) - self._t0)
        if now is None:  # the guide ended: the hand lets go
            self.guide = None
            d.xfrc_applied[self._body] = 0.0
            return
        d.xfrc_applied[self._body] = self.wrench(*now)

    def wrench(self, target: np.ndarray, target_vel: np.ndarray, press: float) -> np.ndarray:
        """The hand's force and torque (6,) on the TCP's body at its centre of mass (world, N,
        N·m), for the hand-frame ``target`` (m), its velocity (m/s) and ``press`` (N)."""
        p, d, m = self.params, self.data, self.model
        jac = self._jac
        mujoco.mj_jacSite(m, d, jac[:3], jac[3:], self._site)
        twist = jac @ d.qvel
        rot = self._hole_rot
        goal = self._hole_pos + rot @ np.array([target[0], target[1], 0.0])
        goal_vel = rot @ np.array([target_vel[0], target_vel[1], 0.0])
        tcp = d.site_xpos[self._site]
        across = p.stiffness * (goal - tcp) + p.damping * (goal_vel - twist[:3])
        across[2] = 0.0
        norm = float(np.linalg.norm(across))
        if norm > p.max_force:
            across *= p.max_force / norm
        force = across + np.array([0.0, 0.0, -press - p.press_damping * twist[2]])
        err = self._rot0 @ d.site_xmat[self._site].reshape(3, 3).T
        angle = 0.5 * np.array(
            [err[2, 1] - err[1, 2], err[0, 2] - err[2, 0], err[1, 0] - err[0, 1]]
        )
        torque = p.rot_stiffness * angle - p.rot_damping * twist[3:]
        tn = float(np.linalg.norm(torque))
        if tn > p.max_torque:
            torque *= p.max_torque / tn
        lever = tcp - d.xipos[self._body]
        return np.concatenate([force, torque + np.cross(lever, force)])
