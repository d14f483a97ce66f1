"""Start configurations of the FR3 by differential inverse kinematics with ``mink``.

For a TCP pose ``T_d`` the joint velocity of each iteration solves mink's QP

    min_v  ||J_tcp v - e(T_d, T(q)) / dt||²  +  w_post ||v - (q_post - q) / dt||²   (+ damping)
    s.t.   q_min <= q + v dt <= q_max

(``FrameTask`` for the TCP site, ``PostureTask`` towards ``q_post``, ``ConfigurationLimit`` for
the joint range), then ``q <- q + v dt``. The posture term picks one solution of the redundant
arm (elbow up, wrist above the flange) and keeps the joints away from their limits; since it
also biases the TCP slightly, ``posture_iterations`` such steps are followed by steps without
it (frame task and limits only) until the TCP is within ``pos_tol`` m and ``rot_tol`` rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import mink
import mujoco
import numpy as np

from teachfit.core.errors import LimitViolation
from teachfit.core.geometry import Pose


@dataclass(frozen=True)
class IKSettings:
    """Solver settings: step ``dt`` (s), weights, tolerances (m, rad), iteration cap."""

    dt: float = 0.05
    posture_cost: float = 1e-2
    damping: float = 1e-4
    pos_tol: float = 1e-6
    rot_tol: float = 1e-5
    posture_iterations: int = 60
    max_iterations: int = 200
    solver: str = "daqp"


@dataclass(frozen=True)
class IKResult:
    """A joint configuration (rad) and the TCP's remaining position/rotation error (m, rad)."""

    q: np.ndarray
    pos_error: float
    rot_error: float
    iterations: int


def solve_ik(
    model: mujoco.MjModel,
    site: str,
    target: Pose,
    q_start: np.ndarray,
    q_posture: np.ndarray,
    settings: IKSettings | None = None,
) -> IKResult:
    """Joint configuration placing ``site`` at ``target`` (world frame); see the module docstring.

    Raises :class:`~teachfit.core.errors.LimitViolation` when the pose cannot be reached within
    the joint limits (the tolerance is not met after ``max_iterations``).
    """
    s = settings or IKSettings()
    config = mink.Configuration(model, q=np.asarray(q_start, dtype=float))
    frame = mink.FrameTask(site, "site", position_cost=1.0, orientation_cost=1.0)
    frame.set_target(
        mink.SE3.from_rotation_and_translation(
            mink.SO3(np.asarray(target.quat, dtype=float)), np.asarray(target.pos, dtype=float)
        )
    )
    posture = mink.PostureTask(model, cost=s.posture_cost)
    posture.set_target(np.asarray(q_posture, dtype=float))
    limits = [mink.ConfigurationLimit(model)]
    pos_err = rot_err = np.inf
    for it in range(1, s.max_iterations + 1):
        tasks = [frame, posture] if it <= s.posture_iterations else [frame]
        vel = mink.solve_ik(config, tasks, s.dt, s.solver, damping=s.damping, limits=limits)
        config.integrate_inplace(vel, s.dt)
        err = frame.compute_error(config)
        pos_err = float(np.linalg.norm(err[:3]))
        rot_err = float(np.linalg.norm(err[3:]))
        if it > s.posture_iterations and pos_err < s.pos_tol and rot_err < s.rot_tol:
            return IKResult(config.q.copy(), pos_err, rot_err, it)
    raise LimitViolation(
        f"IK cannot reach the TCP pose {np.round(target.pos, 4).tolist()} within the joint limits "
        f"(left {pos_err * 1e3:.3f} mm, {np.degrees(rot_err):.3f} deg)"
    )
