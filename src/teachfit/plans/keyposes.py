"""Candidate key poses from a demonstration and their ranking.

Wang et al. 2019 (docs/methods.md), the paper's Fig. 6.

The paper's rule (:func:`rank_key_poses`): the demonstration's most violently changing pose
parameter (pitch, for the L) is fitted with a polynomial over time; its derivative at each
candidate key pose ranks the candidates by descending magnitude, so the most decisive poses
are inserted into the planner first.

That rule misses poses where the part moves without turning: on the L-groove the tilted poses
that carry the part through the opening have a near-zero pitch derivative and rank last, yet
no plan exists without them (4-6 of 6 poses used, paper 2-3). :func:`straight_chain` ranks by
what makes a pose decisive for a planner that first tries straight motions: the greedy chain
of candidates, each the farthest one (in demonstration order) that a straight, collision-free
motion reaches from the previous. The planner inserts the chain first (in its order), then the
other candidates by the derivative rule.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from teachfit.core.errors import PlanningError
from teachfit.core.geometry import Pose, wxyz_to_rotation

__all__ = [
    "PARAMS",
    "KeyPoses",
    "pose_parameters",
    "rank_key_poses",
    "select_candidates",
    "straight_chain",
]

PARAMS: tuple[str, ...] = ("x", "y", "z", "roll", "pitch", "yaw")
"""Pose parameters: position of ``L`` in ``G`` (m) and extrinsic x-y-z Euler angles (rad)."""


def pose_parameters(pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
    """(T, 6) ``[x, y, z, roll, pitch, yaw]`` (m, rad; angles unwrapped over time).

    Parameters
    ----------
    pos : (T, 3) positions in m. quat : (T, 4) quaternions w-x-y-z.
    """
    quat = np.asarray(quat, dtype=float)
    rpy = wxyz_to_rotation(quat).as_euler("xyz")
    return np.concatenate([np.asarray(pos, dtype=float), np.unwrap(rpy, axis=0)], axis=1)


def select_candidates(
    pos: np.ndarray,
    quat: np.ndarray,
    n: int,
    *,
    char_length: float = 0.1,
    eligible: np.ndarray | None = None,
    include: np.ndarray | None = None,
) -> np.ndarray:
    """Indices (n,) of candidate key poses, evenly spaced along the demonstration's pose path.

    Parameters
    ----------
    pos : (T, 3) m. quat : (T, 4) w-x-y-z.
    n : int
        Number of candidates wanted.
    char_length : float
        Rotations count as the displacement (m) of a point this far away.
    eligible : (T,) bool, optional
        Samples a key pose may be taken from (the paper's "important area", where the parts
        are close); the path length is measured over them only. All samples when None or
        when fewer than ``n`` are eligible.
    include : (m,) int, optional
        Samples that are candidates whatever the spacing (``m <= n``, not the first or last
        sample): the other ``n - m`` are spaced evenly as above.

    Returns
    -------
    (<= n,) int, increasing and unique; the first and last samples are never chosen.
    """
    if n < 1:
        raise PlanningError(f"need at least one candidate key pose, got n={n}")
    forced = np.unique(np.asarray([] if include is None else include, dtype=int))
    if len(forced) > n or (len(forced) and (forced[0] < 1 or forced[-1] > len(pos) - 2)):
        raise PlanningError(f"include: at most {n} inner sample indices, got {forced.tolist()}")
    step = np.diff(pose_parameters(pos, quat), axis=0)
    step[:, 3:] *= char_length  # 1 rad of rotation moves the part's far end by char_length
    length = np.concatenate([[0.0], np.linalg.norm(step, axis=1)])
    mask = np.ones(len(length), dtype=bool)
    mask[[0, -1]] = False
    if eligible is not None and np.count_nonzero(np.asarray(eligible) & mask) >= n:
        mask &= np.asarray(eligible, dtype=bool)
    s = np.cumsum(np.where(mask, length, 0.0))
    if len(s) < 3 or s[-1] <= 0:
        raise PlanningError("demonstration does not move: no key poses to take from it")
    lo, hi = s[mask].min(), s[mask].max()
    spaced = n - len(forced)
    targets = lo + (hi - lo) * (np.arange(spaced) + 0.5) / max(spaced, 1)
    where = np.flatnonzero(mask)
    idx = where[np.clip(np.searchsorted(s[where], targets), 0, len(where) - 1)]
    return np.unique(np.concatenate([idx, forced]))


@dataclass(frozen=True, eq=False)
class KeyPoses:
    """Ranked candidate key poses of one demonstration.

    Attributes
    ----------
    indices : (K,) int
        Demonstration sample index of each candidate, increasing (time order).
    t : (K,) float
        Their time stamps (s).
    L2G : (K, 4, 4) float
        Their poses of ``L`` in ``G`` (m), as transforms; :attr:`poses` as :class:`Pose`.
    param : str
        Ranked parameter (one of :data:`PARAMS`).
    values : (K,) float
        That parameter at the candidates (m or rad).
    derivative : (K,) float
        Derivative of the fitted polynomial at the candidates (m/s or rad/s).
    order : (K,) int
        Candidate positions (into the arrays above) by descending ``|derivative|``: ``order[0]``
        is inserted into the planner first.
    poly : np.polynomial.Polynomial
        The fitted polynomial, parameter value as a function of time (s).
    demo_t, demo_values : (T,) float
        The demonstration's time stamps and the parameter over them (for figures).
    """

    indices: np.ndarray
    t: np.ndarray
    L2G: np.ndarray
    param: str
    values: np.ndarray
    derivative: np.ndarray
    order: np.ndarray
    poly: np.polynomial.Polynomial
    demo_t: np.ndarray
    demo_values: np.ndarray

    @property
    def ranks(self) -> np.ndarray:
        """(K,) int rank of each candidate, 1 = inserted first."""
        ranks = np.empty(len(self.order), dtype=int)
        ranks[self.order] = np.arange(1, len(self.order) + 1)
        return ranks

    @property
    def poses(self) -> tuple[Pose, ...]:
        """The candidates' poses ``L2G`` (m, w-x-y-z), in the order of :attr:`indices`."""
        return tuple(Pose.from_matrix(T) for T in self.L2G)


def rank_key_poses(
    t: np.ndarray,
    pos: np.ndarray,
    quat: np.ndarray,
    n_candidates: int,
    *,
    param: str = "auto",
    degree: int = 7,
    char_length: float = 0.1,
    eligible: np.ndarray | None = None,
    include: np.ndarray | None = None,
) -> KeyPoses:
    """Select candidate key poses of a demonstration and rank them.

    Parameters
    ----------
    t : (T,) s. pos : (T, 3) m. quat : (T, 4) w-x-y-z.
        The demonstration, ``L2G`` over time.
    n_candidates : int
        Number of candidate key poses (paper: 6 for the L, 11 for the tenon).
    param : str
        One of :data:`PARAMS`, or ``"auto"`` for the parameter with the largest range
        (positions divided by ``char_length``, so that they compare with angles in rad).
    degree : int
        Polynomial degree, lowered to ``T - 1`` for short demonstrations.
    char_length : float
        Characteristic length (m) of the moving part.
    eligible : (T,) bool, optional
        Samples candidates may be taken from, see :func:`select_candidates`.
    include : (m,) int, optional
        Samples that are candidates in any case, see :func:`select_candidates`.

    Raises
    ------
    PlanningError
        Fewer than two poses, unknown parameter, or a motionless demonstration.
    """
    t, pos, quat = _checked_demo(t, pos, quat)
    values6 = pose_parameters(pos, quat)
    param = _ranking_param(values6, param, char_length)
    column = values6[:, PARAMS.index(param)]
    idx = select_candidates(
        pos, quat, n_candidates, char_length=char_length, eligible=eligible, include=include
    )
    # numpy's Polynomial.fit maps time onto [-1, 1] internally, which keeps the fit well
    # conditioned for any demonstration length.
    poly = np.polynomial.Polynomial.fit(t, column, deg=int(min(degree, len(t) - 1)))
    derivative = poly.deriv()(t[idx])
    return KeyPoses(
        indices=idx,
        t=t[idx],
        L2G=_pose_matrices(pos[idx], quat[idx]),
        param=param,
        values=column[idx],
        derivative=derivative,
        order=np.argsort(-np.abs(derivative), kind="stable"),
        poly=poly,
        demo_t=t,
        demo_values=column,
    )


def _checked_demo(
    t: np.ndarray, pos: np.ndarray, quat: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``t`` (T,), ``pos`` (T, 3), ``quat`` (T, 4) as float arrays; PlanningError for fewer
    than two poses or mismatched shapes."""
    t = np.asarray(t, dtype=float)
    pos = np.asarray(pos, dtype=float)
    quat = np.asarray(quat, dtype=float)
    if t.ndim != 1 or len(t) < 2 or pos.shape != (len(t), 3) or quat.shape != (len(t), 4):
        raise PlanningError(
            f"a demonstration needs at least 2 poses with matching shapes, got t {t.shape}, "
            f"pos {pos.shape}, quat {quat.shape}"
        )
    return t, pos, quat


def _ranking_param(values6: np.ndarray, param: str, char_length: float) -> str:
    """``param`` checked against :data:`PARAMS`; ``"auto"``: the column of ``values6`` (T, 6)
    with the largest range (positions divided by ``char_length`` m, to compare with rad)."""
    if param == "auto":
        spread = np.ptp(values6, axis=0)
        spread[:3] /= char_length
        param = PARAMS[int(np.argmax(spread))]
    if param not in PARAMS:
        raise PlanningError(f"unknown pose parameter {param!r}; use one of {PARAMS} or 'auto'")
    return param


def _pose_matrices(pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
    """(K, 4, 4) homogeneous matrices of positions (K, 3) m and quaternions (K, 4) w-x-y-z."""
    L2G = np.tile(np.eye(4), (len(pos), 1, 1))
    L2G[:, :3, :3] = wxyz_to_rotation(quat).as_matrix()
    L2G[:, :3, 3] = pos
    return L2G


def straight_chain(n: int, connects: Callable[[int, int], bool]) -> list[int]:
    """Greedy chain of candidates ``0 .. n-1`` from the start (``-1``) to the goal (``n``).

    From the current node, the chain steps to the farthest later node ``j`` (goal first, then
    candidates backwards) with ``connects(current, j)`` true (a free straight motion); where
    none connects, it steps to the next candidate. Returns the candidates in the chain, in
    demonstration order (the goal is not listed): the smallest set of candidates that such a
    greedy walk needs, ranked first by the planner.
    """
    chain: list[int] = []
    current = -1
    while current < n:
        step = next((j for j in range(n, current + 1, -1) if connects(current, j)), current + 1)
        if step < n:
            chain.append(step)
        current = step
    return chain
