"""Rigid transforms for capture: validation, inversion, small SE(3) helpers, TOML formatting.

Transforms are (4, 4) homogeneous matrices named ``a2b``: ``p_b = a2b @ p_a`` (so ``cam2rig``
maps camera coordinates to rig coordinates). Rotations use rotation vectors (axis * angle, rad).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.core.errors import CaptureError

__all__ = [
    "ROTATION_TOL",
    "checked_transform",
    "invert",
    "rotation_angle_deg",
    "skew",
    "toml_matrix",
    "transform",
]

ROTATION_TOL = 1e-6
"""Largest ``|R^T R - I|`` (max abs entry) and ``|det R - 1|`` accepted for a rotation."""


def checked_transform(value: object, what: str) -> np.ndarray:
    """A read-only (4, 4) float copy of ``value``, or :class:`CaptureError` naming ``what``.

    Accepts a (4, 4) homogeneous matrix whose last row is ``[0, 0, 0, 1]`` and whose upper-left
    (3, 3) block is a proper rotation (``R^T R = I`` and ``det R = +1`` within
    :data:`ROTATION_TOL`); a (3, 4) matrix gets the last row appended.
    """
    try:
        T = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise CaptureError(f"{what}: not a numeric matrix ({exc})") from exc
    if T.shape == (3, 4):
        T = np.vstack([T, [0.0, 0.0, 0.0, 1.0]])
    if T.shape != (4, 4):
        raise CaptureError(f"{what}: expected a 4x4 (or 3x4) matrix, got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        raise CaptureError(f"{what}: contains NaN or inf")
    if not np.allclose(T[3], [0.0, 0.0, 0.0, 1.0], atol=ROTATION_TOL):
        raise CaptureError(f"{what}: last row must be [0, 0, 0, 1], got {T[3].tolist()}")
    R = T[:3, :3]
    ortho = float(np.abs(R.T @ R - np.eye(3)).max())
    det = float(np.linalg.det(R))
    if ortho > ROTATION_TOL or abs(det - 1.0) > ROTATION_TOL:
        raise CaptureError(
            f"{what}: the 3x3 block is not a rotation matrix (max |R^T R - I| = {ortho:.2e}, "
            f"det = {det:.6f}; need orthonormal with det +1)"
        )
    T.setflags(write=False)
    return T


def transform(rotvec: np.ndarray, trans: np.ndarray) -> np.ndarray:
    """(4, 4) transform from a rotation vector (3,) in rad and a translation (3,)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.asarray(rotvec, dtype=float).reshape(3)).as_matrix()
    T[:3, 3] = np.asarray(trans, dtype=float).reshape(3)
    return T


def invert(T: np.ndarray) -> np.ndarray:
    """Inverse of a rigid (4, 4) transform: ``[R^T, -R^T t]``."""
    out = np.eye(4)
    R = T[:3, :3]
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ T[:3, 3]
    return out


def skew(v: np.ndarray) -> np.ndarray:
    """(3, 3) cross-product matrix ``[v]x`` with ``[v]x @ w = v x w``."""
    x, y, z = np.asarray(v, dtype=float)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rotation_angle_deg(R: np.ndarray) -> np.ndarray:
    """Angle(s) in degrees of rotation matrices (..., 3, 3), by scipy (``Rotation.magnitude``:
    accurate for small angles too, where ``acos((trace R - 1) / 2)`` loses digits)."""
    R = np.asarray(R, dtype=float)
    angle = Rotation.from_matrix(R.reshape(-1, 3, 3)).magnitude()
    deg = np.degrees(angle)
    return deg[0] if R.ndim == 2 else deg.reshape(R.shape[:-2])


def toml_matrix(M: np.ndarray, indent: str = "") -> str:
    """A matrix or vector as a TOML array literal, rows on their own lines, full precision."""
    M = np.asarray(M, dtype=float)
    if M.ndim == 1:
        return "[" + ", ".join(repr(float(v)) for v in M) + "]"
    rows = [indent + "  " + toml_matrix(row) + "," for row in M]
    return "[\n" + "\n".join(rows) + "\n" + indent + "]"
