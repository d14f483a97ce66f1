"""OMPL at the planner's boundary: the planners by name, the global seed, state conversions.

States are ``(7,)`` arrays ``[x, y, z, qw, qx, qy, qz]`` (``L2G`` in m, a unit quaternion);
:func:`slerp` interpolates their rotations as OMPL's SE(3) space does.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import ompl.base as ob
import ompl.geometric as og
import ompl.util as ou
from scipy.spatial.transform import Rotation

from teachfit.core.errors import PlanningError
from teachfit.core.geometry import rotation_to_wxyz

__all__ = ["PLANNERS", "matrix_to_state", "seed_ompl", "slerp"]

ou.setLogLevel(ou.LogLevel.LOG_ERROR)

PLANNERS: dict[str, Callable[[ob.SpaceInformation], ob.Planner]] = {
    "RRTConnect": og.RRTConnect,
    "RRT": og.RRT,
    "RRTstar": og.RRTstar,
    "KPIECE1": og.KPIECE1,
    "BKPIECE1": og.BKPIECE1,
    "LBKPIECE1": og.LBKPIECE1,
    "PRM": og.PRM,
}
"""OMPL geometric planners selectable by name."""


def seed_ompl(seed: int) -> None:
    """Seed OMPL's global RNG: every OMPL sampler created afterwards draws from ``seed``.

    OMPL derives the seed of each new random generator (a planner's sampler, a path simplifier)
    from this global one; reseeding after the first draw in a process works (ompl 2.0) but logs
    an error, which is silenced here. OMPL ignores a seed of 0, so ``seed`` maps to ``seed + 1``.

    Raises
    ------
    PlanningError
        ``seed`` is not an integer in ``[0, 2**32 - 2]``.
    """
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise PlanningError(f"seed must be an integer, got {seed!r}")
    if not 0 <= int(seed) <= 2**32 - 2:
        raise PlanningError(f"seed must be in [0, 2**32 - 2], got {seed}")
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    try:
        ou.RNG.setSeed(int(seed) + 1)
    finally:
        ou.setLogLevel(level)


def slerp(qa: np.ndarray, qb: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(N, 4) unit quaternions w-x-y-z from ``qa`` (s = 0) to ``qb`` (s = 1) along the shorter
    arc, as OMPL's SO(3) interpolation. Written out (the textbook formula) because scipy's
    ``Slerp`` costs ~0.5 ms to build per segment, and densifying runs per straight motion."""
    qa = qa / np.linalg.norm(qa)
    qb = qb / np.linalg.norm(qb)
    dot = float(qa @ qb)
    if dot < 0.0:
        qb, dot = -qb, -dot
    theta = np.arccos(min(dot, 1.0))
    if theta < 1e-9:
        return np.tile(qa, (len(s), 1))
    wa, wb = np.sin((1.0 - s) * theta), np.sin(s * theta)
    return (wa[:, None] * qa + wb[:, None] * qb) / np.sin(theta)


def matrix_to_state(T: np.ndarray) -> np.ndarray:
    """(..., 7) states ``[x, y, z, qw, qx, qy, qz]`` of (..., 4, 4) transforms (scipy's
    quaternion sign). A stack converts in one call: scipy's per-call overhead (~0.3 ms) is most
    of the cost of one conversion."""
    T = np.asarray(T, dtype=float)
    q = rotation_to_wxyz(Rotation.from_matrix(T[..., :3, :3]), canonical=False)
    return np.concatenate([T[..., :3, 3], q], axis=-1)
