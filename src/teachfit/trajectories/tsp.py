"""Shortest open tour from a fixed start through N points (fixed start, free end).

The open path is solved as a closed tour over ``start, points…, dummy`` in which the dummy is at
zero distance from every node and the edge ``(dummy, start)`` may never be removed: the closed
tour ``start → p_1 → … → p_N → dummy → start`` then costs exactly the open path.

``solver="fast"`` (default): nearest-neighbour construction, then the compiled local search
of :mod:`teachfit.trajectories.tsp_kernel` (2-opt, Or-opt (of any segment and a new free end
up to 300 points) and Lin-Kernighan chains over the
nearest and Delaunay neighbours from ``scipy.spatial``, then a fixed number of seeded
segment-swap kicks (every second one at long edges up to 300 points); up to 300 points it reads
a distance matrix; why it is written here is said there). ``solver="lkh"`` calls LKH-3
through ``elkai`` (slow, the reference quality of the benchmark).

Distances are Euclidean after scaling each coordinate by ``weights`` (e.g. ``(1, 1, ℓ)`` to
count a rotation about z as ℓ metres per radian).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.spatial import Delaunay, QhullError, cKDTree
from scipy.spatial.distance import cdist

from teachfit.core.errors import PlanningError


@dataclass(frozen=True)
class OpenTour:
    """Result of an open-tour search.

    Attributes
    ----------
    order : ndarray of int, shape (N,)
        Indices into ``points`` in visiting order (the start is not included).
    length : float
        Weighted length of ``start → points[order[0]] → … → points[order[-1]]``.
    """

    order: np.ndarray
    length: float


def path_length(start: np.ndarray, points: np.ndarray, order: np.ndarray, weights=None) -> float:
    """Weighted length of the open path ``start, points[order]`` (weights scale coordinates)."""
    w = 1.0 if weights is None else np.asarray(weights, dtype=float)
    path = np.vstack([np.asarray(start, float)[None], np.asarray(points, float)[order]]) * w
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def _quadrant_neighbours(x: np.ndarray, k: int, per_quadrant: int = 2) -> np.ndarray:
    """Candidate lists, shape (n, W): the ``k`` nearest nodes plus the ``per_quadrant`` nearest
    in each quadrant of the first two coordinates (among the 40 nearest), nearest first, padded
    by repeating the last. Quadrant neighbours let clustered points reach the next cluster."""
    n = x.shape[0]
    q = min(n - 1, max(k, 40))
    _, idx = cKDTree(x).query(x, k=q + 1)
    idx = np.atleast_2d(idx)
    # drop each row's own index (first, or later among exact duplicates)
    own = idx == np.arange(n)[:, None]
    first_own = np.argmax(own, axis=1)
    keep = np.ones_like(idx, dtype=bool)
    keep[np.arange(n), first_own] = ~own[np.arange(n), first_own]
    keep[np.arange(n), -1] &= own.any(axis=1)  # rows without self: drop the farthest instead
    idx = idx[keep].reshape(n, q)
    xy = x[:, :2] if x.shape[1] >= 2 else np.column_stack([x, np.zeros(n)])
    d = xy[idx] - xy[:, None]
    quad = (d[..., 0] >= 0).astype(int) + 2 * (d[..., 1] >= 0).astype(int)
    mask = np.zeros_like(idx, dtype=bool)
    mask[:, :k] = True
    for qd in range(4):
        hit = quad == qd
        mask |= hit & (np.cumsum(hit, axis=1) <= per_quadrant)
    count = mask.sum(axis=1)
    order = np.argsort(~mask, axis=1, kind="stable")[:, : count.max()]
    out = np.take_along_axis(idx, order, axis=1)
    col = np.arange(out.shape[1])[None, :]
    last = np.take_along_axis(out, (count - 1)[:, None], axis=1)
    return np.where(col < count[:, None], out, last).astype(np.int64)


def _candidates(x: np.ndarray, k: int, width: int = 10) -> np.ndarray:
    """Candidate lists, shape (n, W <= width): the ``k`` nearest nodes and the Delaunay
    neighbours (2-D and 3-D points), nearest first, padded by repeating the last.

    Delaunay edges hold nearly all edges of an optimal tour, including the long ones between
    clusters that no short nearest-neighbour list reaches; degenerate point sets (qhull
    fails) and other dimensions fall back to :func:`_quadrant_neighbours`."""
    from teachfit.trajectories.tsp_moves import merge_candidates

    n, dim = x.shape
    if dim not in (2, 3) or n <= dim + 1:
        return _quadrant_neighbours(x, k)
    try:
        tri = Delaunay(x)
    except QhullError:
        return _quadrant_neighbours(x, k)
    indptr, indices = tri.vertex_neighbor_vertices
    _, near = cKDTree(x).query(x, k=min(k, n - 1) + 1)
    width = min(width, n - 1)
    return merge_candidates(x, np.atleast_2d(near).astype(np.int64), indptr, indices, width)


# kick size and acceptance of the iterated local search (measured in
# benchmarks/search_speed.py: larger windows and a little threshold accepting win)
_WINDOW = 1 << 30  # segments of any length (clusters move as a whole)
_THRESHOLD = 0.1  # of the mean nearest-neighbour edge
#: up to _LK_FROM points: every second kick cuts at long edges, each cut the longest of this
#: many drawn tour edges (the kick where the tour is poor: whole clusters and the free end
#: move; instances over 1.01 x LKH among 180 sets of 300 points, per kick seed: 2: 2-7, 3: 1-2,
#: 4: 2-6, none: 20-27), and in the plane a higher threshold (0.1: 8-9, 0.2: 2-5, 0.45: 1-2,
#: 0.8: 5-10); 3-D points keep 0.1 (15 Gaussian sets: mean 1.0032 x LKH, 0.45: 1.0067)
_LONG_CUTS, _THRESHOLD_PLANE = 3, 0.45
_DEPTH, _BREADTH = 3, 1  # Lin-Kernighan chain: flips at most, alternatives at its first step
# up to this many points the chain is off and the kicks are 5 N (5 N were as close to LKH
# as 3 N kicks with chains, in half the time: 300 points, benchmarks/search_speed.py)
_LK_FROM = 300
#: at least this many kicks (small sets: 1500 kicks of 100 points take about 15 ms)
_MIN_KICKS = 1500
#: kicks per point up to _LK_FROM points: 5 N (5.5 N with the distance matrix, 2026-12-05,
#: then 5 N again with the long-edge kicks and the new-end move: 4-7 % less CPU than 5.5 N
#: before, as close to LKH as 5.5 N with them: 7 against 4 of 540 runs over 1.01 x LKH)
_KICKS_PER_POINT = 5.0
#: independent runs of the iterated local search up to _LK_FROM points, each from the
#: nearest-neighbour path with its own kicks, the shortest kept: the per-run tail differs (600
#: sets of 300 points x 3 kick seeds over 1.01 x LKH-3: one run of 5 N kicks 33 / 1800, of
#: 10 N 8 / 1800, two runs of 5 N 5 / 1800 at the CPU of the 10 N run)
_RUNS = 2
#: up to this many nodes (the start and 300 points) the kernel reads a distance matrix: 15-19 %
#: less CPU at 100 and 300 points, the same tours; slower at 600 and 1000 points (the matrix
#: leaves the cache), so coordinates there (benchmarks/search_speed.py point sets)
_MATRIX_UP_TO = 301


def _distances(x: np.ndarray) -> np.ndarray:
    """What the kernel measures with: up to :data:`_MATRIX_UP_TO` nodes the distance matrix
    with the dummy's zero row and column (shape (n + 1, n + 1); a look-up is cheaper than the
    square root), else the coordinates (shape (n, D))."""
    n = x.shape[0]
    if n > _MATRIX_UP_TO:
        return np.ascontiguousarray(x)
    dm = np.zeros((n + 1, n + 1))
    dm[:n, :n] = cdist(x, x)
    return dm


def _compiled(
    x: np.ndarray, rng: np.random.Generator, n_neighbours: int, n_kicks: int
) -> list[int]:
    """Nearest-neighbour path improved by :func:`teachfit.trajectories.tsp_kernel.improve_tour`,
    :data:`_RUNS` times up to :data:`_LK_FROM` points, ``n_kicks`` each; the shortest path.
    The first run draws its kicks from ``rng``, the others from children spawned from it, so
    each run's kicks begin with those of any smaller ``n_kicks``."""
    from teachfit.trajectories.tsp_kernel import improve_tour
    from teachfit.trajectories.tsp_moves import nearest_neighbour_path

    n = x.shape[0]  # node 0 = start, 1..n-1 = points; dummy = n
    neigh = _candidates(x, n_neighbours)
    tour = np.append(nearest_neighbour_path(x, neigh), n)
    small = n - 1 <= _LK_FROM
    runs = _RUNS if small else 1
    rngs = [rng, *rng.spawn(runs - 1)]
    scale = float(np.ptp(x, axis=0).max()) or 1.0
    d0 = np.linalg.norm(np.diff(x[tour[:-1]], axis=0), axis=1).mean()
    dist = _distances(x)
    options = (
        _WINDOW,
        1e-12 * scale,
        (_THRESHOLD_PLANE if small and x.shape[1] == 2 else _THRESHOLD) * d0,
        0 if small else _DEPTH,
        _BREADTH,
        small,
        _LONG_CUTS if small else 0,
    )
    best, best_length = tour, np.inf
    for run_rng in rngs:
        draws = run_rng.integers(0, 1 << 30, size=(n_kicks, 3), dtype=np.int64)
        out = improve_tour(dist, neigh, tour, draws, *options)
        length = float(np.linalg.norm(np.diff(x[out[:-1]], axis=0), axis=1).sum())
        if length < best_length:
            best, best_length = out, length
    return [int(v) for v in best]


def _default_kicks(n: int) -> int:
    """Kicks of the iterated local search: max(5 N, 1500) up to 300 points (≈ 15-25 ms, no LK
    chains, Or-opt of any segment, distance matrix), then 3 N (N / 300)^0.75 (measured in
    benchmarks/search_speed.py: larger sets need more kicks per point to stay within 1 % of
    LKH; with (N / 300)^0.5 uniform 2000 points gave 1.011)."""
    if n <= _LK_FROM:
        return max(int(_KICKS_PER_POINT * n), _MIN_KICKS)
    return int(round(3 * n * (n / _LK_FROM) ** 0.75))


def _lkh(x: np.ndarray, runs: int) -> list[int]:
    import elkai  # optional reference solver

    n = x.shape[0]
    d = cdist(x, x)
    big = 2.0 * float(d.max()) + 1.0  # any tour not keeping start next to the dummy pays this
    full = np.zeros((n + 1, n + 1))
    full[:n, :n] = d
    full[0, 1:n] += big
    full[1:n, 0] += big
    scale = 1e6 / max(float(full.max()), 1e-300)
    ints = np.rint(full * scale).astype(int).tolist()
    return [int(v) for v in elkai.DistanceMatrix(ints).solve_tsp(runs=runs)[:-1]]


# Long (> 60 lines) by its numpydoc docstring (41 lines of code).
def open_tour(
    points: np.ndarray,
    start: np.ndarray | None = None,
    *,
    weights: np.ndarray | None = None,
    solver: Literal["fast", "lkh"] = "fast",
    rng: np.random.Generator | None = None,
    n_neighbours: int = 6,
    n_kicks: int | None = None,
    lkh_runs: int = 1,
) -> OpenTour:
    """Shortest open tour from ``start`` through all ``points`` (free end).

    Parameters
    ----------
    points : ndarray, shape (N, D)
        Points to visit, N >= 1.
    start : ndarray, shape (D,), optional
        Fixed first position (default: the origin). Not part of ``order``.
    weights : ndarray, shape (D,), optional
        Per-coordinate scale of the metric ``‖diag(w)(p - q)‖`` (default ones).
    solver : {"fast", "lkh"}
        Heuristic of this module or LKH-3 via elkai.
    rng : numpy.random.Generator, optional
        Kick randomness of the fast solver (default: seed 0, deterministic).
    n_neighbours : int
        Candidate-list size K of the local search.
    n_kicks : int, optional
        Iterated-local-search kicks; default ``max(5 N, 1500)`` up to 300 points (≈ 15-25 ms
        CPU), ``3 N (N / 300)^0.75`` beyond. A fixed count,
        not a time budget: the same input gives the same tour on every machine.
    lkh_runs : int
        LKH ``RUNS`` parameter.

    Raises
    ------
    PlanningError
        Empty or non-finite points, or a start of the wrong dimension.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[0] < 1:
        raise PlanningError(f"points must be a non-empty (N, D) array, got shape {p.shape}")
    s = np.zeros(p.shape[1]) if start is None else np.asarray(start, dtype=float)
    w = np.ones(p.shape[1]) if weights is None else np.asarray(weights, dtype=float)
    if s.shape != (p.shape[1],) or w.shape != (p.shape[1],):
        raise PlanningError("start and weights must have one entry per coordinate")
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(s)) and np.all(w > 0)):
        raise PlanningError("points and start must be finite, weights positive")
    x = np.vstack([s[None], p]) * w
    n = p.shape[0]
    if n <= 2:
        orders = [[0]] if n == 1 else [[0, 1], [1, 0]]
        best = min(orders, key=lambda o: path_length(s, p, np.array(o), w))
        order = np.array(best)
    else:
        if solver == "fast":
            rng = np.random.default_rng(0) if rng is None else rng
            kicks = _default_kicks(n) if n_kicks is None else int(n_kicks)
            tour = _compiled(x, rng, n_neighbours, kicks)
        elif solver == "lkh":
            tour = _lkh(x, lkh_runs)
        else:
            raise PlanningError(f"unknown TSP solver {solver!r}")
        i0 = tour.index(0)
        path = tour[i0:] + tour[:i0]
        if path[1] == n + 1:  # the dummy follows the start: walk the other way
            path = [0] + path[1:][::-1]
        order = np.array([v - 1 for v in path[1:] if v != n + 1], dtype=int)
    return OpenTour(order=order, length=path_length(s, p, order, w))
