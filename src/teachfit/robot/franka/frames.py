"""Frames of the Franka driver: robot base vs task world, libfranka's EE frame vs teachfit's TCP.

* ``base2world`` places the robot base in the task's world frame
  (``p_world = R p_base + t``). The default puts the task cell (world origin) 0.5 m in front of
  the base and 0.25 m above it, within the FR3's comfortable reach with the tool pointing down.
* libfranka reports ``O_T_EE``: the end-effector frame ``EE`` (the flange plus ``F_T_EE``,
  by default the Franka Hand's fingertip centre, z pointing away from the flange) in the base
  frame ``O``. teachfit's TCP is the *lowest point of the held part* with its z axis pointing
  back up the part (:mod:`teachfit.tasks.base`). ``ee2tcp`` is that offset: by default the part's
  top sits at the EE frame and its tip ``held_part_length`` further out, z flipped (a rotation of
  pi about x), so a TCP quaternion of identity means "part pointing straight down".
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from teachfit.core.geometry import Pose, rotation_to_wxyz, wxyz_to_rotation

#: the task cell 0.5 m in front of and 0.25 m above the robot base
DEFAULT_BASE2WORLD = Pose(np.array([-0.5, 0.0, -0.25]))
_FLIP_X = np.array([0.0, 1.0, 0.0, 0.0])  # w-x-y-z: rotation of pi about x


def ee2tcp_for_part(held_part_length: float) -> Pose:
    """The EE -> TCP offset for a part of ``held_part_length`` (m) held with its top at EE."""
    return Pose(np.array([0.0, 0.0, float(held_part_length)]), _FLIP_X)


@dataclass(frozen=True)
class FrankaFrames:
    """Where the robot sits in the task world and where its TCP is on the flange.

    Parameters
    ----------
    base2world : Pose
        The robot base frame ``O`` in the task world frame.
    ee2tcp : Pose
        teachfit's TCP in libfranka's end-effector frame ``EE`` (``O_T_EE``).
    """

    base2world: Pose = field(default_factory=lambda: DEFAULT_BASE2WORLD)
    ee2tcp: Pose = field(default_factory=lambda: ee2tcp_for_part(0.0))

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """``(W_T_O, EE_T_TCP)`` as 4x4 homogeneous matrices."""
        return self.base2world.matrix, self.ee2tcp.matrix


def col_major(values: object) -> np.ndarray:
    """A 4x4 matrix from libfranka's 16 column-major values (``O_T_EE``, ``F_T_EE``, ...)."""
    return np.asarray(values, dtype=float).reshape(4, 4, order="F")


def skew(v: np.ndarray) -> np.ndarray:
    """The cross-product matrix of ``v`` (3,)."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def approach_waypoints(
    start: Pose, goal: Pose, speed: float, ang_speed: float, dt: float
) -> list[Pose]:
    """Poses from ``start`` to ``goal`` every ``dt`` s at most ``speed`` (m/s) and
    ``ang_speed`` (rad/s), with a smooth (cosine) start and stop; the goal is the last one."""
    dist = float(np.linalg.norm(goal.pos - start.pos))
    r0, r1 = wxyz_to_rotation(start.quat), wxyz_to_rotation(goal.quat)
    angle = float((r0.inv() * r1).magnitude())
    # a cosine profile peaks at pi/2 times the mean speed
    duration = max(0.5 * np.pi * dist / speed, 0.5 * np.pi * angle / ang_speed, dt)
    s = np.linspace(0.0, 1.0, int(np.ceil(duration / dt)) + 1)[1:]
    s = 0.5 - 0.5 * np.cos(np.pi * s)
    quats = rotation_to_wxyz(Slerp([0.0, 1.0], Rotation.concatenate([r0, r1]))(s))
    return [Pose(start.pos + a * (goal.pos - start.pos), q) for a, q in zip(s, quats, strict=True)]
