"""The planner's settings and the outcome of one query (values, and the path written to a file)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teachfit.core.atomic import atomic_path
from teachfit.core.errors import PlanningError
from teachfit.core.geometry import Pose, array_to_poses, poses_to_array, poses_to_matrices
from teachfit.plans.keyposes import KeyPoses
from teachfit.plans.ompl_space import PLANNERS

__all__ = ["PlanResult", "PlannerConfig"]


@dataclass(frozen=True)
class PlannerConfig:
    """Settings of :class:`MotionPlanner`.

    Attributes
    ----------
    planner : str
        OMPL planner, a key of :data:`PLANNERS` (paper: a RRT-Connect variant).
    te : float or None
        Time budget (s) of one attempt; when exceeded the next key pose is inserted. The paper
        used 5 s with Panda3D's collision checks in Python; t_e is in effect a budget of
        samples, ~200 of our checks by default (None): 0.002 s on parts made of boxes (~10 us
        a check), 0.02 s on meshes (~0.1 ms): RRT-Connect's short detours; the key poses do
        the rest.
    max_checks : int or None
        Budget of one attempt in collision checks instead of ``te`` seconds (``te`` is then
        ignored): the result of a query no longer depends on the machine's speed or load.
    resolution : float
        Longest motion (m; rotations count as the motion of the part's farthest vertex) that
        OMPL checks without an intermediate state.
    verify_resolution : float
        Same, for the final dense verification of the path.
    shortcut : bool
        Shortcut the path (OMPL's ``reduceVertices``).
    smooth_steps : int
        B-spline smoothing passes (OMPL's ``smoothBSpline``); 0 disables smoothing.
    repair_samples : int
        Samples per radius when looking for the collision-free pose nearest a key pose.
    first_key_poses : int
        Number of ranked key poses in the first attempt (paper: 0).
    key_region : float or None
        Candidate key poses are taken where the demonstrated part is closer than this (m) to
        the fixed part (the paper's "important area"); 0 takes them anywhere, None uses the
        assembly's ``key_region``.
    """

    planner: str = "RRTConnect"
    te: float | None = None
    resolution: float = 0.0005
    verify_resolution: float = 0.0005
    shortcut: bool = True
    smooth_steps: int = 2
    repair_samples: int = 64
    first_key_poses: int = 0
    key_region: float | None = None
    max_checks: int | None = None

    def __post_init__(self) -> None:
        if self.planner not in PLANNERS:
            raise PlanningError(f"unknown planner {self.planner!r}; known: {', '.join(PLANNERS)}")
        te_ok = self.te is None or self.te > 0
        if not te_ok or not self.resolution > 0 or not self.verify_resolution > 0:
            raise PlanningError("te, resolution and verify_resolution must be > 0")
        if self.max_checks is not None and self.max_checks < 1:
            raise PlanningError(f"max_checks must be >= 1 or None, got {self.max_checks}")
        if (
            self.smooth_steps < 0
            or self.repair_samples < 1
            or self.first_key_poses < 0
            or (self.key_region is not None and self.key_region < 0)
        ):
            raise PlanningError(
                "smooth_steps, repair_samples, first_key_poses, key_region must be >= 0"
            )


@dataclass(frozen=True, eq=False)
class PlanResult:
    """Outcome of one planning query.

    Attributes
    ----------
    success : bool
        A path was found and passed dense verification.
    path : (N, 7) float
        The OMPL states ``[x, y, z, qw, qx, qy, qz]`` of ``L2G`` from start to goal (empty on
        failure); outside the planner use :attr:`poses`.
    time_s : float
        Planning time (s): ranking the key poses and the attempts, up to a collision-free path
        (what the paper's Table I reports).
    total_s : float
        Wall time of the whole query including shortcutting, smoothing and verification (s).
    attempts : int
        Attempts made (each with one more key pose than the previous).
    used_key_poses, candidates, replaced_key_poses : int
        Key poses in the successful attempt, candidates available, key poses that were in
        collision and were replaced.
    collision_checks : int
        Collision checks made.
    planner : str
        OMPL planner used.
    message : str
        Why it failed, or ``"ok"``.
    key_poses : KeyPoses or None
        The ranked candidates (None without demonstration).
    """

    success: bool
    path: np.ndarray
    time_s: float
    total_s: float
    attempts: int
    used_key_poses: int
    candidates: int
    replaced_key_poses: int
    collision_checks: int
    planner: str
    message: str
    key_poses: KeyPoses | None = None

    @property
    def poses(self) -> tuple[Pose, ...]:
        """The path as poses ``L2G`` (m, w-x-y-z) from start to goal (empty on failure)."""
        return array_to_poses(self.path)

    def L2G(self) -> np.ndarray:
        """(N, 4, 4) path as homogeneous transforms."""
        return poses_to_matrices(self.poses)

    def save(self, path: str | Path) -> Path:
        """Write the path to ``path`` (``.npy``) as (N, 7) rows ``x, y, z`` (m), ``qw, qx, qy,
        qz``, atomically (nothing is left behind on failure); return ``path``."""
        with atomic_path(path, "path file") as tmp, open(tmp, "xb") as fh:
            np.save(fh, poses_to_array(self.poses))
        return Path(path)
