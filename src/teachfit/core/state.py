"""What a robot measures and what it is commanded: values every layer shares.

Frames and units: positions in metres, quaternions ``w, x, y, z``, twists ``[v; w]`` in m/s and
rad/s, wrenches ``[f; tau]`` in N and N·m, all in the world frame at the tool centre point (TCP).
The measured wrench is the one the *environment exerts on the tool*.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from teachfit.core.errors import ControlError
from teachfit.core.geometry import IDENTITY_QUAT, Pose


def _vec(value: object, n: int, name: str) -> np.ndarray:
    arr = np.array(value, dtype=float).reshape(-1)
    if arr.shape != (n,):
        raise ControlError(f"{name} must have {n} elements, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ControlError(f"{name} contains NaN or inf")
    arr.setflags(write=False)
    return arr


def _gain(value: object, name: str) -> np.ndarray:
    """A (6, 6) symmetric positive semi-definite gain from a scalar, (6,) diagonal or (6, 6)."""
    arr = np.array(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(6, float(arr))
    if arr.shape == (6,):
        arr = np.diag(arr)
    if arr.shape != (6, 6):
        raise ControlError(f"{name} must be a scalar, (6,) or (6, 6), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ControlError(f"{name} contains NaN or inf")
    diag = np.diagonal(arr)
    if np.count_nonzero(arr) == np.count_nonzero(diag):  # diagonal (skills send these each
        # command period): symmetric, and positive semi-definite iff no diagonal entry < 0
        if diag.min() < -1e-9 * max(1.0, np.abs(diag).max()):
            raise ControlError(f"{name} must be positive semi-definite")
        arr.setflags(write=False)
        return arr
    b = arr[0, 1]
    if b == arr[1, 0] and np.count_nonzero(arr) == np.count_nonzero(diag) + 2 and b != 0:
        # a symmetric x-y block on a diagonal (aligned_stiffness, sent every command period):
        # its eigenvalues in closed form instead of eigvalsh, the same test
        a, d = arr[0, 0], arr[1, 1]
        low = min(diag.min(), 0.5 * (a + d) - float(np.hypot(0.5 * (a - d), b)))
        if low < -1e-9 * max(1.0, np.abs(arr).max()):
            raise ControlError(f"{name} must be positive semi-definite")
        arr.setflags(write=False)
        return arr
    if not np.allclose(arr, arr.T, atol=1e-9 * max(1.0, np.abs(arr).max())):
        raise ControlError(f"{name} must be symmetric")
    if np.linalg.eigvalsh(arr).min() < -1e-9 * max(1.0, np.abs(arr).max()):
        raise ControlError(f"{name} must be positive semi-definite")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True)
class RobotState:
    """What the robot measures at one instant (world frame, at the TCP)."""

    t: float
    pos: np.ndarray
    quat: np.ndarray
    lin_vel: np.ndarray
    ang_vel: np.ndarray
    wrench: np.ndarray

    @property
    def pose(self) -> Pose:
        return Pose(self.pos, self.quat)

    @property
    def twist(self) -> np.ndarray:
        return np.concatenate([self.lin_vel, self.ang_vel])


_FIELDS = ("pos", "quat", "lin_vel", "ang_vel", "wrench_ff", "stiffness")
_DEFAULTS = {"damping": None, "damping_ratio": 1.0, "expires_after": 0.25}
_F8 = np.dtype(np.float64)


@dataclass(frozen=True)
class ImpedanceCommand:
    """A Cartesian impedance set-point (world frame, at the TCP).

    The controller tracks ``x_d(t) = pos + lin_vel (t - t0)`` (and likewise the orientation)
    between commands, so a robot can be commanded at a lower rate than it controls.

    Parameters
    ----------
    pos, quat : desired TCP pose (m; w-x-y-z).
    lin_vel, ang_vel : desired twist (m/s, rad/s).
    wrench_ff : feed-forward wrench ``[f; tau]`` the robot adds (N, N·m).
    stiffness : scalar, (6,) diagonal, or (6, 6) Cartesian stiffness (N/m, N·m/rad).
    damping : same shapes (N·s/m, N·m·s/rad); ``None`` = critically damped for the robot's
        apparent mass (``damping_ratio``).
    expires_after : s after which the set-point stops being extrapolated with the desired
        twist and is held where it got to (commands that stop arriving cannot drive the robot
        away).
    """

    pos: np.ndarray
    quat: np.ndarray = field(default_factory=lambda: IDENTITY_QUAT.copy())
    lin_vel: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ang_vel: np.ndarray = field(default_factory=lambda: np.zeros(3))
    wrench_ff: np.ndarray = field(default_factory=lambda: np.zeros(6))
    stiffness: np.ndarray = field(default_factory=lambda: np.array([1000.0] * 3 + [50.0] * 3))
    damping: np.ndarray | None = None
    damping_ratio: float = 1.0
    expires_after: float = 0.25

    def __post_init__(self) -> None:
        object.__setattr__(self, "pos", _vec(self.pos, 3, "pos"))
        quat = _vec(self.quat, 4, "quat")
        norm = float(np.linalg.norm(quat))
        if abs(norm - 1.0) > 1e-3:
            raise ControlError(f"quat must have unit norm, has {norm:.6f}")
        quat = quat / norm
        quat.setflags(write=False)
        object.__setattr__(self, "quat", quat)
        object.__setattr__(self, "lin_vel", _vec(self.lin_vel, 3, "lin_vel"))
        object.__setattr__(self, "ang_vel", _vec(self.ang_vel, 3, "ang_vel"))
        object.__setattr__(self, "wrench_ff", _vec(self.wrench_ff, 6, "wrench_ff"))
        object.__setattr__(self, "stiffness", _gain(self.stiffness, "stiffness"))
        if self.damping is not None:
            object.__setattr__(self, "damping", _gain(self.damping, "damping"))
        if not self.expires_after > 0:
            raise ControlError(f"expires_after must be > 0 s, got {self.expires_after}")
        if not self.damping_ratio >= 0:
            raise ControlError(f"damping_ratio must be >= 0, got {self.damping_ratio}")

    @classmethod
    def from_diagonal_frame(
        cls,
        pos: np.ndarray,
        quat: np.ndarray,
        lin_vel: np.ndarray,
        ang_vel: np.ndarray,
        wrench_ff: np.ndarray,
        stiffness: np.ndarray,
        diagonal: np.ndarray,
    ) -> ImpedanceCommand:
        """The command :meth:`__init__` builds, for a ``stiffness`` (6, 6) that the caller
        made as ``B diag(diagonal) B^T`` with ``B`` block-rotation (a task frame's axes):
        symmetric and positive semi-definite whenever ``diagonal >= 0``, so the general
        checks (``allclose``, ``eigvalsh``: ~150 µs, per 10 ms command) are skipped.

        The float arrays given become the command's, read-only and not copied: pass arrays
        nothing else writes (fresh ones, or one read-only ``stiffness`` shared by several
        commands). The values are those :meth:`__init__` stores (the quaternion normalised
        the same way); anything non-finite, a negative ``diagonal`` entry or a non-unit
        ``quat`` goes through :meth:`__init__`, which raises its usual :class:`ControlError`.
        """
        parts = (pos, quat, lin_vel, ang_vel, wrench_ff, stiffness)
        # one finite sum for all (NaN and inf propagate); Python sums of ``tolist`` cost a
        # quarter of numpy's reductions on arrays this small
        total = sum(pos.tolist()) + sum(quat.tolist()) + sum(lin_vel.tolist())
        total += sum(ang_vel.tolist()) + sum(wrench_ff.tolist()) + sum(stiffness.ravel().tolist())
        norm = math.sqrt(float(quat.dot(quat)))  # = np.linalg.norm (sqrt of x.dot(x))
        if not (
            min(diagonal.tolist()) >= 0.0
            and math.isfinite(total)
            and abs(norm - 1.0) <= 1e-3
            and all(a.dtype == _F8 for a in parts)
        ):
            return cls(pos, quat, lin_vel, ang_vel, wrench_ff, stiffness)
        self = object.__new__(cls)
        values = (pos, quat / norm, lin_vel, ang_vel, wrench_ff, stiffness)
        for arr in values:
            arr.setflags(write=False)
        # a frozen dataclass's fields live in its __dict__: one update instead of a
        # object.__setattr__ per field
        self.__dict__.update(zip(_FIELDS, values, strict=True))
        self.__dict__.update(_DEFAULTS)
        return self

    @classmethod
    def hold(cls, pose: Pose, **kwargs: Any) -> ImpedanceCommand:
        """A command that holds ``pose`` still (``kwargs``: the other fields, checked there)."""
        return cls(pos=pose.pos, quat=pose.quat, **kwargs)
