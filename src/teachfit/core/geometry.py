"""The one geometry kernel: rigid poses, rotations and the quaternion conventions of teachfit.

Quaternions are ``(w, x, y, z)`` (MuJoCo's order), unit norm. A pose ``tool2world`` maps tool
coordinates to world coordinates: ``p_world = R(quat) @ p_tool + pos``.

Two tiers, one convention:

* :class:`Pose` and the array functions go through ``scipy.spatial.transform.Rotation``
  (batched, any shape).
* The ``*_into`` functions are the per-tick kernel of the 1 kHz control and skill loops: they
  write into preallocated buffers and call MuJoCo's quaternion routines (``mju_mulQuat``,
  ``mju_subQuat``, ...). Why not scipy here: one ``Rotation`` round trip costs ~100 µs per call
  on this machine against ~3 µs for MuJoCo's C routines, and a control tick has ~30 µs to spare.
  Nothing else in teachfit does quaternion arithmetic.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from teachfit.core.errors import TeachfitError

IDENTITY_QUAT = np.array([1.0, 0.0, 0.0, 0.0])


def wxyz_to_rotation(quat: np.ndarray) -> Rotation:
    """A scipy ``Rotation`` from ``(..., 4)`` quaternions in ``w, x, y, z`` order."""
    q = np.asarray(quat, dtype=float)
    return Rotation.from_quat(np.concatenate([q[..., 1:], q[..., :1]], axis=-1))


def rotation_to_wxyz(rot: Rotation, *, canonical: bool = True) -> np.ndarray:
    """``(..., 4)`` quaternions in ``w, x, y, z`` order, with ``w >= 0`` when ``canonical``.

    ``canonical=False`` keeps scipy's sign: for callers whose results must stay bit for bit
    what they were (the planner's seeded OMPL states).
    """
    q = rot.as_quat()
    q = np.concatenate([q[..., 3:], q[..., :3]], axis=-1)
    if not canonical:
        return q
    sign = np.where(q[..., :1] < 0, -1.0, 1.0)
    return q * sign


def quat_from_rz(angle: float | np.ndarray) -> np.ndarray:
    """Quaternion(s) ``(..., 4)`` of a rotation by ``angle`` rad about the world z-axis."""
    a = np.asarray(angle, dtype=float) / 2.0
    zeros = np.zeros_like(a)
    return np.stack([np.cos(a), zeros, zeros, np.sin(a)], axis=-1)


def rz_from_quat(quat: np.ndarray) -> np.ndarray:
    """Rotation about z (yaw, rad) of ``(..., 4)`` quaternions, by the z-y-x Euler convention."""
    q = np.asarray(quat, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quat_angle(q: np.ndarray, qs: np.ndarray) -> np.ndarray:
    """Angle (rad, in ``[0, pi]``) of the rotation between unit (4,) ``q`` and each of ``qs``
    (N, 4), w-x-y-z: ``2 arccos |q . qs|`` (sign-blind, one batched numpy expression)."""
    dot = np.clip(np.abs(np.asarray(qs, dtype=float) @ np.asarray(q, dtype=float)), 0.0, 1.0)
    return 2 * np.arccos(dot)


def yaw_of(quat: np.ndarray) -> float:
    """Yaw (rad, in ``(-pi, pi]``) of one (4,) w-x-y-z quaternion: :func:`rz_from_quat`."""
    return float(rz_from_quat(quat))


@dataclass(frozen=True)
class Pose:
    """A rigid pose: position ``pos`` (3,) in metres and unit quaternion ``quat`` (4,) w-x-y-z."""

    pos: np.ndarray
    quat: np.ndarray = field(default_factory=lambda: IDENTITY_QUAT.copy())

    def __post_init__(self) -> None:
        # the same checks in Python on the lists (the execution loop builds a Pose every 10 ms
        # command: numpy's reductions on 3-4 elements cost ~10 µs together); the values are
        # those of np.linalg.norm (sqrt of x.dot(x)) and of the copies np.array makes
        pos = np.array(self.pos, dtype=float).reshape(-1)
        quat = np.array(self.quat, dtype=float).reshape(-1)
        if pos.shape != (3,) or quat.shape != (4,):
            raise TeachfitError(f"Pose needs pos (3,) and quat (4,), got {pos.shape}, {quat.shape}")
        if not all(map(math.isfinite, pos.tolist() + quat.tolist())):
            raise TeachfitError("Pose contains NaN or inf")
        norm = math.sqrt(float(quat.dot(quat)))
        if abs(norm - 1.0) > 1e-3:
            raise TeachfitError(f"Pose quaternion must have unit norm, has {norm:.6f}")
        quat = quat / norm
        pos.setflags(write=False)
        quat.setflags(write=False)
        object.__setattr__(self, "pos", pos)
        object.__setattr__(self, "quat", quat)

    @property
    def rotation(self) -> Rotation:
        return wxyz_to_rotation(self.quat)

    @property
    def matrix(self) -> np.ndarray:
        """Homogeneous transform (4, 4)."""
        out = np.eye(4)
        out[:3, :3] = self.rotation.as_matrix()
        out[:3, 3] = self.pos
        return out

    @property
    def rz(self) -> float:
        return float(rz_from_quat(self.quat))

    def compose(self, other: Pose) -> Pose:
        """``self * other``: e.g. ``search2world.compose(tool2search) == tool2world``."""
        rot = self.rotation
        return Pose(
            self.pos + rot.apply(np.array(other.pos)), rotation_to_wxyz(rot * other.rotation)
        )

    def inverse(self) -> Pose:
        inv = self.rotation.inv()
        return Pose(-inv.apply(np.array(self.pos)), rotation_to_wxyz(inv))

    def translated(self, delta: ArrayLike) -> Pose:
        return Pose(self.pos + np.asarray(delta, dtype=float), self.quat)

    @classmethod
    def from_xyz_rz(cls, x: float, y: float, z: float, rz: float = 0.0) -> Pose:
        return cls(np.array([x, y, z]), quat_from_rz(rz))

    @classmethod
    def from_matrix(cls, T: np.ndarray) -> Pose:
        """Pose of a (4, 4) homogeneous transform (rotation part orthonormalised by scipy)."""
        T = np.asarray(T, dtype=float)
        if T.shape != (4, 4):
            raise TeachfitError(f"Pose.from_matrix needs a (4, 4) transform, got {T.shape}")
        return cls(T[:3, 3], rotation_to_wxyz(Rotation.from_matrix(T[:3, :3])))

    @classmethod
    def from_array(cls, state: np.ndarray) -> Pose:
        """Pose of a (7,) array ``[x, y, z, qw, qx, qy, qz]`` (m, w-x-y-z)."""
        state = np.asarray(state, dtype=float).reshape(-1)
        if state.shape != (7,):
            raise TeachfitError(f"a pose array has 7 numbers, got {state.shape}")
        return cls(state[:3], state[3:])

    def as_array(self) -> np.ndarray:
        """(7,) ``[x, y, z, qw, qx, qy, qz]`` (m, w-x-y-z)."""
        return np.concatenate([self.pos, self.quat])


def poses_to_array(poses: Sequence[Pose]) -> np.ndarray:
    """(N, 7) ``[x, y, z, qw, qx, qy, qz]`` rows of ``poses`` ((0, 7) when empty)."""
    if len(poses) == 0:
        return np.empty((0, 7))
    return np.stack([p.as_array() for p in poses])


def array_to_poses(states: np.ndarray) -> tuple[Pose, ...]:
    """Poses of (N, 7) rows ``[x, y, z, qw, qx, qy, qz]`` (m, w-x-y-z)."""
    states = np.asarray(states, dtype=float)
    if states.ndim != 2 or states.shape[1] != 7:
        raise TeachfitError(f"pose arrays are (N, 7), got {states.shape}")
    return tuple(Pose(s[:3], s[3:]) for s in states)


def poses_to_matrices(poses: Sequence[Pose]) -> np.ndarray:
    """(N, 4, 4) homogeneous transforms of ``poses`` (one scipy call for all)."""
    out = np.tile(np.eye(4), (len(poses), 1, 1))
    if len(poses):
        out[:, :3, :3] = wxyz_to_rotation(np.stack([p.quat for p in poses])).as_matrix()
        out[:, :3, 3] = np.stack([p.pos for p in poses])
    return out


# ------------------------------------------------------------------ per-tick kernel (in place)
def quat_mul_into(out: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``out = a ⊗ b`` for (4,) quaternions (w-x-y-z); ``out`` may not alias ``a`` or ``b``."""
    mujoco.mju_mulQuat(out, a, b)
    return out


def quat_conj_into(out: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``out = q^-1`` (the conjugate of a unit quaternion)."""
    mujoco.mju_negQuat(out, q)
    return out


def quat_rotate_into(out: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``out = R(q) v`` for a (3,) vector."""
    mujoco.mju_rotVecQuat(out, v, q)
    return out


def quat_diff_into(out: np.ndarray, qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
    """Rotation vector ``r`` (3,) in ``qb``'s own frame with ``qb ⊗ exp(r) = qa`` (rad)."""
    mujoco.mju_subQuat(out, qa, qb)
    return out


def quat_integrate_into(q: np.ndarray, omega: np.ndarray, dt: float) -> np.ndarray:
    """``q ← q ⊗ exp(ω dt)`` in place, ``ω`` (3,) rad/s in ``q``'s own frame."""
    mujoco.mju_quatIntegrate(q, omega, dt)
    return q


def quat_normalize_into(q: np.ndarray) -> float:
    """Normalise (4,) ``q`` in place; returns its norm before. A norm below ~1e-15 leaves the
    identity (MuJoCo's choice): callers that must reject a zero quaternion test the norm."""
    return float(mujoco.mju_normalize4(q))


def quat_to_matrix_into(out: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``out`` (9,) = row-major rotation matrix of a unit (4,) ``q`` (not normalised here).

    The per-collision-check form (the planner's validity checker): ~2 µs against ~100 µs for
    ``Rotation.from_quat(q).as_matrix()``; ``out.reshape(3, 3)`` is the (3, 3) view.
    """
    mujoco.mju_quat2Mat(out, q)
    return out


def quat_to_rotvec_into(out: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Rotation vector (3,) of ``q`` (axis times angle, rad)."""
    mujoco.mju_quat2Vel(out, q, 1.0)
    return out
