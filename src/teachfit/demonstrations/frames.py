"""Frame transforms applied on import, and quaternion component orders.

A robot logs its tool pose in some frame of its own (for a Franka Panda ``panda_link0``, the
robot base). teachfit's tasks live in the simulation world. On import a log can be

* re-expressed in another frame with a fixed transform ``log2target`` (the pose of the log's
  frame in the target frame: ``p_target = R @ p_log + pos``), or
* re-anchored at its first pose (``"first-pose"``): positions relative to the first position,
  axes and orientations unchanged. This is the translation part of the search frame
  (:func:`teachfit.models.search_data.search_data` keeps the recording frame's axes), so the
  learned model is the same; only the stored start pose becomes the origin.

The transform used is recorded in the demonstration: ``frame`` names the new frame,
``meta["source_frame"]`` the log's and ``meta["source2frame"]`` the pose
``[x, y, z, qw, qx, qy, qz]`` (m, w-x-y-z) of the log's frame in the new one.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from teachfit.core.errors import DatasetError
from teachfit.core.geometry import rotation_to_wxyz, wxyz_to_rotation

QUAT_ORDERS: tuple[str, ...] = ("w,x,y,z", "x,y,z,w")
FIRST_POSE = "first-pose"


def to_wxyz(quat: np.ndarray, order: str) -> np.ndarray:
    """Quaternions (T, 4) given in component ``order`` (one of :data:`QUAT_ORDERS`) as w-x-y-z."""
    if order not in QUAT_ORDERS:
        raise DatasetError(f"must be one of {QUAT_ORDERS}, got {order!r}", column="quat_order")
    q = np.asarray(quat, dtype=float)
    return q if order == "w,x,y,z" else q[..., [3, 0, 1, 2]]


def from_wxyz(quat: np.ndarray, order: str) -> np.ndarray:
    """Quaternions (T, 4) w-x-y-z as their components in ``order`` (the inverse of
    :func:`to_wxyz`)."""
    if order not in QUAT_ORDERS:
        raise DatasetError(f"must be one of {QUAT_ORDERS}, got {order!r}", column="quat_order")
    q = np.asarray(quat, dtype=float)
    return q if order == "w,x,y,z" else q[..., [1, 2, 3, 0]]


@dataclass(frozen=True)
class FrameTransform:
    """How an imported log is re-expressed before it is stored.

    Parameters
    ----------
    to : str
        Name of the frame the demonstration is stored in. Ignored for ``first_pose`` (the new
        frame is then called ``"<log frame>_start"``).
    pos : tuple of float
        Origin of the log's frame in ``to`` (m, 3 values).
    quat : tuple of float
        Orientation of the log's frame in ``to`` (unit quaternion, w-x-y-z, 4 values).
    first_pose : bool
        Re-anchor at the first pose instead: subtract the first position, keep the axes.
    """

    to: str = "world"
    pos: tuple[float, ...] = (0.0, 0.0, 0.0)
    quat: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0)
    first_pose: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.to, str) or not self.to:
            raise DatasetError(f"'to' must be a non-empty string, got {self.to!r}", column="to")
        for label, size in (("pos", 3), ("quat", 4)):
            value = getattr(self, label)
            ok = isinstance(value, list | tuple) and len(value) == size
            if not ok or not all(_is_real(v) and math.isfinite(v) for v in value):
                raise DatasetError(
                    f"must be a list of {size} finite numbers, got {value!r}", column=label
                )
            object.__setattr__(self, label, tuple(float(v) for v in value))
        norm = math.sqrt(sum(v * v for v in self.quat))
        if abs(norm - 1.0) > 1e-3:
            raise DatasetError(
                f"must be a unit quaternion w, x, y, z (norm {norm:.6g})", column="quat"
            )

    @classmethod
    def parse(cls, value: Any) -> FrameTransform:
        """From a map value: ``"first-pose"`` or a table ``{to, pos, quat}``; or a CLI string
        ``"first-pose"`` / ``"TO:x,y,z,qw,qx,qy,qz"``."""
        if value == FIRST_POSE:
            return cls(first_pose=True)
        if isinstance(value, str):
            to, sep, numbers = value.rpartition(":")
            try:
                cells = [float(c) for c in numbers.split(",")]
            except ValueError:
                cells = []
            if not sep or len(cells) != 7:
                raise DatasetError(
                    f"expected {FIRST_POSE!r} or 'FRAME:x,y,z,qw,qx,qy,qz', got {value!r}",
                    column="transform",
                )
            return cls(to=to, pos=tuple(cells[:3]), quat=tuple(cells[3:]))
        if not isinstance(value, Mapping):
            raise DatasetError(
                f"expected {FIRST_POSE!r} or a table with to, pos, quat; got {value!r}",
                column="transform",
            )
        unknown = sorted(set(value) - {"to", "pos", "quat"})
        if unknown or "to" not in value:
            problem = f"unknown key {unknown[0]!r}" if unknown else "needs 'to'"
            raise DatasetError(f"[transform] {problem} (keys: to, pos, quat)", column="transform")
        return cls(**dict(value))

    def target(self, frame: str) -> str:
        """Name of the frame a log recorded in ``frame`` is stored in."""
        return f"{frame}_start" if self.first_pose else self.to

    def apply(
        self, pos: np.ndarray, quat: np.ndarray, wrench: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, list[float]]:
        """Re-express positions (T, 3) m, quaternions (T, 4) w-x-y-z and wrenches (T, 6).

        Returns the new arrays and the pose ``[x, y, z, qw, qx, qy, qz]`` of the log's frame in
        the new frame. Forces and torques are rotated (the torque reference point, the tool, is
        unchanged).
        """
        if self.first_pose:
            origin = [float(-v) for v in pos[0]] + [1.0, 0.0, 0.0, 0.0]
            return pos - pos[0], quat, wrench, origin
        rot = wxyz_to_rotation(np.array(self.quat))
        new_pos = rot.apply(pos) + np.array(self.pos)
        new_quat = rotation_to_wxyz(rot * wxyz_to_rotation(quat))
        new_wrench = None
        if wrench is not None:
            new_wrench = np.hstack([rot.apply(wrench[:, :3]), rot.apply(wrench[:, 3:])])
        return new_pos, new_quat, new_wrench, [*self.pos, *self.quat]


def _is_real(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)
